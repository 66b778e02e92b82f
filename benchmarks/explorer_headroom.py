"""How much a chooser among frontier-rule's 12 slots could gain: two true-map oracles.

    python benchmarks/explorer_headroom.py --families random-20,rooms-32 --episodes 16

The oracles and the options: :mod:`frontier_marl.experiments.explorer_studies.headroom`.
"""

from frontier_marl.experiments.explorer_studies.headroom import main

if __name__ == "__main__":
    raise SystemExit(main())
