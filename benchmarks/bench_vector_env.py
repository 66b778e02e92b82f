"""Speed of the batched vector env (docs/performance.md). Not a test: run it by hand.

    python benchmarks/bench_vector_env.py                   # everything, ~10 minutes
    python benchmarks/bench_vector_env.py --skip-training   # decisions per second only
    python benchmarks/bench_vector_env.py --json out.json

What it measures: :mod:`frontier_marl.experiments.speed.bench_vector_env`.
"""

from frontier_marl.experiments.speed.bench_vector_env import main

if __name__ == "__main__":
    raise SystemExit(main())
