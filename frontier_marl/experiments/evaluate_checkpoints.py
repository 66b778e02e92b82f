"""Evaluate every checkpoint of a run: how the greedy policy changes during training.

    python training/evaluate_checkpoints.py runs/config01/seed0
    python training/evaluate_checkpoints.py RUN --seeds 1000 0 --episodes 30 --json curve.json

Each checkpoint's model plays ``--episodes`` deterministic episodes from each first reset seed
in ``--seeds`` (default: 1000, held-out validation episodes, and 0, the thesis protocol's) on
the env it was trained on. Keep the checkpoints with ``--set train.keep_checkpoints=0`` (and,
for a fine curve, ``--set train.checkpoint_every=50000``). A table goes to stdout; ``--json``
writes the rows.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from frontier_marl.evaluation.model_evaluation import evaluate_model
from frontier_marl.policies.model_files import list_checkpoints
from frontier_marl.policies.models import load_model


def evaluate_checkpoints(
    run_dir: str | Path, seeds: list[int], episodes: int = 30
) -> list[dict[str, Any]]:
    """One row per checkpoint: its step and, per seed, mean reward and terminations."""
    checkpoints = list_checkpoints(run_dir)
    if not checkpoints:
        raise ValueError(f"no checkpoints in {str(run_dir)!r}")
    rows = []
    for checkpoint in checkpoints:
        loaded = load_model(checkpoint.model)
        cfg = loaded.env_config()
        row: dict[str, Any] = {"step": checkpoint.step}
        for seed in seeds:
            result = evaluate_model(loaded, cfg, episodes=episodes, seed=seed, heuristics=())
            row[f"mean_reward@{seed}"] = result["model"]["mean_reward"]
            row[f"terminations@{seed}"] = result["model"]["terminations"]
        rows.append(row)
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="run folder with checkpoints/")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1000, 0])
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    rows = evaluate_checkpoints(args.run, args.seeds, args.episodes)
    print(f"{'step':<10}" + "".join(f"{f'seeds {s}..':>20}" for s in args.seeds))
    for row in rows:
        cells = "".join(
            f"{row[f'mean_reward@{s}']:>12.2f} ({row[f'terminations@{s}']:>2}/{args.episodes})"
            for s in args.seeds
        )
        print(f"{row['step']:<10}{cells}")
    if args.json is not None:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    return 0
