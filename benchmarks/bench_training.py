"""Training speed benchmark: steps per second and where the time goes.

    python benchmarks/bench_training.py                       # config01, 20 000 steps
    python benchmarks/bench_training.py config04 --steps 50000 --json speed.json

Runs the real training loop (``frontier_marl.training.train.train``, no evaluation, no
checkpoints) and times, inside it, the env (the FrontierParallelEnv step itself), the SuperSuit
and SB3 vector layers above it, and the DQN gradient steps; the rest is SB3's collection loop
(action selection, replay buffer, logging). Wall and CPU times are both reported: on a shared
machine the CPU time is the steadier number. Run one benchmark at a time.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

from frontier_marl.training.experiment import load_experiment
from frontier_marl.training.train import train


class Timer:
    """Accumulates the duration of calls to a wrapped function."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self.calls = 0

    def wrap(self, fn):  # noqa: ANN001, ANN202
        def timed(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
            start = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - start
                self.calls += 1

        return timed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", nargs="?", default="config01")
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--set", dest="overrides", action="append", default=[])
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)

    import stable_baselines3
    from stable_baselines3 import DQN

    from frontier_marl.envs.parallel import FrontierParallelEnv
    from frontier_marl.training import vec_env as vec_module

    experiment = load_experiment(
        args.config,
        [
            *args.overrides,
            f"train.total_timesteps={args.steps}",
            f"train.seed={args.seed}",
            "train.eval_episodes=0",
            "train.checkpoint_every=0",
        ],
    )
    env_timer, vec_timer, grad_timer = Timer(), Timer(), Timer()
    originals = (FrontierParallelEnv.step, DQN.train, vec_module.make_vec_env)
    FrontierParallelEnv.step = env_timer.wrap(FrontierParallelEnv.step)
    DQN.train = grad_timer.wrap(DQN.train)

    def make_timed_vec_env(*a, **kw):  # noqa: ANN002, ANN003, ANN202
        vec = originals[2](*a, **kw)
        vec.step_wait = vec_timer.wrap(vec.step_wait)
        return vec

    vec_module.make_vec_env = make_timed_vec_env
    try:
        with tempfile.TemporaryDirectory() as tmp:
            result = train(experiment, Path(tmp) / "run", progress_bar=False)
    finally:
        FrontierParallelEnv.step, DQN.train, vec_module.make_vec_env = originals

    wall, cpu, steps = result.wall_time_s, result.cpu_time_s, result.steps_this_session
    report = {
        "config": experiment.name,
        "steps": steps,
        "wall_time_s": round(wall, 2),
        "cpu_time_s": round(cpu, 2),
        "steps_per_second_wall": round(steps / wall, 1),
        "steps_per_second_cpu": round(steps / cpu, 1),
        "projected_1e6_minutes_cpu": round(1e6 / (steps / cpu) / 60, 1),
        "share_env": round(env_timer.seconds / wall, 3),
        "share_vector_layers": round((vec_timer.seconds - env_timer.seconds) / wall, 3),
        "share_gradient_steps": round(grad_timer.seconds / wall, 3),
        "share_rest_of_sb3": round(1 - (vec_timer.seconds + grad_timer.seconds) / wall, 3),
        "us_per_env_step": round(env_timer.seconds / max(env_timer.calls, 1) * 1e6, 1),
        "us_per_gradient_step": round(grad_timer.seconds / max(grad_timer.calls, 1) * 1e6, 1),
        "torch_threads": experiment.train.torch_threads,
        "stable_baselines3": stable_baselines3.__version__,
        "python": sys.version.split()[0],
    }
    for key, value in report.items():
        print(f"{key:>28}: {value}")
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
