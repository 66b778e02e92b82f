"""The same rooms layouts on ever finer grids: where cost-utility overtakes nearest-path.

For every scale K of ``--scales``, the ``rooms-32`` family drawn K times finer
(``map_scale=K``, a 32K x 32K grid: walls and doors K cells thick) with a sensor range of
``round(13 K / 3)`` cells, so that the sensor spans about 4.3 cells of the layout at every
scale (13 cells at K = 3, as in the ``rooms-96-fine`` family; about 31 at K = 7, the
Explore-Bench floor plans' ratio). Validation episodes only::

    python benchmarks/resolution_sweep.py --scales 1,2,3,4,6 --episodes 24 \\
        --policies cost-utility,nearest-path,explorer \\
        --json training/results/explorer/resolution-sweep.json
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

from frontier_marl.cli import main as cli


def sensor_range(scale: int) -> int:
    """The sensor range at ``scale``: about 4.3 layout cells."""
    return round(13 * scale / 3)


def benchmark_at(scale: int, policies: str, episodes: int, out: Path) -> list[dict]:
    """The benchmark rows of ``policies`` on rooms-32 layouts drawn ``scale`` times finer."""
    side = 32 * scale
    command = ["benchmark", "--families", "rooms-32", "--split", "validation"]
    for key, value in (("map_scale", scale), ("height", side), ("width", side)):
        command += ["--set", f"{key}={value}"]
    command += ["--set", f"perception_range={sensor_range(scale)}"]
    command += ["--episodes", str(episodes), "--policies", policies, "--json", str(out)]
    if cli([*command, "--no-progress"]) != 0:
        raise SystemExit(f"the benchmark failed at scale {scale}")
    return json.loads(out.read_text())["rows"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scales", default="1,2,3,4,6", help="comma-separated scales K")
    parser.add_argument("--episodes", type=int, default=24, help="validation episodes per scale")
    parser.add_argument("--policies", default="cost-utility,nearest-path,explorer")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    try:
        scales = [int(k) for k in args.scales.split(",")]
    except ValueError:
        parser.error(f"--scales must be comma-separated integers, got {args.scales!r}")
    summary = []
    with tempfile.TemporaryDirectory() as folder:
        for scale in scales:
            for row in benchmark_at(scale, args.policies, args.episodes, Path(folder) / "b.json"):
                best = row.get("vs_best") or {}
                summary.append(
                    {
                        "scale": scale,
                        "perception_range": sensor_range(scale),
                        "policy": row["policy"],
                        "success": row["success"],
                        "t99_mean": row["t99_mean"],
                        "vs_best_mean": best.get("mean"),
                        "vs_best_ci": [best["ci_low"], best["ci_high"]] if best else None,
                        "best_heuristic": row["best_heuristic"],
                    }
                )
    if args.json is not None:
        options = {"scales": scales, "episodes": args.episodes, "policies": args.policies}
        args.json.write_text(json.dumps({"options": options, "rows": summary}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
