"""Choose between explorer candidates on validation episodes no training run has used (beside
frontier-rule, the linear ``explorer`` until the map-aware model replaced it).

``frontier-marl train`` validates on the first validation seeds of each family (800,000 and
up; the explorer configs use at most 48), and keeps the generation that scores best there, so
those episodes flatter the models they selected. This script scores candidates on the
validation seeds from ``--first`` (default 800,100) on, the same episodes for every policy::

    cp -r runs/explorer-turn/best runs/explorer-turn-best   # a model is labelled by its folder
    python benchmarks/explorer_selection.py --episodes 128 \\
        --models runs/explorer-ablation/tour-rule,runs/explorer-turn-best \\
        --json training/results/explorer/selection-turn.json

``--heuristics`` names the heuristics to compare with (default nearest-path, the best on the
coarse families; add cost-utility, the best on the fine grids). Held-out seeds (900,000 and
up) are never touched.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from frontier_marl.evaluation.benchmark.families import VALIDATION_SEEDS
from frontier_marl.evaluation.benchmark.run import run_on_seeds
from frontier_marl.evaluation.benchmark.stats import format_table


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=128, help="episodes per family")
    parser.add_argument("--first", type=int, default=VALIDATION_SEEDS.start + 100)
    parser.add_argument("--models", default="", help="comma-separated model folders or names")
    parser.add_argument(
        "--heuristics", default="nearest-path", help="comma-separated heuristics to compare with"
    )
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    if not VALIDATION_SEEDS.start <= args.first < VALIDATION_SEEDS.stop:
        parser.error(f"--first must be a validation seed, in {VALIDATION_SEEDS}")
    heuristics = [h for h in args.heuristics.split(",") if h]
    if not heuristics:
        parser.error("--heuristics must name at least one heuristic")
    names = [*heuristics, "frontier-rule", *[m for m in args.models.split(",") if m]]
    seeds = range(args.first, VALIDATION_SEEDS.stop)
    rows = run_on_seeds(names, seeds, args.episodes, progress=not args.no_progress)
    print(format_table(rows))
    means: dict[str, list[float]] = {}
    for row in rows:
        if row.get("vs_best"):
            means.setdefault(row["policy"], []).append(row["vs_best"]["mean"])
    for policy, values in means.items():
        mean = 100 * sum(values) / len(values)
        print(f"{policy}: mean T99 vs each family's best heuristic {mean:+.2f} %")
    if args.json is not None:
        summary = [{k: v for k, v in row.items() if k != "per_episode"} for row in rows]
        command = {"episodes": args.episodes, "first_seed": args.first, "models": names}
        args.json.write_text(json.dumps({"options": command, "rows": summary}, indent=1))
    return 0
