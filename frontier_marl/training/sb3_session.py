"""One training session of an SB3 algorithm (DQN, PPO, MaskablePPO) into a run folder: build
or resume the model, learn with the run's callbacks, save the final checkpoint and model, record
the session, evaluate.

Seeding (see :mod:`frontier_marl.training.vec_env`): ``DQN(seed=...)`` is never used
(SuperSuit's ``ConcatVecEnv`` has no ``seed``); ``set_random_seed`` seeds python/numpy/torch,
the action space is seeded for the epsilon-random actions, and every vector copy is reset with
its own seed. A resumed session derives its seeds from ``(seed, step)`` so it does not replay
the first session's episodes.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces
from stable_baselines3.common.utils import set_random_seed
from stable_baselines3.common.vec_env import VecMonitor

from frontier_marl.config import EnvConfig, make_config
from frontier_marl.evaluation.benchmark.families import family
from frontier_marl.evaluation.model_evaluation import evaluate_model
from frontier_marl.policies.metadata import build_metadata, save_metadata
from frontier_marl.policies.model_files import MODEL_FILE, Checkpoint
from frontier_marl.policies.models import LoadedModel, load_model
from frontier_marl.training.batched_vec_env import MixedVecEnv, make_batched_vec_env
from frontier_marl.training.callbacks import Periodic, ProgressBar
from frontier_marl.training.checkpoints import save_checkpoint
from frontier_marl.training.experiment import Experiment
from frontier_marl.training.family_validation import FamilyValidator
from frontier_marl.training.plots import plot_action_histogram
from frontier_marl.training.results import TrainResult
from frontier_marl.training.run_files import (
    end_session,
    plot_learning_curve,
    set_logger,
    start_session,
)
from frontier_marl.training.sb3_algorithm import SB3Algorithm
from frontier_marl.training.validation import BEST_DIR, BestPolicyKeeper
from frontier_marl.training.vec_env import make_vec_env
from frontier_marl.utils.json_files import write_json


def policy_name(observation_space: Any) -> str:
    """``MultiInputPolicy`` for Dict observations, ``MlpPolicy`` for flat ones (as the thesis)."""
    return "MultiInputPolicy" if isinstance(observation_space, spaces.Dict) else "MlpPolicy"


def session_seed(seed: int, start_step: int) -> int:
    """The seed of a session starting at ``start_step`` (``seed`` itself for a fresh run)."""
    if start_step == 0:
        return seed
    return int(np.random.SeedSequence([seed, start_step]).generate_state(1)[0])


def training_vec_env(experiment: Experiment, seed: int) -> Any:
    """The SB3 vector env of ``experiment`` (see :class:`TrainSettings`' ``vec_env``,
    ``n_envs`` and ``families``), its worlds seeded from ``seed``."""
    settings = experiment.train
    bootstrap = settings.bootstrap_truncations
    skip = {"skip_forced_steps": True} if settings.skip_forced_steps else {}
    if not settings.families:
        make = make_batched_vec_env if settings.vec_env == "batched" else make_vec_env
        kwargs = {"config": experiment.env_config(), **skip}
        return make(kwargs, settings.n_envs, seed, bootstrap)
    parts = []
    names = [name for name in settings.families for _ in settings.agents]
    for i, (name, cfg) in enumerate(zip(names, experiment.env_configs(), strict=True)):
        seeds = family(name).train
        part = make_batched_vec_env(
            {"config": cfg, **skip}, settings.n_envs, seed + 1000 * i, bootstrap, seed_range=seeds
        )
        parts.append(part.venv)  # one VecMonitor around the mix
    return VecMonitor(MixedVecEnv(parts))


def build_model(
    algorithm: SB3Algorithm,
    experiment: Experiment,
    vec_env: Any,
    checkpoint: Checkpoint | None,
    verbose: int,
) -> Any:
    """A new model of ``experiment``'s settings, or the checkpoint's with its replay buffer."""
    settings = experiment.train
    algorithm_class, policy_class = algorithm.classes(settings.policy)
    if checkpoint is not None:
        model = algorithm_class.load(checkpoint.model, env=vec_env, device=settings.device)
        if algorithm.resumes_replay_buffer and checkpoint.replay_buffer.is_file():
            model.load_replay_buffer(checkpoint.replay_buffer)
        return model
    try:
        return algorithm_class(
            policy_class or policy_name(vec_env.observation_space),
            vec_env,
            device=settings.device,
            verbose=verbose,
            **experiment.hyperparameters(),
        )
    except (TypeError, ValueError, AssertionError) as exc:
        vec_env.close()
        raise ValueError(
            f"[{algorithm.section}] settings rejected by {algorithm_class.__name__}: {exc}"
        ) from exc


def session_callbacks(
    experiment: Experiment,
    run_dir: Path,
    metadata: Callable[[], dict[str, Any]],
    checkpoint_now: Callable[[Any], Checkpoint],
    start_step: int,
) -> list[Any]:
    """The periodic checkpoint and validation callbacks of ``experiment``'s settings."""
    settings, cfg = experiment.train, experiment.env_config()
    callbacks: list[Any] = []
    if settings.checkpoint_every > 0:
        callbacks.append(Periodic(settings.checkpoint_every, checkpoint_now))
    if settings.validate_every > 0:
        scorer, log_key = None, "eval/validation_mean_reward"
        if settings.families:
            scorer = FamilyValidator(
                settings.families, settings.validation_episodes, cfg, settings.agents[0]
            )
            log_key = "eval/validation_score"
        keeper = BestPolicyKeeper(run_dir, cfg, settings, metadata, start_step, scorer)
        callbacks.append(Periodic(settings.validate_every, keeper, log_key=log_key))
    return callbacks


