"""Inference speed of the map-aware explorer: decisions per second on one core.

    python benchmarks/bench_map_explorer.py --model runs/explorer/best --json out.json

What it times: :mod:`frontier_marl.experiments.speed.bench_map_explorer`.
"""

from frontier_marl.experiments.speed.bench_map_explorer import main

if __name__ == "__main__":
    raise SystemExit(main())
