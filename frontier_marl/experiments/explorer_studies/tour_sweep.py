"""How T99 depends on the tour weight of the hand-set rule, family by family, on training seeds.

Scores nearest-path and the rule "path -1, tour W" for every W of ``--weights`` on the same
training episodes of every family (seeds from ``--first``, default 700,000; the held-out and
validation seeds are never touched). A flat response says a linear scorer on these two
features has no better weight to find for any family::

    python benchmarks/explorer_tour_sweep.py --weights=-0.25,-0.5,-0.75,-1.0 --episodes 64 \\
        --json training/results/explorer/tour-sweep.json
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from frontier_marl.evaluation.benchmark.families import TRAIN_SEEDS
from frontier_marl.evaluation.benchmark.run import run_on_seeds
from frontier_marl.evaluation.benchmark.stats import format_table
from frontier_marl.training.cem import save_hand_set
from frontier_marl.training.experiment import load_experiment


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--weights", default="-0.25,-0.5,-0.75,-1.0", help="tour weights")
    parser.add_argument("--episodes", type=int, default=64, help="training episodes per family")
    parser.add_argument("--first", type=int, default=700_000, help="first training seed")
    parser.add_argument("--out", type=Path, default=Path("runs/explorer-tour-sweep"))
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    if not TRAIN_SEEDS.start <= args.first < TRAIN_SEEDS.stop:
        parser.error(f"--first must be a training seed, in {TRAIN_SEEDS}")
    try:
        weights = [float(w) for w in args.weights.split(",")]
    except ValueError:
        parser.error(f"--weights must be comma-separated numbers, got {args.weights!r}")
    experiment = load_experiment("explorer-cem")
    folders = []
    for weight in weights:
        folder = args.out / f"tour{weight:+g}"
        save_hand_set({"path": -1.0, "tour": weight}, folder, experiment)
        folders.append(str(folder))
    seeds = range(args.first, TRAIN_SEEDS.stop)
    rows = run_on_seeds(["nearest-path", *folders], seeds, args.episodes, not args.no_progress)
    print(format_table(rows))
    if args.json is not None:
        summary = [{k: v for k, v in row.items() if k != "per_episode"} for row in rows]
        options = {"weights": weights, "episodes": args.episodes, "first_seed": args.first}
        args.json.write_text(json.dumps({"options": options, "rows": summary}, indent=1))
    return 0
