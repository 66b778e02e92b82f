"""The same layouts on ever finer grids: where cost-utility overtakes nearest-path.

    python benchmarks/resolution_sweep.py --scales 1,2,3,4,6 --episodes 24 \\
        --policies cost-utility,nearest-path,explorer \\
        --json training/results/explorer/resolution-sweep.json

The layouts and the sensor at each scale:
:mod:`frontier_marl.experiments.explorer_studies.resolution_sweep`.
"""

from frontier_marl.experiments.explorer_studies.resolution_sweep import main

if __name__ == "__main__":
    raise SystemExit(main())
