"""Wall time of ``lookahead-oracle`` per episode, this tree against another checkout.

    python benchmarks/bench_oracle.py                          # this tree alone
    python benchmarks/bench_oracle.py --old ../frontier_marl-main --rounds 2 --json oracle.json

Runs the oracle on the first ``--episodes`` validation episodes of ``--family`` (rooms-64 by
default) in a fresh process per tree and round (``PYTHONPATH`` set to the tree), alternating
the trees, after one warm-up episode per tree (numba's compile), and reports the best seconds
per episode of each, their ratio, and whether both trees gave the same per-episode T99.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

_CHILD = """
import json, sys, time
import frontier_marl
from frontier_marl.evaluation.benchmark.families import family, variant_configs
from frontier_marl.evaluation.benchmark.run import oracle, run_family
fam = family(sys.argv[1])
configs = variant_configs(fam, None, 1)
run_family(fam, oracle(), configs, 1, split="validation")  # warm: numba's compile and caches
start = time.perf_counter()
result = run_family(fam, oracle(), configs, int(sys.argv[2]), split="validation")
seconds = time.perf_counter() - start
t99 = [e.cells_to_coverage["0.99"] for e in result.episodes]
print(json.dumps({"seconds": seconds, "t99": t99, "package": frontier_marl.__file__}))
"""


def run_tree(tree: Path, family: str, episodes: int) -> dict[str, Any]:
    """One timed run of the oracle in a fresh process importing ``tree``'s package (run from
    the tree: ``python -c`` puts its working folder first on the path)."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    args = [sys.executable, "-c", _CHILD, family, str(episodes)]
    done = subprocess.run(args, env=env, cwd=tree, check=True, capture_output=True, text=True)
    report: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    if not Path(report.pop("package")).is_relative_to(tree):
        raise RuntimeError(f"{tree}: the timed process imported another frontier_marl")
    return report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--family", default="rooms-64")
    parser.add_argument("--episodes", type=int, default=3)
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--old", type=Path, default=None, help="another checkout to compare")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    trees = {"new": Path(__file__).resolve().parents[3]}
    if args.old is not None:
        trees["old"] = args.old.resolve()
    runs: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
    for _ in range(args.rounds):
        for name, tree in trees.items():
            runs[name].append(run_tree(tree, args.family, args.episodes))
            best = min(r["seconds"] for r in runs[name]) / args.episodes
            print(f"{name}: {best:.2f} s per episode, T99 {runs[name][-1]['t99']}", flush=True)
    report: dict[str, Any] = {"family": args.family, "episodes": args.episodes, "runs": runs}
    if "old" in runs:
        old = min(r["seconds"] for r in runs["old"])
        new = min(r["seconds"] for r in runs["new"])
        report.update(ratio=old / new, same_t99=runs["old"][0]["t99"] == runs["new"][0]["t99"])
        print(f"ratio old/new {report['ratio']:.1f}x, same T99: {report['same_t99']}")
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    print(f"({time.strftime('%H:%M:%S')})")
    return 0
