"""Evaluate every checkpoint of a run: how the greedy policy changes during training.

    python training/evaluate_checkpoints.py runs/config01/seed0
    python training/evaluate_checkpoints.py RUN --seeds 1000 0 --episodes 30 --json curve.json

The episodes and the options: :mod:`frontier_marl.experiments.evaluate_checkpoints`.
"""

from frontier_marl.experiments.evaluate_checkpoints import main

if __name__ == "__main__":
    raise SystemExit(main())
