"""The checkpoint evaluation of training/evaluate_checkpoints.py on a tiny run with three
checkpoints."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from frontier_marl.experiments.evaluate_checkpoints import evaluate_checkpoints, main
from frontier_marl.training.experiment import experiment_from_dict


def test_one_row_per_checkpoint_and_seed(tmp_path: Path) -> None:
    from frontier_marl.evaluation.model_evaluation import evaluate_model
    from frontier_marl.policies.models import load_model
    from frontier_marl.training.train import train

    experiment = experiment_from_dict(
        {
            "name": "tiny",
            "env": {"preset": "thesis-20x20", "height": 10, "width": 10, "perception_range": 2},
            "dqn": {"learning_starts": 100},
            "train": {
                "total_timesteps": 600,
                "checkpoint_every": 200,
                "keep_checkpoints": 0,
                "eval_episodes": 0,
            },
        }
    )
    run = tmp_path / "run"
    train(experiment, run, progress_bar=False)
    out = tmp_path / "curve.json"
    assert main([str(run), "--seeds", "1000", "0", "--episodes", "2", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())
    assert [row["step"] for row in rows] == [200, 400, 600]
    last = load_model(run / "checkpoints" / "step_000000600" / "model.zip")
    expected = evaluate_model(last, last.env_config(), episodes=2, seed=1000, heuristics=())
    assert rows[-1]["mean_reward@1000"] == expected["model"]["mean_reward"]
    assert all(0 <= row["terminations@0"] <= 2 for row in rows)


def test_a_run_without_checkpoints_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="no checkpoints"):
        evaluate_checkpoints(tmp_path, [0])
