"""The map scorer's fit: seconds per epoch on one torch thread, the shipped fit's settings.

    python benchmarks/bench_map_scorer_fit.py                       # ~1 minute
    python benchmarks/bench_map_scorer_fit.py --labels runs/x/labels/round0.npz --json fit.json

Labels ``--episodes`` rooms-32 training episodes on the true map (frontier-rule playing, as
round 0 of ``frontier-marl train explorer`` does), or loads a run's ``--labels``, then times
:func:`~frontier_marl.training.cost_regression.fitted` over ``--epochs`` epochs (the labelling
is not timed). Reports decisions, candidates, the valid share of the decisions' slots (the
fit convolves only the valid candidates' crops) and the seconds per epoch.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from frontier_marl.evaluation.benchmark.families import family
from frontier_marl.policies.map_explorer import MAP_EXPLORER_SETTINGS
from frontier_marl.training.cost_regression import fitted, label_round
from frontier_marl.training.cost_to_go import Samples
from frontier_marl.training.settings import RegressionSettings


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--labels", type=Path, help="a run's labels (RUN/labels/round0.npz)")
    parser.add_argument("--episodes", type=int, default=160, help="rooms-32 episodes to label")
    parser.add_argument("--epochs", type=int, default=1)
    parser.add_argument("--json", type=Path, help="write the report here")
    args = parser.parse_args(argv)
    if args.episodes < 1 or args.epochs < 1:
        parser.error("--episodes and --epochs must be at least 1")
    return args


def rooms_labels(episodes: int) -> Samples:
    """True-map labels of ``episodes`` rooms-32 training episodes, on two processes."""
    seeds = np.asarray(family("rooms-32").train)[:episodes]
    reg = RegressionSettings(completions=0, label_workers=2)
    return label_round([("rooms-32", int(seed)) for seed in seeds], None, reg, 0)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    samples = Samples.load(args.labels) if args.labels else rooms_labels(args.episodes)
    decisions = len(np.unique(samples.decision))
    reg = RegressionSettings(fit_epochs=args.epochs)
    started = time.perf_counter()
    fitted(samples, reg, 0)
    seconds = time.perf_counter() - started
    report = {
        "decisions": decisions,
        "candidates": len(samples),
        "valid_share": len(samples) / (decisions * int(MAP_EXPLORER_SETTINGS["n_slots"])),
        "epochs": args.epochs,
        "seconds_per_epoch": seconds / args.epochs,
    }
    print(
        f"{decisions:,} decisions, {len(samples):,} candidates "
        f"({report['valid_share']:.0%} of the slots valid): "
        f"{report['seconds_per_epoch']:.1f} s per epoch on one torch thread"
    )
    if args.json:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0
