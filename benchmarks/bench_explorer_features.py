"""What the explorer's slot features cost in the env step (docs/performance.md).

    python benchmarks/bench_explorer_features.py --families rooms-64,rooms-96-fine \\
        --worlds 64 --seconds 5 --json out.json

The layouts compared: :mod:`frontier_marl.experiments.speed.bench_explorer_features`.
"""

from frontier_marl.experiments.speed.bench_explorer_features import main

if __name__ == "__main__":
    raise SystemExit(main())
