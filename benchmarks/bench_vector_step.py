"""Where one step of the batched env goes, part by part.

    python benchmarks/bench_vector_step.py --worlds 8 --steps 5000

What it measures: :mod:`frontier_marl.experiments.speed.bench_vector_step`.
"""

from frontier_marl.experiments.speed.bench_vector_step import main

if __name__ == "__main__":
    raise SystemExit(main())
