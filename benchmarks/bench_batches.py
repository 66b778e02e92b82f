"""Decisions per second of the batched env at batch 1, 8 and 64, and memory per world.

    python benchmarks/bench_batches.py --seconds 3 --json batches.json

What it measures: :mod:`frontier_marl.experiments.speed.bench_batches`.
"""

from frontier_marl.experiments.speed.bench_batches import main

if __name__ == "__main__":
    raise SystemExit(main())
