"""Where do the heuristics get stuck? Every episode a heuristic ends without reaching the
threshold, with what the robot did in its last decisions (docs/calibration.md, "Livelocks").

    python baselines/livelocks.py --preset thesis-30x30 --map-mode static --episodes 30
    python baselines/livelocks.py --episodes 300 --policies greedy-distance,greedy-gain \\
        --set commit=until-progress --json livelocks.json

What it reports: :mod:`frontier_marl.experiments.livelocks`.
"""

from frontier_marl.experiments.livelocks import main

if __name__ == "__main__":
    raise SystemExit(main())
