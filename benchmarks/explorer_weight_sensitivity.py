"""How much the shipped explorer's T99 moves when its weights move, on several sets of episodes.

    python benchmarks/explorer_weight_sensitivity.py --seed-sets 730000,731000,732000 \\
        --episodes 64 --json training/results/explorer/weight-sensitivity.json

The directions and the options:
:mod:`frontier_marl.experiments.explorer_studies.weight_sensitivity`.
"""

from frontier_marl.experiments.explorer_studies.weight_sensitivity import main

if __name__ == "__main__":
    raise SystemExit(main())
