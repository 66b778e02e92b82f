"""The same layouts on ever finer grids: where cost-utility overtakes nearest-path.

For every scale K of ``--scales``, the layouts of ``--layouts`` drawn K times finer
(``map_scale=K``, walls and doors K cells thick) with the sensor range scaled with them:

* ``rooms``: the ``rooms-32`` family on a 32K x 32K grid, r = ``round(13 K / 3)`` (about 4.3
  layout cells at every scale: 13 cells at K = 3, as in ``rooms-96-fine``; about 31 at K = 7,
  the Explore-Bench floor plans' ratio);
* ``floorplan``: the ``floorplan-96`` family's 48 x 48 buildings on a 48K x 48K grid,
  r = ``round(13 K / 2)`` (13 cells at K = 2, as in ``floorplan-96``; 32 at K = 5, a 240-cell
  grid: the Explore-Bench floor plans' size and sensor).

Validation episodes only, from ``--first`` (default 800,000)::

    python benchmarks/resolution_sweep.py --scales 1,2,3,4,6 --episodes 24 \\
        --policies cost-utility,nearest-path,explorer \\
        --json training/results/explorer/resolution-sweep.json
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

from frontier_marl.evaluation.benchmark.families import VALIDATION_SEEDS, family
from frontier_marl.evaluation.benchmark.run import contenders, run_benchmark

#: layouts: (family, layout side in cells, sensor range per scale step)
LAYOUTS = {"rooms": ("rooms-32", 32, 13 / 3), "floorplan": ("floorplan-96", 48, 13 / 2)}


def sensor_range(scale: int, layouts: str = "rooms") -> int:
    """The sensor range at ``scale``: the same span of the layout at every scale."""
    return round(LAYOUTS[layouts][2] * scale)


def benchmark_at(scale: int, layouts: str, policies: str, episodes: int, first: int) -> list[dict]:
    """The benchmark rows of ``policies`` on ``layouts`` drawn ``scale`` times finer, on the
    validation episodes from seed ``first``."""
    name, side, _ = LAYOUTS[layouts]
    fam = replace(family(name), validation=range(first, VALIDATION_SEEDS.stop))
    overrides = {
        "map_scale": scale,
        "height": side * scale,
        "width": side * scale,
        "perception_range": sensor_range(scale, layouts),
    }
    return run_benchmark(
        [fam], contenders(policies.split(",")), episodes, overrides=overrides, split="validation"
    )


def _parse_args(argv: list[str] | None) -> tuple[argparse.Namespace, list[int]]:
    """The options, with the checked scales."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scales", default="1,2,3,4,6", help="comma-separated scales K")
    parser.add_argument("--layouts", choices=sorted(LAYOUTS), default="rooms")
    parser.add_argument("--episodes", type=int, default=24, help="validation episodes per scale")
    parser.add_argument("--first", type=int, default=VALIDATION_SEEDS.start)
    parser.add_argument("--policies", default="cost-utility,nearest-path,explorer")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    try:
        scales = [int(k) for k in args.scales.split(",")]
    except ValueError:
        parser.error(f"--scales must be comma-separated integers, got {args.scales!r}")
    if not VALIDATION_SEEDS.start <= args.first < VALIDATION_SEEDS.stop:
        parser.error(f"--first must be a validation seed, in {VALIDATION_SEEDS}")
    return args, scales


def _summary_row(scale: int, layouts: str, row: dict[str, Any]) -> dict[str, Any]:
    """One policy's benchmark row at ``scale``, in brief."""
    best = row.get("vs_best") or {}
    return {
        "scale": scale,
        "perception_range": sensor_range(scale, layouts),
        "policy": row["policy"],
        "success": row["success"],
        "t99_mean": row["t99_mean"],
        "vs_best_mean": best.get("mean"),
        "vs_best_ci": [best["ci_low"], best["ci_high"]] if best else None,
        "best_heuristic": row["best_heuristic"],
    }


def main(argv: list[str] | None = None) -> int:
    args, scales = _parse_args(argv)
    summary = []
    for scale in scales:
        for row in benchmark_at(scale, args.layouts, args.policies, args.episodes, args.first):
            summary.append(_summary_row(scale, args.layouts, row))
        mine = [row for row in summary if row["scale"] == scale]
        cells = ", ".join(f"{row['policy']} {row['t99_mean']:.1f}" for row in mine)
        print(f"K = {scale}: {cells}", flush=True)
    if args.json is not None:
        options = {
            "scales": scales,
            "layouts": args.layouts,
            "episodes": args.episodes,
            "first_seed": args.first,
            "policies": args.policies,
        }
        args.json.write_text(json.dumps({"options": options, "rows": summary}, indent=1))
    return 0
