"""Speed benchmark of the simulator (docs/performance.md). Not a test: run it by hand.

    python benchmarks/bench_env.py                 # everything, ~3 minutes on 2 cores
    python benchmarks/bench_env.py --skip-dqn      # decisions per second only
    python benchmarks/bench_env.py --json out.json

Reports decisions per second (one decision = one ``step`` of all robots) for a random-valid-slot
policy and a nearest-cluster policy on the thesis presets and larger maps, and the share of SB3
DQN training wall time spent in the env: the same DQN trains for the same number of steps on the
env and on a null env with identical spaces, in one run (interleaved in chunks), and

    env share = (T_env - T_null) / T_env.

``benchmarks/bench_revisions.py`` loads this module from its file to time older source trees of
the package with it, so it reads the package only through its public names (``frontier_marl``).
SB3 and torch (the train extra) are imported by the DQN part alone, where it runs.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import frontier_marl
from frontier_marl.envs.infos import slot_table

SETTINGS: list[tuple[str, dict[str, Any]]] = [
    ("thesis-20x20, 1 robot", {"preset": "thesis-20x20"}),
    ("thesis-30x30, 1 robot", {"preset": "thesis-30x30"}),
    (
        "64x64, 4 robots",
        {"preset": "thesis-20x20", "height": 64, "width": 64, "n_agents": 4, "max_steps": 2000},
    ),
    (
        "128x128, 8 robots",
        {
            "preset": "thesis-20x20",
            "height": 128,
            "width": 128,
            "n_agents": 8,
            "max_steps": 4000,
            "perception_range": 5,
        },
    ),
]


def explore_bench_settings(map_file: Path) -> list[tuple[str, dict[str, Any]]]:
    """Explore-Bench's room1_modified map with its classical sensor range (35 cells).

    Explore-Bench's own Python simulator reached ~12 steps/s (nearest frontier, one cell per
    step) and ~2.7 steps/s (learning env, one goal per step, moved all the way) on this map and
    machine kind (figures from shared/maps/explore-bench/README.md, the folder beside the
    repository, where ``benchmarks/bench_env.py`` looks for the map).
    """
    common = {
        "map_path": str(map_file),
        "perception_range": 35,
        "max_steps": 100_000,
        "no_progress_limit": 10_000,
    }
    return [
        ("room1_modified, 1 cell", {**common, "cells_per_step": 1}),
        ("room1_modified, full", {**common, "cells_per_step": "full"}),
    ]


def nearest(info: dict[str, Any], rng: np.random.Generator) -> int:
    table = slot_table(info)
    return int(np.argmin(table.distance[: table.live])) if table.live else 0


def random_valid(info: dict[str, Any], rng: np.random.Generator) -> int:
    return int(rng.choice(np.flatnonzero(info["action_mask"])))


def decisions_per_second(kwargs: dict[str, Any], policy: Any, seconds: float) -> dict[str, float]:
    """Play whole episodes for about ``seconds``; time only ``reset`` and ``step``."""
    env = frontier_marl.parallel_env(**kwargs)
    rng = np.random.default_rng(0)
    env_time, steps, episodes, seed = 0.0, 0, 0, 0
    while env_time < seconds:
        start = time.perf_counter()
        _, infos = env.reset(seed=seed)
        env_time += time.perf_counter() - start
        seed += 1
        while env.agents:
            actions = {agent: policy(infos[agent], rng) for agent in env.agents}
            start = time.perf_counter()
            _, _, _, _, infos = env.step(actions)
            env_time += time.perf_counter() - start
            steps += 1
        episodes += 1
    return {
        "decisions_per_s": steps / env_time,
        "us_per_decision": 1e6 * env_time / steps,
        "steps": steps,
        "episodes": episodes,
    }


class NullEnv(gym.Env):
    """Same spaces as ``like``, constant observation, 100-step episodes, no simulation."""

    def __init__(self, like: gym.Env) -> None:
        self.observation_space = like.observation_space
        self.action_space = like.action_space
        self._obs = self.observation_space.sample()
        self._t = 0

    def reset(self, *, seed: int | None = None, options: Any = None) -> Any:
        super().reset(seed=seed)
        self._t = 0
        return self._obs, {}

    def step(self, action: Any) -> Any:
        self._t += 1
        return self._obs, 0.0, False, self._t >= 100, {}


def thesis_dqn(env: gym.Env, steps: int) -> Any:
    """The thesis's DQN on ``env`` (one torch thread), keeping the schedules (epsilon) of one
    ``steps``-step run when it is trained in chunks."""
    import torch
    from stable_baselines3 import DQN

    class ChunkedDQN(DQN):
        def _update_current_progress_remaining(self, num_timesteps: int, total: int) -> None:
            super()._update_current_progress_remaining(num_timesteps, steps)

    torch.set_num_threads(1)
    return ChunkedDQN(
        "MultiInputPolicy",
        env,
        learning_rate=5e-5,
        exploration_fraction=0.7,
        exploration_final_eps=0.05,
        batch_size=64,
        buffer_size=50_000,
        target_update_interval=500,
        train_freq=4,
        learning_starts=1000,
        seed=0,
        verbose=0,
    )


def train_interleaved(envs: dict[str, gym.Env], steps: int, chunks: int) -> dict[str, list[float]]:
    """Train one thesis DQN per env in rotating chunks of ``steps / chunks`` steps, each model
    continuing its own run, so the drifting speed of these shared machines hits all alike;
    the seconds of every chunk, by env name."""
    models = {}
    for name, env in envs.items():
        # One-time costs stay out of the timing: the first reset of a process loads the
        # compiled kernels (~0.25 s, once per process, but ~1.5 % of a short run).
        env.reset(seed=0)
        models[name] = thesis_dqn(env, steps)
    names = list(models)
    seconds: dict[str, list[float]] = {name: [] for name in names}
    per_chunk = -(-steps // chunks)
    for chunk in range(chunks):
        shift = chunk % len(names)
        for name in names[shift:] + names[:shift]:
            start = time.perf_counter()
            models[name].learn(total_timesteps=per_chunk, reset_num_timesteps=chunk == 0)
            seconds[name].append(time.perf_counter() - start)
    return seconds


def dqn_env_share(steps: int, chunks: int = 15) -> dict[str, Any]:
    """Train the thesis's DQN on the env and on a null env with the same spaces, interleaved
    (:func:`train_interleaved`): back-to-back runs disagreed by several points."""
    real = frontier_marl.FrontierExploreEnv(preset="thesis-20x20", info="minimal")
    seconds = train_interleaved({"null": NullEnv(real), "env": real}, steps, chunks)
    timings = {name: sum(chunk) for name, chunk in seconds.items()}
    share = (timings["env"] - timings["null"]) / timings["env"]
    # The spread of the share between chunk pairs tells how far to trust it on this machine.
    chunk_shares = np.array(
        [(e - n) / e for n, e in zip(seconds["null"], seconds["env"], strict=True)]
    )
    trained = chunks * -(-steps // chunks)
    return {
        "steps": trained,
        "chunks": chunks,
        "seconds_null": timings["null"],
        "seconds_env": timings["env"],
        "steps_per_s_env": trained / timings["env"],
        "env_share": share,
        "env_share_standard_error": float(chunk_shares.std(ddof=1) / np.sqrt(chunks))
        if chunks > 1
        else float("nan"),
        "env_share_by_chunk": chunk_shares.tolist(),
    }


def _parse_args(argv: list[str] | None, explore_bench_map: Path | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=8.0, help="timed seconds per setting")
    parser.add_argument("--dqn-steps", type=int, default=30_000)
    parser.add_argument(
        "--dqn-chunks", type=int, default=15, help="alternating chunks of the two DQN runs"
    )
    parser.add_argument("--skip-dqn", action="store_true")
    parser.add_argument("--json", help="write the figures to this file")
    parser.add_argument(
        "--explore-bench-map",
        type=Path,
        default=explore_bench_map,
        help="Explore-Bench PGM map for the side-by-side figure (skipped if absent)",
    )
    return parser.parse_args(argv)


def _decision_rows(
    settings: list[tuple[str, dict[str, Any]]], seconds: float
) -> list[dict[str, Any]]:
    """Decisions per second of the nearest and the random rule in every setting, printed."""
    rows = []
    print(f"{'setting':<24}{'policy':<10}{'decisions/s':>12}{'us/decision':>13}")
    for label, kwargs in settings:
        for policy_name, policy in (("nearest", nearest), ("random", random_valid)):
            row = decisions_per_second(kwargs, policy, seconds)
            rows.append({"setting": label, "policy": policy_name, **row})
            print(
                f"{label:<24}{policy_name:<10}{row['decisions_per_s']:>12.0f}"
                f"{row['us_per_decision']:>13.1f}"
            )
    return rows


def _print_dqn(dqn: dict[str, Any]) -> None:
    print(
        f"DQN {dqn['steps']} steps: null env {dqn['seconds_null']:.1f} s, "
        f"thesis-20x20 env {dqn['seconds_env']:.1f} s "
        f"({dqn['steps_per_s_env']:.0f} steps/s); env share {100 * dqn['env_share']:.1f} % "
        f"(standard error over the chunks {100 * dqn['env_share_standard_error']:.1f})"
    )


def main(argv: list[str] | None = None, *, explore_bench_map: Path | None = None) -> int:
    """The command line of ``benchmarks/bench_env.py``, which passes Explore-Bench's
    room1_modified map beside the repository as ``explore_bench_map`` (the default of
    ``--explore-bench-map``)."""
    args = _parse_args(argv, explore_bench_map)
    settings = list(SETTINGS)
    if args.explore_bench_map is not None and args.explore_bench_map.is_file():
        settings += explore_bench_settings(args.explore_bench_map)
    report: dict[str, Any] = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "decisions": _decision_rows(settings, args.seconds),
    }
    if not args.skip_dqn:
        dqn = dqn_env_share(args.dqn_steps, args.dqn_chunks)
        report["dqn"] = dqn
        _print_dqn(dqn)
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(report, handle, indent=2)
    return 0
