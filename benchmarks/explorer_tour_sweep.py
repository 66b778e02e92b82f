"""How T99 depends on the tour weight of the hand-set rule, family by family, on training seeds.

    python benchmarks/explorer_tour_sweep.py --weights=-0.25,-0.5,-0.75,-1.0 --episodes 64 \\
        --json training/results/explorer/tour-sweep.json

The sweep: :mod:`frontier_marl.experiments.explorer_studies.tour_sweep`.
"""

from frontier_marl.experiments.explorer_studies.tour_sweep import main

if __name__ == "__main__":
    raise SystemExit(main())
