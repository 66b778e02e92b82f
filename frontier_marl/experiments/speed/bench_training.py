"""Training speed benchmark: steps per second and where the time goes.

    python benchmarks/bench_training.py                       # config01, 20 000 steps
    python benchmarks/bench_training.py config04 --steps 50000 --json speed.json
    python benchmarks/bench_training.py --stages   # also time the stages inside the env step

Runs the real training loop (``frontier_marl.training.train.train``, no evaluation, no
checkpoints, the SuperSuit pipeline: ``train.vec_env=supersuit``; the batched env has its own
benchmark, ``bench_vector_env.py``) and times, inside it, the env (the FrontierParallelEnv step
itself), the SuperSuit and SB3 vector layers above it, and the DQN gradient steps; the rest is
SB3's collection loop (action selection, replay buffer, logging). ``--stages`` also times the
parts of a decision step (the compiled call before the labelling: decisions, movement and
sensing, frontier masks; ``scipy.ndimage.label``; the compiled call after it: clusters, slots,
explored fraction, reward table; the observations; the info dicts) and the episode resets.
Wall and CPU times are both reported: on a shared machine the CPU time is the steadier number.
Run one benchmark at a time."""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import stable_baselines3
from stable_baselines3 import DQN

from frontier_marl.core import worlds
from frontier_marl.envs import parallel
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.sim import batch_engine, engine
from frontier_marl.training import vec_env as vec_module
from frontier_marl.training.experiment import Experiment, load_experiment
from frontier_marl.training.results import TrainResult
from frontier_marl.training.train import train


class Timer:
    """Accumulates the duration of calls to a wrapped function."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self.calls = 0
        self.first_call_seconds = 0.0  # the first reset of a process loads the compiled kernels

    def wrap(self, fn):  # noqa: ANN001, ANN202
        def timed(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
            start = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                elapsed = time.perf_counter() - start
                if not self.calls:
                    self.first_call_seconds = elapsed
                self.seconds += elapsed
                self.calls += 1

        return timed


def stage_functions() -> list[tuple[object, str]]:
    """(owner, attribute) of the functions ``--stages`` times; the first two cover the rest."""
    return [
        (batch_engine, "before_labelling"),  # decisions, planning, walking, sensing, masks
        (worlds.Worlds, "label_stale"),  # the frontier masks labelled (ndimage.label)
        (batch_engine, "after_labelling"),  # clusters, slots, explored fraction, reward table
        (batch_engine.BatchMDP, "observations"),
        (parallel, "build_infos"),  # the info dicts
        (engine.ExplorationMDP, "reset"),
    ]


def _parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("config", nargs="?", default="config01")
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--set", dest="overrides", action="append", default=[])
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--stages", action="store_true", help="time the stages of a step too")
    return parser.parse_args(argv)


def _experiment(args: argparse.Namespace) -> Experiment:
    """The config with the benchmark's budget and seed, no evaluation or checkpoints."""
    return load_experiment(
        args.config,
        [
            *args.overrides,
            f"train.total_timesteps={args.steps}",
            f"train.seed={args.seed}",
            "train.eval_episodes=0",
            "train.checkpoint_every=0",
            "train.vec_env=supersuit",  # the layers timed below are SuperSuit's
        ],
    )


@dataclass
class _Timers:
    """The env step, the vector layers' step, the gradient steps and (``--stages``) the stages."""

    env: Timer = field(default_factory=Timer)
    vec: Timer = field(default_factory=Timer)
    grad: Timer = field(default_factory=Timer)
    stages: dict[str, Timer] = field(default_factory=dict)


@contextmanager
def _timed(stages: bool) -> Iterator[_Timers]:
    """Wrap the timed functions in timers while the block runs; restore them afterwards."""
    timers = _Timers()
    originals = (FrontierParallelEnv.step, DQN.train, vec_module.make_vec_env)
    FrontierParallelEnv.step = timers.env.wrap(FrontierParallelEnv.step)
    DQN.train = timers.grad.wrap(DQN.train)

    def make_timed_vec_env(*a, **kw):  # noqa: ANN002, ANN003, ANN202
        vec = originals[2](*a, **kw)
        vec.step_wait = timers.vec.wrap(vec.step_wait)
        return vec

    vec_module.make_vec_env = make_timed_vec_env
    patched: list[tuple[object, str, object]] = []
    if stages:
        for owner, name in stage_functions():
            timer = timers.stages[name] = Timer()
            original = getattr(owner, name)
            patched.append((owner, name, original))
            setattr(owner, name, timer.wrap(original))
    try:
        yield timers
    finally:
        FrontierParallelEnv.step, DQN.train, vec_module.make_vec_env = originals
        for owner, name, original in patched:
            setattr(owner, name, original)


def _report(experiment: Experiment, result: TrainResult, timers: _Timers) -> dict[str, Any]:
    """Speed, time shares and per-call costs of the run, and versions."""
    wall, cpu, steps = result.wall_time_s, result.cpu_time_s, result.steps_this_session
    env, vec, grad = timers.env, timers.vec, timers.grad
    return {
        "config": experiment.name,
        "steps": steps,
        "wall_time_s": round(wall, 2),
        "cpu_time_s": round(cpu, 2),
        "steps_per_second_wall": round(steps / wall, 1),
        "steps_per_second_cpu": round(steps / cpu, 1),
        "projected_1e6_minutes_cpu": round(1e6 / (steps / cpu) / 60, 1),
        "share_env": round(env.seconds / wall, 3),
        "share_vector_layers": round((vec.seconds - env.seconds) / wall, 3),
        "share_gradient_steps": round(grad.seconds / wall, 3),
        "share_rest_of_sb3": round(1 - (vec.seconds + grad.seconds) / wall, 3),
        "us_per_env_step": round(env.seconds / max(env.calls, 1) * 1e6, 1),
        "us_per_gradient_step": round(grad.seconds / max(grad.calls, 1) * 1e6, 1),
        "torch_threads": experiment.train.torch_threads,
        "stable_baselines3": stable_baselines3.__version__,
        "python": sys.version.split()[0],
    }


def _stage_report(timers: _Timers) -> dict[str, dict[str, Any]]:
    """Each stage's calls and costs, without its first call (one-time costs, kernel loading)."""
    return {
        name: {
            "calls": max(timer.calls - 1, 0),
            "us_per_call": round(later / max(timer.calls - 1, 1) * 1e6, 1),
            "us_per_env_step": round(later / max(timers.env.calls, 1) * 1e6, 1),
            "first_call_ms": round(timer.first_call_seconds * 1e3, 1),
        }
        for name, timer in timers.stages.items()
        for later in [timer.seconds - timer.first_call_seconds]
    }


def _print_report(report: dict[str, Any]) -> None:
    for key, value in report.items():
        if key != "stages":
            print(f"{key:>28}: {value}")
    for name, row in report["stages"].items():
        print(
            f"{name:>28}: {row['us_per_env_step']:6.1f} µs per env step "
            f"({row['calls']} calls, {row['us_per_call']} µs each; "
            f"first call {row['first_call_ms']} ms, not counted)"
        )


def main(argv: list[str] | None = None) -> int:
    args = _parse_args(argv)
    experiment = _experiment(args)
    with _timed(args.stages) as timers, tempfile.TemporaryDirectory() as tmp:
        result = train(experiment, Path(tmp) / "run", progress_bar=False)
    report = _report(experiment, result, timers)
    report["stages"] = _stage_report(timers)
    _print_report(report)
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0
