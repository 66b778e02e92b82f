"""Speed of the batched vector env (docs/performance.md). Not a test: run it by hand.

    python benchmarks/bench_vector_env.py                   # everything, ~10 minutes
    python benchmarks/bench_vector_env.py --skip-training   # decisions per second only
    python benchmarks/bench_vector_env.py --json out.json

1. **Decisions per second** (one decision = one robot's choice; a world of K robots makes K per
   step), one process on one core, random valid slots, only the envs' ``step``/``reset`` calls
   timed, for N = 1, 8, 64, 256 worlds: the batched :func:`frontier_marl.vector_env`, a Python
   loop over N ParallelEnvs, SB3's ``DummyVecEnv`` over N ``gym.make`` envs (one robot only)
   and SuperSuit's concatenated vector env over N ParallelEnvs. Each figure is also given as a
   ratio to the single ParallelEnv (the loop at N = 1), measured in the same run.
2. **The env's share of training time**: DQN (the thesis's hyperparameters, configuration 1's
   observation) on the batched env with 8 worlds, and PPO on 16, each against a null vector env
   with identical spaces, the two trainings interleaved in chunks (env share =
   (T_env - T_null) / T_env); and the CPU time of one step of the 8-world env alone and between
   DQN's own work (:func:`interleaved_step_cost`).

SB3, SuperSuit and torch (the train extra) are imported where they are used: the batched
env's rates (:func:`rate_batched`, which ``bench_explorer_features`` uses) need none of them.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from typing import Any

import gymnasium as gym
import numpy as np

import frontier_marl
from frontier_marl.config import make_config

SETTINGS: dict[str, dict[str, Any]] = {
    "thesis-20x20, 1 robot": {"preset": "thesis-20x20"},
    "rooms 64x64, 4 robots": {
        "preset": "rooms-32",
        "height": 64,
        "width": 64,
        "n_agents": 4,
        "perception_range": 5,
        "max_steps": 2048,
    },
}
WORLDS = (1, 8, 64, 256)
CONFIG01 = {"preset": "thesis-20x20", "reward": "reward2", "normalize": True}


def random_valid(masks: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One random valid slot per row of the (M, n_slots) masks."""
    return (rng.random(masks.shape) * masks).argmax(axis=1)


def rate_batched(kwargs: dict[str, Any], n: int, seconds: float) -> float:
    env = frontier_marl.vector_env(n, info="mask", **kwargs)
    rng = np.random.default_rng(0)
    start = time.perf_counter()
    _, infos = env.reset(seed=0)
    timed, decisions = time.perf_counter() - start, 0
    while timed < seconds:
        actions = random_valid(infos["action_mask"], rng)
        start = time.perf_counter()
        _, _, _, _, infos = env.step(actions)
        timed += time.perf_counter() - start
        decisions += env.num_envs
    return decisions / timed


def rate_loop(kwargs: dict[str, Any], n: int, seconds: float) -> float:
    envs = [frontier_marl.parallel_env(info="minimal", **kwargs) for _ in range(n)]
    rng = np.random.default_rng(0)
    start = time.perf_counter()
    infos = [env.reset(seed=i)[1] for i, env in enumerate(envs)]
    timed, decisions = time.perf_counter() - start, 0
    while timed < seconds:
        for i, env in enumerate(envs):
            masks = np.stack([info["action_mask"] for info in infos[i].values()])
            actions = dict(zip(infos[i], random_valid(masks, rng).tolist(), strict=True))
            start = time.perf_counter()
            _, _, _, _, infos[i] = env.step(actions)
            if not env.agents:
                infos[i] = env.reset()[1]
            timed += time.perf_counter() - start
            decisions += len(actions)
    return decisions / timed


def rate_sb3(make_vec: Any, n: int, seconds: float) -> float:
    """Decisions per second of an SB3-style vector env (``step`` returns 4 values)."""
    vec = make_vec(n)
    rng = np.random.default_rng(0)
    start = time.perf_counter()
    vec.reset()
    timed, decisions = time.perf_counter() - start, 0
    while timed < seconds:
        masks = np.stack(vec.env_method("action_masks"))
        actions = random_valid(masks, rng)
        start = time.perf_counter()
        vec.step(actions)
        timed += time.perf_counter() - start
        decisions += vec.num_envs
    vec.close()
    return decisions / timed


def dummy_vec_env(kwargs: dict[str, Any]) -> Any:
    from stable_baselines3.common.vec_env import DummyVecEnv

    def make(n: int) -> Any:
        def one() -> Any:
            return gym.make(frontier_marl.GYM_ID, info="minimal", **kwargs)

        vec = DummyVecEnv([one] * n)
        vec.seed(0)
        return vec

    return make


