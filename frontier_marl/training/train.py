"""Training one experiment into a run folder: the dispatcher over the algorithms.

Run folder::

    RUN/model.zip, model.json        final model + metadata (env config, observation layout)
    RUN/evaluation.json              30-episode deterministic evaluation beside greedy-distance
    RUN/actions.png                  action histogram of that evaluation
    RUN/learning_curve.png           episode reward, TD loss and epsilon against steps
    RUN/metrics.jsonl                every logger dump (the learning curve's data)
    RUN/tb/                          TensorBoard: rollout/ep_rew_mean, train/loss,
                                     rollout/exploration_rate
    RUN/checkpoints/step_*/          model + replay buffer (DQN) + metadata (newest ``keep`` kept)
    RUN/validation.jsonl, RUN/best/  with ``train.validate_every``: validation scores, and the
                                     best-validated policy with its own evaluation.json
    RUN/run.json                     the experiment and one entry per training session

The SB3 algorithms (:mod:`~frontier_marl.training.dqn`, :mod:`~frontier_marl.training.ppo`)
run in :mod:`~frontier_marl.training.sb3_session`; CEM in :mod:`~frontier_marl.training.cem`.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import torch

from frontier_marl.policies.model_files import (
    Checkpoint,
    find_checkpoint,
)
from frontier_marl.training.algorithms import sb3_algorithm
from frontier_marl.training.cem import train_cem
from frontier_marl.training.cost_regression import train_cost_regression
from frontier_marl.training.experiment import Experiment, experiment_from_dict
from frontier_marl.training.results import TrainResult
from frontier_marl.training.run_folder import own_run_folder
from frontier_marl.training.sb3_session import train_sb3

#: Train settings a resumed run may change; everything else must match the checkpoint.
RESUMABLE_TRAIN_KEYS = {
    "total_timesteps",
    "validate_every",
    "checkpoint_every",
    "keep_checkpoints",
    "log_interval",
    "eval_episodes",
    "eval_seed",
    "eval_map_mode",
    "torch_threads",
}


def default_run_dir(experiment: Experiment, root: str | Path = "runs") -> Path:
    return Path(root) / experiment.name / f"seed{experiment.train.seed}"


def resume_experiment(
    checkpoint: Checkpoint, overrides: dict[str, Any] | None = None
) -> Experiment:
    """The checkpoint's experiment with allowed ``train`` overrides applied."""
    meta = checkpoint.metadata()
    saved = meta.get("experiment")
    if not saved:
        raise ValueError(f"checkpoint {checkpoint.path} has no saved experiment in model.json")
    data = json.loads(json.dumps(saved))
    for key, value in (overrides or {}).items():
        if key not in RESUMABLE_TRAIN_KEYS:
            raise ValueError(
                f"cannot change train.{key} when resuming (allowed: "
                f"{', '.join(sorted(RESUMABLE_TRAIN_KEYS))}); env and dqn settings are fixed "
                "by the checkpoint"
            )
        data["train"][key] = value
    return experiment_from_dict(data, source=str(checkpoint.path))


def train(
    experiment: Experiment,
    run_dir: str | Path,
    *,
    resume: Checkpoint | str | Path | None = None,
    progress_bar: bool = True,
    verbose: int = 0,
    callbacks: Sequence[Any] = (),
    overwrite: bool = False,
) -> TrainResult:
    """Train (or resume) one experiment into ``run_dir``; Ctrl-C saves a checkpoint.

    The session owns ``run_dir`` while it runs (:mod:`~frontier_marl.training.run_folder`); a
    fresh run is refused where an earlier run's files lie unless ``overwrite`` (a workflow
    restarting its own unfinished run). ``callbacks`` are extra SB3 callbacks (e.g. to report
    to a tuner).
    """
    settings = experiment.train
    run_dir = Path(run_dir)
    checkpoint = find_checkpoint(resume) if isinstance(resume, str | Path) else resume
    if settings.algorithm in ("cem", "cost-regression") and checkpoint is not None:
        raise ValueError(
            f"a train.algorithm = {settings.algorithm!r} run cannot be resumed: start it again"
        )
    with own_run_folder(run_dir, fresh=checkpoint is None, overwrite=overwrite):
        torch.set_num_threads(settings.torch_threads)
        if settings.algorithm == "cem":
            return train_cem(experiment, run_dir, progress_bar)
        if settings.algorithm == "cost-regression":
            return train_cost_regression(experiment, run_dir, progress_bar)
        algorithm = sb3_algorithm(settings.algorithm)
        return train_sb3(
            algorithm, experiment, run_dir, checkpoint, progress_bar, verbose, callbacks
        )
