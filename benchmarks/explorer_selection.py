"""Choose between explorer candidates on validation episodes no training run has used.

    cp -r runs/explorer-turn/best runs/explorer-turn-best   # a model is labelled by its folder
    python benchmarks/explorer_selection.py --episodes 128 \\
        --models runs/explorer-ablation/tour-rule,runs/explorer-turn-best \\
        --json training/results/explorer/selection-turn.json

The seeds and the options: :mod:`frontier_marl.experiments.explorer_studies.selection`.
"""

from frontier_marl.experiments.explorer_studies.selection import main

if __name__ == "__main__":
    raise SystemExit(main())