def supersuit_vec_env(kwargs: dict[str, Any]) -> Any:
    import supersuit as ss

    class Masked:
        """SuperSuit's vector env with the robots' action masks read from the envs."""

        def __init__(self, n: int) -> None:
            markov = ss.pettingzoo_env_to_vec_env_v1(
                frontier_marl.parallel_env(info="minimal", **kwargs)
            )
            self.vec = ss.concat_vec_envs_v1(markov, n, num_cpus=0, base_class="stable_baselines3")
            self.num_envs = self.vec.num_envs
            self.envs = [copy.par_env for copy in self.vec.venv.vec_envs]

        def reset(self) -> Any:
            return self.vec.reset()

        def step(self, actions: np.ndarray) -> Any:
            return self.vec.step(actions)

        def env_method(self, name: str) -> list[np.ndarray]:
            return [mask for env in self.envs for mask in env.mdp.action_masks()]

        def close(self) -> None:
            self.vec.close()

    return Masked


def decisions_table(seconds: float) -> list[dict[str, Any]]:
    rows = []
    for label, kwargs in SETTINGS.items():
        rate_batched(kwargs, 2, 0.2)  # loads the compiled kernels (once per process)
        rate_loop(kwargs, 1, 0.2)
        single = rate_loop(kwargs, 1, seconds)
        print(f"{label}: single ParallelEnv {single:,.0f} decisions/s")
        for n in WORLDS:
            rates = {
                "batched": rate_batched(kwargs, n, seconds),
                "loop": single if n == 1 else rate_loop(kwargs, n, seconds),
                "supersuit": rate_sb3(supersuit_vec_env(kwargs), n, seconds),
            }
            if kwargs.get("n_agents", 1) == 1:
                rates["dummy_vec_env"] = rate_sb3(dummy_vec_env(kwargs), n, seconds)
            row = {"setting": label, "worlds": n, "single": single, **rates}
            row["batched_vs_single"] = rates["batched"] / single
            rows.append(row)
            print(
                f"  N={n:>3}: "
                + ", ".join(f"{name} {rate:,.0f}" for name, rate in rates.items())
                + f"  (batched / single = {row['batched_vs_single']:.1f}x)"
            )
    return rows


class NullVecEnv:
    """An SB3 ``VecEnv`` with ``like``'s spaces: constant observations, 100-step episodes."""

    def __new__(cls, like: Any) -> Any:
        from stable_baselines3.common.vec_env import VecEnv

        class _Null(VecEnv):
            def __init__(self) -> None:
                super().__init__(like.num_envs, like.observation_space, like.action_space)
                sample = like.observation_space.sample()
                n = self.num_envs
                if isinstance(sample, dict):
                    self._obs = {k: np.repeat(v[None], n, axis=0) for k, v in sample.items()}
                else:
                    self._obs = np.repeat(sample[None], n, axis=0)
                self._t = 0

            def reset(self) -> Any:
                self._t = 0
                return self._obs

            def step_async(self, actions: np.ndarray) -> None:
                pass

            def step_wait(self) -> Any:
                self._t += 1
                done = self._t >= 100
                infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
                if done:
                    self._t = 0
                    for j, info in enumerate(infos):
                        info["terminal_observation"] = (
                            {k: v[j] for k, v in self._obs.items()}
                            if isinstance(self._obs, dict)
                            else self._obs[j]
                        )
                dones = np.full(self.num_envs, done)
                return self._obs, np.zeros(self.num_envs, np.float32), dones, infos

            def close(self) -> None:
                pass

            def get_attr(self, name: str, indices: Any = None) -> list[Any]:
                return [None] * self.num_envs

            def set_attr(self, *args: Any, **kwargs: Any) -> None:
                pass

            def env_method(self, *args: Any, **kwargs: Any) -> list[Any]:
                return []

            def env_is_wrapped(self, *args: Any, **kwargs: Any) -> list[bool]:
                return [False] * self.num_envs

            def seed(self, seed: int | None = None) -> list[None]:
                return [None] * self.num_envs

        return _Null()


def _model(algorithm: str, env: Any) -> Any:
    """DQN with the thesis's hyperparameters, or PPO, on ``env``."""
    from stable_baselines3 import DQN, PPO

    if algorithm == "dqn":
        return DQN(
            "MultiInputPolicy", env, learning_rate=5e-5, exploration_fraction=0.7,
            exploration_final_eps=0.05, batch_size=64, buffer_size=50_000,
            target_update_interval=500, train_freq=4, learning_starts=1000, seed=0,
        )  # fmt: skip
    return PPO("MultiInputPolicy", env, n_steps=128, batch_size=256, n_epochs=4, seed=0)