@dataclass
class _Session:
    """One session's model and env, and what its metadata and checkpoints record."""

    algorithm: SB3Algorithm
    experiment: Experiment
    run_dir: Path
    cfg: EnvConfig
    model: Any
    vec_env: Any
    seed: int
    start_step: int

    def metadata(self) -> dict[str, Any]:
        model = self.model
        return build_metadata(
            self.cfg,
            model.observation_space,
            model.action_space,
            policy=policy_name(model.observation_space),
            algorithm=self.algorithm.label,
            num_timesteps=model.num_timesteps,
            experiment=self.experiment.to_dict(),
            extra={"seed": self.experiment.train.seed, "session_seed": self.seed},
        )

    def checkpoint_now(self, m: Any) -> Checkpoint:
        keep = self.experiment.train.keep_checkpoints
        return save_checkpoint(m, self.run_dir, self.metadata(), keep=keep)


def _start(
    algorithm: SB3Algorithm,
    experiment: Experiment,
    run_dir: Path,
    checkpoint: Checkpoint | None,
    verbose: int,
) -> _Session:
    """Seed the session, build its vector env and model (or resume it), set its logger."""
    cfg = experiment.env_config()
    start_step = 0 if checkpoint is None else checkpoint.step
    seed = session_seed(experiment.train.seed, start_step)
    set_random_seed(seed)
    vec_env = training_vec_env(experiment, seed)
    model = build_model(algorithm, experiment, vec_env, checkpoint, verbose)
    if checkpoint is not None:
        start_step = model.num_timesteps
    model.action_space.seed(seed)
    skip_repeated_mode_switches(model.policy)
    set_logger(model, run_dir, start_step, checkpoint is not None, verbose)
    return _Session(algorithm, experiment, run_dir, cfg, model, vec_env, seed, start_step)


def _end(run: _Session, session: Any, result: TrainResult) -> None:
    """Save the final checkpoint and model, record the session, plot, evaluate."""
    model, run_dir, experiment = run.model, run.run_dir, run.experiment
    result.files["checkpoint"] = run.checkpoint_now(model).path
    meta = save_model(model, run.metadata(), result)
    end_session(
        run_dir,
        session,
        model.num_timesteps,
        result.wall_time_s,
        result.cpu_time_s,
        result.interrupted,
    )
    model.logger.close()
    run.vec_env.close()
    result.files["learning_curve"] = plot_learning_curve(run_dir, experiment, result.num_timesteps)
    if not result.interrupted and experiment.train.eval_episodes > 0:
        loaded = LoadedModel(model, result.model_path, meta)
        evaluate_session(loaded, run.cfg, experiment, run_dir, result)


