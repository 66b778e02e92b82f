"""The training loop: one experiment -> a run folder with model, logs, checkpoints, evaluation.

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

Seeding (see :mod:`frontier_marl.training.vec_env`): ``DQN(seed=...)`` is never used
(SuperSuit's ``ConcatVecEnv`` has no ``seed``); ``set_random_seed`` seeds python/numpy/torch,
the action space is seeded for the epsilon-random actions, and every vector copy is reset with
its own seed. A resumed session derives its seeds from ``(seed, step)`` so it does not replay
the first session's episodes.
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from frontier_marl.config import make_config
from frontier_marl.policies.metadata import build_metadata, save_metadata
from frontier_marl.policies.model_files import (
    MODEL_FILE,
    Checkpoint,
    find_checkpoint,
    list_checkpoints,
)
from frontier_marl.training.algorithms import LABEL, SECTION, learner
from frontier_marl.training.checkpoints import save_checkpoint
from frontier_marl.training.experiment import Experiment, TrainSettings, experiment_from_dict
from frontier_marl.training.run_files import plot_learning_curve, record_session, set_logger
from frontier_marl.training.validation import BEST_DIR
from frontier_marl.utils.json_files import write_json

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


@dataclass
class TrainResult:
    """What :func:`train` produced."""

    run_dir: Path
    model_path: Path
    num_timesteps: int
    steps_this_session: int
    wall_time_s: float
    cpu_time_s: float
    interrupted: bool
    evaluation: dict[str, Any] | None = None
    best_evaluation: dict[str, Any] | None = None  # of RUN/best/ (with train.validate_every)
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def steps_per_second(self) -> float:
        return self.steps_this_session / self.wall_time_s if self.wall_time_s > 0 else 0.0


def default_run_dir(experiment: Experiment, root: str | Path = "runs") -> Path:
    return Path(root) / experiment.name / f"seed{experiment.train.seed}"


def policy_name(observation_space: Any) -> str:
    """``MultiInputPolicy`` for Dict observations, ``MlpPolicy`` for flat ones (as the thesis)."""
    from gymnasium import spaces

    return "MultiInputPolicy" if isinstance(observation_space, spaces.Dict) else "MlpPolicy"


def session_seed(seed: int, start_step: int) -> int:
    """The seed of a session starting at ``start_step`` (``seed`` itself for a fresh run)."""
    if start_step == 0:
        return seed
    return int(np.random.SeedSequence([seed, start_step]).generate_state(1)[0])


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


def training_vec_env(experiment: Experiment, seed: int) -> Any:
    """The SB3 vector env of ``experiment`` (see :class:`TrainSettings`' ``vec_env``,
    ``n_envs`` and ``families``), its worlds seeded from ``seed``."""
    from frontier_marl.training.batched_vec_env import MixedVecEnv, make_batched_vec_env
    from frontier_marl.training.vec_env import make_vec_env

    settings = experiment.train
    bootstrap = settings.bootstrap_truncations
    skip = {"skip_forced_steps": True} if settings.skip_forced_steps else {}
    if not settings.families:
        make = make_batched_vec_env if settings.vec_env == "batched" else make_vec_env
        kwargs = {"config": experiment.env_config(), **skip}
        return make(kwargs, settings.n_envs, seed, bootstrap)
    from stable_baselines3.common.vec_env import VecMonitor

    from frontier_marl.evaluation.benchmark.families import family

    parts = []
    names = [name for name in settings.families for _ in settings.agents]
    for i, (name, cfg) in enumerate(zip(names, experiment.env_configs(), strict=True)):
        seeds = family(name).train
        part = make_batched_vec_env(
            {"config": cfg, **skip}, settings.n_envs, seed + 1000 * i, bootstrap, seed_range=seeds
        )
        parts.append(part.venv)  # one VecMonitor around the mix
    return VecMonitor(MixedVecEnv(parts))


def train(
    experiment: Experiment,
    run_dir: str | Path,
    *,
    resume: Checkpoint | str | Path | None = None,
    progress_bar: bool = True,
    verbose: int = 0,
    callbacks: Sequence[Any] = (),
) -> TrainResult:
    """Train (or resume) one experiment into ``run_dir``; Ctrl-C saves a checkpoint.

    ``callbacks`` are extra SB3 callbacks (e.g. to report to a tuner); a ``KeyboardInterrupt``
    raised anywhere in ``learn`` ends the session like Ctrl-C: checkpoint, model, no evaluation.
    """
    import torch
    from stable_baselines3.common.utils import set_random_seed

    settings: TrainSettings = experiment.train
    run_dir = Path(run_dir)
    if resume is None or isinstance(resume, Checkpoint):
        checkpoint = resume
    else:
        checkpoint = find_checkpoint(resume)
    if checkpoint is None and ((run_dir / "model.zip").exists() or list_checkpoints(run_dir)):
        raise ValueError(
            f"run folder {str(run_dir)!r} already holds a run: continue it with "
            f"--resume {run_dir} or choose another --out"
        )
    run_dir.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(settings.torch_threads)
    if settings.algorithm == "cem":
        from frontier_marl.training.cem import train_cem

        if checkpoint is not None:
            raise ValueError("a train.algorithm = 'cem' run cannot be resumed: start it again")
        return train_cem(experiment, run_dir, progress_bar)

    cfg = experiment.env_config()
    start_step = 0 if checkpoint is None else checkpoint.step
    seed = session_seed(settings.seed, start_step)
    set_random_seed(seed)
    vec_env = training_vec_env(experiment, seed)
    algorithm, policy_class = learner(settings.algorithm, settings.policy)
    if checkpoint is None:
        try:
            model = algorithm(
                policy_class or policy_name(vec_env.observation_space),
                vec_env,
                device=settings.device,
                verbose=verbose,
                **experiment.hyperparameters(),
            )
        except (TypeError, ValueError, AssertionError) as exc:
            vec_env.close()
            section = SECTION[settings.algorithm]
            raise ValueError(
                f"[{section}] settings rejected by {algorithm.__name__}: {exc}"
            ) from exc
    else:
        model = algorithm.load(checkpoint.model, env=vec_env, device=settings.device)
        if checkpoint.replay_buffer.is_file() and hasattr(model, "load_replay_buffer"):
            model.load_replay_buffer(checkpoint.replay_buffer)
        start_step = model.num_timesteps
    model.action_space.seed(seed)
    skip_repeated_mode_switches(model.policy)
    policy = policy_name(model.observation_space)
    set_logger(model, run_dir, start_step, checkpoint is not None, verbose)

    def metadata() -> dict[str, Any]:
        return build_metadata(
            cfg,
            model.observation_space,
            model.action_space,
            policy=policy,
            algorithm=LABEL[settings.algorithm],
            num_timesteps=model.num_timesteps,
            experiment=experiment.to_dict(),
            extra={"seed": settings.seed, "session_seed": seed},
        )

    def checkpoint_now(m: Any) -> Checkpoint:
        return save_checkpoint(m, run_dir, metadata(), keep=settings.keep_checkpoints)

    all_callbacks: list[Any] = list(callbacks)
    progress = None
    if progress_bar:
        from frontier_marl.training.callbacks import ProgressBar

        progress = ProgressBar()
        all_callbacks.append(progress)
    from frontier_marl.training.callbacks import Periodic

    if settings.checkpoint_every > 0:
        all_callbacks.append(Periodic(settings.checkpoint_every, checkpoint_now))
    if settings.validate_every > 0:
        from frontier_marl.training.validation import BestPolicyKeeper

        scorer, log_key = None, "eval/validation_mean_reward"
        if settings.families:
            from frontier_marl.training.family_validation import FamilyValidator

            scorer = FamilyValidator(
                settings.families, settings.validation_episodes, cfg, settings.agents[0]
            )
            log_key = "eval/validation_score"
        keeper = BestPolicyKeeper(run_dir, cfg, settings, metadata, start_step, scorer)
        all_callbacks.append(Periodic(settings.validate_every, keeper, log_key=log_key))

    remaining = settings.total_timesteps - model.num_timesteps
    interrupted = False
    started, cpu_started = time.perf_counter(), time.process_time()
    try:
        if remaining > 0:
            model.learn(
                remaining,
                callback=all_callbacks,
                log_interval=settings.log_interval,
                reset_num_timesteps=checkpoint is None,
            )
    except KeyboardInterrupt:
        interrupted = True
        if progress is not None:
            progress.close()
    wall = time.perf_counter() - started
    cpu = time.process_time() - cpu_started
    steps_done = model.num_timesteps - start_step

    files: dict[str, Path] = {}
    last = checkpoint_now(model)
    files["checkpoint"] = last.path
    model_path = run_dir / "model.zip"
    model.save(model_path)
    meta = metadata()
    meta["training"] = {"wall_time_s": wall, "cpu_time_s": cpu, "steps_this_session": steps_done}
    save_metadata(meta, run_dir / "model.json")
    files["model"] = model_path
    files["metadata"] = run_dir / "model.json"
    record_session(
        run_dir,
        experiment,
        start_step,
        model.num_timesteps,
        wall,
        cpu,
        interrupted,
        None if checkpoint is None else checkpoint.path,
    )
    model.logger.close()
    vec_env.close()

    result = TrainResult(
        run_dir=run_dir,
        model_path=model_path,
        num_timesteps=model.num_timesteps,
        steps_this_session=steps_done,
        wall_time_s=wall,
        cpu_time_s=cpu,
        interrupted=interrupted,
        files=files,
    )
    result.files["learning_curve"] = plot_learning_curve(run_dir, experiment, result.num_timesteps)
    if not interrupted and settings.eval_episodes > 0:
        eval_cfg = cfg
        if settings.eval_map_mode != "as-trained":
            eval_cfg = make_config(config=cfg, map_mode=settings.eval_map_mode)
        result.evaluation = _final_evaluation(
            model, model_path, meta, eval_cfg, settings, run_dir, experiment, result
        )
        best = run_dir / BEST_DIR / MODEL_FILE
        if settings.validate_every > 0 and best.is_file():
            from frontier_marl.policies.models import load_model

            loaded = load_model(best, device=settings.device)
            result.best_evaluation = _final_evaluation(
                loaded.model,
                best,
                loaded.metadata or {},
                eval_cfg,
                settings,
                run_dir / BEST_DIR,
                experiment,
                result,
                label="best",
            )
    return result


def skip_repeated_mode_switches(policy: Any) -> None:
    """Make ``policy.set_training_mode(mode)`` a no-op when the mode is already set.

    SB3 calls it before every ``predict`` and every gradient step; each call walks all
    submodules (about 30 us), and on the greedy part of a run that was ~10 % of the training
    time. The result is unchanged: only repeated calls with the same mode are skipped (and the
    DQN MLP has no dropout or batch norm anyway). The patch lives on this policy instance only;
    it is not saved with the model.
    """
    original = policy.set_training_mode
    state: dict[str, bool | None] = {"mode": None}

    def set_training_mode(mode: bool) -> None:
        if state["mode"] != mode:
            original(mode)
            state["mode"] = mode

    policy.set_training_mode = set_training_mode


def _final_evaluation(
    model: Any,
    model_path: Path,
    meta: dict[str, Any],
    cfg: Any,
    settings: TrainSettings,
    run_dir: Path,
    experiment: Experiment,
    result: TrainResult,
    label: str = "",
) -> dict[str, Any]:
    """The protocol evaluation of a model, saved in ``run_dir`` (the run's or ``RUN/best/``)."""
    from frontier_marl.evaluation.model_evaluation import evaluate_model
    from frontier_marl.policies.models import LoadedModel
    from frontier_marl.training.plots import plot_action_histogram

    loaded = LoadedModel(model=model, path=model_path, metadata=meta)
    name = f"{experiment.name} ({label})" if label else experiment.name
    evaluation = evaluate_model(
        loaded,
        cfg,
        episodes=settings.eval_episodes,
        seed=settings.eval_seed,
        name=name,
    )
    evaluation["experiment"] = experiment.name
    if "validation" in meta:  # the best-validated policy: when and how it was chosen
        evaluation["validation"] = meta["validation"]
    path = run_dir / "evaluation.json"
    write_json(evaluation, path)
    plot_action_histogram(
        evaluation["rows"],
        run_dir / "actions.png",
        title=f"{name}: actions over {settings.eval_episodes} deterministic episodes",
    )
    suffix = f"_{label}" if label else ""
    result.files[f"evaluation{suffix}"] = path
    result.files[f"actions{suffix}"] = run_dir / "actions.png"
    return evaluation