def _chunk_seconds(models: dict[str, Any], steps: int, chunks: int) -> dict[str, list[float]]:
    """Train the models in alternating chunks (the order flips every chunk); each chunk's
    wall time per model."""
    seconds: dict[str, list[float]] = {name: [] for name in models}
    per_chunk = -(-steps // chunks)
    for chunk in range(chunks):
        order = list(models) if chunk % 2 == 0 else list(models)[::-1]
        for name in order:
            start = time.perf_counter()
            models[name].learn(per_chunk, reset_num_timesteps=chunk == 0)
            seconds[name].append(time.perf_counter() - start)
    return seconds


def training_share(algorithm: str, n_envs: int, steps: int, chunks: int) -> dict[str, Any]:
    """Train ``algorithm`` on the batched env and on a null env with the same spaces, in
    alternating chunks of one run each; the env's share of the wall time."""
    import torch

    from frontier_marl.training.batched_vec_env import make_batched_vec_env

    torch.set_num_threads(1)
    real = make_batched_vec_env({"config": make_config(**CONFIG01)}, n_envs, seed=0)
    envs = {"null": NullVecEnv(real), "env": real}
    models = {name: _model(algorithm, env) for name, env in envs.items()}
    seconds = _chunk_seconds(models, steps, chunks)
    total = {name: sum(values) for name, values in seconds.items()}
    by_chunk = np.array([(e - n) / e for n, e in zip(seconds["null"], seconds["env"], strict=True)])
    return {
        "algorithm": algorithm,
        "n_envs": n_envs,
        "steps": models["env"].num_timesteps,
        "seconds_null": total["null"],
        "seconds_env": total["env"],
        "env_share": (total["env"] - total["null"]) / total["env"],
        "env_share_standard_error": float(by_chunk.std(ddof=1) / np.sqrt(chunks)),
    }


def interleaved_step_cost(n_envs: int, steps: int, rounds: int = 3) -> dict[str, Any]:
    """CPU microseconds per ``step`` of the batched env (``n_envs`` worlds, random slots), alone
    and with DQN's own work between the steps (action selection every step, a gradient step
    every 4, as in training): what the env costs inside training beyond its own work. Each
    figure is the median of ``rounds`` alternated rounds."""
    import torch

    from frontier_marl.training.batched_vec_env import make_batched_vec_env

    torch.set_num_threads(1)
    env = make_batched_vec_env({"config": make_config(**CONFIG01)}, n_envs, seed=0)
    model = _model("dqn", env)
    model.learn(1100)  # past learning_starts: the replay buffer can be sampled
    rng = np.random.default_rng(0)
    state = {"obs": env.reset()}

    def step_us(interleaved: bool) -> float:
        spent = 0.0
        for i in range(steps):
            if interleaved:
                model.predict(state["obs"], deterministic=False)
                if i % 4 == 0:
                    model.train(gradient_steps=1, batch_size=64)
            actions = random_valid(env.venv.action_masks(), rng)
            start = time.thread_time()
            env.step_async(actions)
            state["obs"] = env.step_wait()[0]
            spent += time.thread_time() - start
        return spent / steps * 1e6

    alone, interleaved = [], []
    for _ in range(rounds):
        alone.append(step_us(False))
        interleaved.append(step_us(True))
    return {
        "n_envs": n_envs,
        "us_per_step_alone": float(np.median(alone)),
        "us_per_step_interleaved": float(np.median(interleaved)),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="timed seconds per figure")
    parser.add_argument("--dqn-steps", type=int, default=100_000)
    parser.add_argument("--ppo-steps", type=int, default=100_000)
    parser.add_argument("--chunks", type=int, default=10)
    parser.add_argument("--skip-training", action="store_true")
    parser.add_argument("--skip-decisions", action="store_true")
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args(argv)
    report: dict[str, Any] = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
    }
    if not args.skip_decisions:
        report["decisions"] = decisions_table(args.seconds)
    if not args.skip_training:
        report["training"] = []
        for algorithm, n_envs, steps in (("dqn", 8, args.dqn_steps), ("ppo", 16, args.ppo_steps)):
            row = training_share(algorithm, n_envs, steps, args.chunks)
            report["training"].append(row)
            print(
                f"{algorithm.upper()}, {n_envs} worlds, {row['steps']} steps: null "
                f"{row['seconds_null']:.1f} s, env {row['seconds_env']:.1f} s; env share "
                f"{100 * row['env_share']:.1f} % "
                f"(standard error {100 * row['env_share_standard_error']:.1f})"
            )
        if args.dqn_steps:
            cost = report["interleaved"] = interleaved_step_cost(8, 2000)
            print(
                f"batched env step, 8 worlds: {cost['us_per_step_alone']:.0f} µs CPU alone, "
                f"{cost['us_per_step_interleaved']:.0f} µs between DQN's network work"
            )
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(report, handle, indent=2)
    return 0
