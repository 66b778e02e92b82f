"""Validation during training (``train.validate_every``) and the best-validated policy."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from frontier_marl.training.experiment import TrainSettings, experiment_from_dict
from frontier_marl.training.validation import read_validation_log

SMALL = {"preset": "thesis-20x20", "height": 10, "width": 10, "perception_range": 2}


def experiment(**train: object) -> object:
    settings = {
        "total_timesteps": 900,
        "checkpoint_every": 0,
        "eval_episodes": 2,
        "log_interval": 2,
        "validate_every": 300,
        "validation_episodes": 3,
        **train,
    }
    return experiment_from_dict(
        {"name": "tiny", "env": SMALL, "dqn": {"learning_starts": 100}, "train": settings}
    )


def test_validation_episodes_must_not_overlap_the_evaluation() -> None:
    with pytest.raises(ValueError, match="validation_seed.*overlap"):
        TrainSettings(validate_every=1000, validation_seed=20, eval_seed=0, eval_episodes=30)
    TrainSettings(validate_every=1000, validation_seed=30, eval_seed=0, eval_episodes=30)
    TrainSettings(validate_every=0, validation_seed=0)  # no validation, no conflict
    with pytest.raises(ValueError, match="train.validation_episodes"):
        TrainSettings(validation_episodes=0)


@pytest.fixture(scope="module")
def validated_run(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    from frontier_marl.training.train import train

    run_dir = tmp_path_factory.mktemp("validated") / "run"
    return run_dir, train(experiment(), run_dir, progress_bar=False)


def test_scores_are_logged_and_the_best_policy_is_kept(validated_run: tuple) -> None:
    run_dir, result = validated_run
    records = read_validation_log(run_dir)
    assert [r["step"] for r in records] == [300, 600, 900]
    assert all(r["episodes"] == 3 and r["seed"] == 1000 for r in records)
    assert all(r["map_mode"] == "static" for r in records)
    best_meta = json.loads((run_dir / "best" / "model.json").read_text())
    best_record = max(records, key=lambda r: r["mean_reward"])  # the first of equal scores
    assert best_meta["validation"] == best_record
    assert best_meta["num_timesteps"] == best_record["step"]
    metrics = [json.loads(line) for line in (run_dir / "metrics.jsonl").read_text().splitlines()]
    key = "eval/validation_mean_reward"
    logged = [m[key] for m in metrics if key in m]
    assert logged and set(logged) <= {r["mean_reward"] for r in records}


def test_best_policy_gets_the_protocol_evaluation_too(validated_run: tuple) -> None:
    run_dir, result = validated_run
    best = json.loads((run_dir / "best" / "evaluation.json").read_text())
    final = json.loads((run_dir / "evaluation.json").read_text())
    assert best["seed"] == final["seed"] == 0 and best["episodes"] == 2
    assert best["validation"]["step"] in (300, 600, 900)
    assert best["model_path"].endswith("best/model.zip")
    assert result.best_evaluation["model"]["mean_reward"] == best["model"]["mean_reward"]
    assert (run_dir / "best" / "actions.png").is_file()


def test_validation_does_not_change_training(validated_run: tuple, tmp_path: Path) -> None:
    """The validation episodes use their own env and no shared RNG: same seed, same weights."""
    import torch
    from stable_baselines3 import DQN

    from frontier_marl.training.train import train

    run_dir, result = validated_run
    plain = train(experiment(validate_every=0), tmp_path / "plain", progress_bar=False)
    weights = [
        torch.cat([p.flatten() for p in DQN.load(path, device="cpu").policy.parameters()])
        for path in (result.model_path, plain.model_path)
    ]
    assert torch.equal(weights[0], weights[1])
    assert not (tmp_path / "plain" / "best").exists()
    assert plain.best_evaluation is None


def test_evaluation_map_mode_can_differ_from_training(tmp_path: Path) -> None:
    from frontier_marl.training.train import train

    dynamic = experiment(total_timesteps=300, eval_map_mode="static")
    dynamic = experiment_from_dict({**dynamic.to_dict(), "env": {**SMALL, "map_mode": "dynamic"}})
    result = train(dynamic, tmp_path / "run", progress_bar=False)
    assert read_validation_log(tmp_path / "run")[0]["map_mode"] == "dynamic"
    for folder in (tmp_path / "run", tmp_path / "run" / "best"):
        evaluation = json.loads((folder / "evaluation.json").read_text())
        assert evaluation["env_config"]["map_mode"] == "static"
    assert result.evaluation["model"]["map_mode"] == "static"
    with pytest.raises(ValueError, match="train.eval_map_mode must be one of"):
        TrainSettings(eval_map_mode="fixed")


def test_cli_evaluates_the_best_policy_folder(validated_run: tuple, capsys) -> None:
    from frontier_marl.cli.main import main

    run_dir, _ = validated_run
    assert main(["evaluate", str(run_dir / "best"), "--episodes", "1", "--no-progress"]) == 0
    assert "greedy-distance" in capsys.readouterr().out


def test_resume_forgets_validations_past_the_checkpoint(tmp_path: Path) -> None:
    from stable_baselines3.common.callbacks import BaseCallback

    from frontier_marl.policies.model_files import list_checkpoints
    from frontier_marl.training.train import resume_experiment, train

    class InterruptAt(BaseCallback):
        def _on_step(self) -> bool:
            if self.model.num_timesteps >= 700:
                raise KeyboardInterrupt
            return True

    run_dir = tmp_path / "run"
    first = train(
        experiment(checkpoint_every=300, keep_checkpoints=0, eval_episodes=0),
        run_dir,
        progress_bar=False,
        callbacks=[InterruptAt()],
    )
    assert first.interrupted
    assert [r["step"] for r in read_validation_log(run_dir)] == [300, 600]
    older = next(c for c in list_checkpoints(run_dir) if c.step == 300)
    resumed = train(
        resume_experiment(older, {"total_timesteps": 900}),
        run_dir,
        resume=older,
        progress_bar=False,
    )
    assert resumed.num_timesteps == 900
    assert [r["step"] for r in read_validation_log(run_dir)] == [300, 600, 900]
    best = json.loads((run_dir / "best" / "model.json").read_text())["validation"]
    assert best in read_validation_log(run_dir)


@pytest.mark.parametrize("best_step", [300, 600])
def test_resume_keeps_a_best_policy_only_from_before_the_checkpoint(
    tmp_path: Path, best_step: int
) -> None:
    from frontier_marl.training.validation import BestPolicyKeeper

    records = [{"step": 300, "mean_reward": 1.5}, {"step": 600, "mean_reward": 2.5}]
    (tmp_path / "validation.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    (tmp_path / "best").mkdir()
    (tmp_path / "best" / "model.zip").write_bytes(b"")
    chosen = next(r for r in records if r["step"] == best_step)
    (tmp_path / "best" / "model.json").write_text(json.dumps({"validation": chosen}))
    settings = TrainSettings(validate_every=300, validation_episodes=3)
    keeper = BestPolicyKeeper(tmp_path, None, settings, dict, start_step=300)
    assert read_validation_log(tmp_path) == records[:1]
    if best_step == 300:  # saved before the checkpoint: still the one to beat
        assert keeper.best_score == 1.5 and (tmp_path / "best").is_dir()
    else:  # saved by a session that was not continued: dropped
        assert keeper.best_score == -math.inf and not (tmp_path / "best").exists()


def test_periodic_callback_needs_a_positive_interval() -> None:
    from frontier_marl.training.callbacks import Periodic

    with pytest.raises(ValueError, match="interval of a periodic callback must be >= 1"):
        Periodic(0, print)
