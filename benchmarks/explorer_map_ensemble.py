"""The map scorer's model variance: scorers fitted alike but for their seeds, averaged.

    python benchmarks/explorer_map_ensemble.py runs/explorer-map-r0 --sizes 1,4,8 --episodes 16

What it runs: :mod:`frontier_marl.experiments.explorer_studies.map_scorer_ensemble`.
"""

from frontier_marl.experiments.explorer_studies.map_scorer_ensemble import main

if __name__ == "__main__":
    raise SystemExit(main())
