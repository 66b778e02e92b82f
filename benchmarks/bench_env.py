"""Speed benchmark of the simulator (docs/performance.md). Not a test: run it by hand.

    python benchmarks/bench_env.py                 # everything, ~3 minutes on 2 cores
    python benchmarks/bench_env.py --skip-dqn      # decisions per second only
    python benchmarks/bench_env.py --json out.json

Adds Explore-Bench's room1_modified map when ../shared/maps/explore-bench (beside the
repository) has it. What it measures: :mod:`frontier_marl.experiments.speed.bench_env`.
"""

from pathlib import Path

from frontier_marl.experiments.speed.bench_env import main

if __name__ == "__main__":
    shared_maps = Path(__file__).resolve().parents[2] / "shared/maps/explore-bench"
    raise SystemExit(main(explore_bench_map=shared_maps / "room1_modified.pgm"))
