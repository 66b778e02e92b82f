"""The map scorer's fit: seconds per epoch on one torch thread.

    python benchmarks/bench_map_scorer_fit.py --json fit.json

What it times: :mod:`frontier_marl.experiments.speed.bench_map_scorer_fit`.
"""

from frontier_marl.experiments.speed.bench_map_scorer_fit import main

if __name__ == "__main__":
    raise SystemExit(main())