def train_sb3(
    algorithm: SB3Algorithm,
    experiment: Experiment,
    run_dir: Path,
    checkpoint: Checkpoint | None,
    progress_bar: bool,
    verbose: int,
    callbacks: Sequence[Any],
) -> TrainResult:
    """Train (or resume from ``checkpoint``) into ``run_dir``; Ctrl-C saves a checkpoint.

    A ``KeyboardInterrupt`` raised anywhere in ``learn`` ends the session like Ctrl-C:
    checkpoint, model, no evaluation.
    """
    run = _start(algorithm, experiment, run_dir, checkpoint, verbose)
    model, start_step = run.model, run.start_step
    resumed_from = None if checkpoint is None else checkpoint.path
    session = start_session(run_dir, experiment, start_step, resumed_from)
    periodic = session_callbacks(experiment, run_dir, run.metadata, run.checkpoint_now, start_step)
    started, cpu_started = time.perf_counter(), time.process_time()
    interrupted = learn(model, experiment, checkpoint is None, callbacks, periodic, progress_bar)
    wall = time.perf_counter() - started
    cpu = time.process_time() - cpu_started
    result = TrainResult(
        run_dir=run_dir,
        model_path=run_dir / MODEL_FILE,
        num_timesteps=model.num_timesteps,
        steps_this_session=model.num_timesteps - start_step,
        wall_time_s=wall,
        cpu_time_s=cpu,
        interrupted=interrupted,
    )
    _end(run, session, result)
    return result


def learn(
    model: Any,
    experiment: Experiment,
    fresh: bool,
    callbacks: Sequence[Any],
    periodic: Sequence[Any],
    progress_bar: bool,
) -> bool:
    """Run ``model.learn`` to ``train.total_timesteps`` with the user's callbacks, the progress
    bar and the periodic ones, in that order; True if it was interrupted."""
    settings = experiment.train
    progress = [ProgressBar()] if progress_bar else []
    remaining = settings.total_timesteps - model.num_timesteps
    try:
        if remaining > 0:
            model.learn(
                remaining,
                callback=[*callbacks, *progress, *periodic],
                log_interval=settings.log_interval,
                reset_num_timesteps=fresh,
            )
    except KeyboardInterrupt:
        for bar in progress:
            bar.close()
        return True
    return False


def save_model(model: Any, meta: dict[str, Any], result: TrainResult) -> dict[str, Any]:
    """Save the final ``RUN/model.zip`` and its ``model.json`` (with the session's times)."""
    model.save(result.model_path)
    meta["training"] = {
        "wall_time_s": result.wall_time_s,
        "cpu_time_s": result.cpu_time_s,
        "steps_this_session": result.steps_this_session,
    }
    save_metadata(meta, result.model_path.with_name("model.json"))
    result.files["model"] = result.model_path
    result.files["metadata"] = result.model_path.with_name("model.json")
    return meta


def evaluate_session(
    loaded: LoadedModel,
    cfg: EnvConfig,
    experiment: Experiment,
    run_dir: Path,
    result: TrainResult,
) -> None:
    """The protocol evaluation of the final model and, with validation, of ``RUN/best/``."""
    settings = experiment.train
    if settings.eval_map_mode != "as-trained":
        cfg = make_config(config=cfg, map_mode=settings.eval_map_mode)
    result.evaluation = final_evaluation(loaded, cfg, experiment, run_dir, result)
    best = run_dir / BEST_DIR / MODEL_FILE
    if settings.validate_every > 0 and best.is_file():
        best_model = load_model(best, device=settings.device)
        if best_model.metadata is None:
            best_model.metadata = {}
        result.best_evaluation = final_evaluation(
            best_model, cfg, experiment, run_dir / BEST_DIR, result, label="best"
        )


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


def final_evaluation(
    loaded: LoadedModel,
    cfg: EnvConfig,
    experiment: Experiment,
    run_dir: Path,
    result: TrainResult,
    label: str = "",
) -> dict[str, Any]:
    """The protocol evaluation of a model, saved in ``run_dir`` (the run's or ``RUN/best/``)."""
    settings = experiment.train
    name = f"{experiment.name} ({label})" if label else experiment.name
    evaluation = evaluate_model(
        loaded, cfg, episodes=settings.eval_episodes, seed=settings.eval_seed, name=name
    )
    evaluation["experiment"] = experiment.name
    meta = loaded.metadata or {}
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
