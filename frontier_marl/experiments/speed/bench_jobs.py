"""What ``frontier-marl benchmark --jobs N`` gains over ``--jobs 1``, runs alternated.

    python benchmarks/bench_jobs.py                             # ~2 min on 2 idle cores
    python benchmarks/bench_jobs.py --jobs 2 --repeats 3 --json bench_jobs.json

Each repeat runs the same small benchmark (``--families``, ``--policies``, ``--episodes``) as a
fresh command once with ``--jobs 1`` and once with ``--jobs N``, alternating which goes first,
and records the wall time, the CPU time of the command and its workers, and the 1-minute load
average before each run (other work on the machine slows both, and the parallel run more). The
rows of the two runs must be identical (the JSON's ``wall_seconds`` aside).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

FAMILIES = "random-20,rooms-32"
POLICIES = "nearest-path,cost-utility,frontier-rule"


def command(args: argparse.Namespace, jobs: int, out: Path) -> list[str]:
    """The benchmark command line of one run."""
    return [
        *(sys.executable, "-m", "frontier_marl", "benchmark"),
        *("--families", args.families, "--policies", args.policies),
        *("--episodes", str(args.episodes), "--jobs", str(jobs), "--no-progress"),
        *("--json", str(out)),
    ]


def timed_run(args: argparse.Namespace, jobs: int, out: Path) -> dict[str, Any]:
    """Wall and CPU seconds of one run (its workers included: they are its children)."""
    load = os.getloadavg()[0]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command(args, jobs, out), check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"jobs": jobs, "wall_s": wall, "cpu_s": cpu, "load_before": load}


def rows(path: Path) -> list[dict[str, Any]]:
    found = json.loads(path.read_text())["rows"]
    for row in found:
        row.pop("wall_seconds")
    return found


def measure(args: argparse.Namespace) -> dict[str, Any]:
    """The alternated runs and the speedup of each pair (wall of jobs 1 / wall of jobs N)."""
    runs, pairs = [], []
    with tempfile.TemporaryDirectory() as folder:
        for repeat in range(args.repeats):
            order = (1, args.jobs) if repeat % 2 == 0 else (args.jobs, 1)
            pair = {jobs: timed_run(args, jobs, Path(folder) / f"{jobs}.json") for jobs in order}
            if rows(Path(folder) / "1.json") != rows(Path(folder) / f"{args.jobs}.json"):
                raise SystemExit("the rows differ between --jobs 1 and --jobs N")
            runs += [pair[jobs] for jobs in order]
            pairs.append(pair[1]["wall_s"] / pair[args.jobs]["wall_s"])
            print(f"repeat {repeat}: " + ", ".join(_line(pair[j]) for j in order))
    return {"runs": runs, "speedups": pairs}


def _line(run: dict[str, Any]) -> str:
    return (
        f"--jobs {run['jobs']} {run['wall_s']:.1f} s wall, {run['cpu_s']:.1f} s CPU "
        f"(load {run['load_before']:.1f})"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2, help="the parallel run's --jobs")
    parser.add_argument("--repeats", type=int, default=3, help="pairs of runs")
    parser.add_argument("--families", default=FAMILIES)
    parser.add_argument("--policies", default=POLICIES)
    parser.add_argument("--episodes", type=int, default=10)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    if args.jobs < 2 or args.repeats < 1 or args.episodes < 1:
        parser.error("--jobs must be >= 2, --repeats and --episodes >= 1")
    result = measure(args)
    speedups = sorted(result["speedups"])
    print(
        f"speedup of --jobs {args.jobs}: median {speedups[len(speedups) // 2]:.2f}x "
        f"(pairs: {', '.join(f'{s:.2f}' for s in result['speedups'])})"
    )
    if args.json is not None:
        options = {k: v for k, v in vars(args).items() if k != "json"}
        args.json.write_text(json.dumps({"options": options, **result}, indent=1) + "\n")
    return 0
