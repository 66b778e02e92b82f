"""How the tour rule gains from the ``unknown_near`` feature, by square size and weight.

    python benchmarks/explorer_near_probe.py --radii 4,8,12,16,20 --weights=-0.2,-0.4,-0.7 \\
        --episodes 64 --first 720000 --json training/results/explorer/near-probe.json

The probe: :mod:`frontier_marl.experiments.explorer_studies.near_probe`.
"""

from frontier_marl.experiments.explorer_studies.near_probe import main

if __name__ == "__main__":
    raise SystemExit(main())
