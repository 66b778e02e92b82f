"""``frontier-marl train``: train one experiment config (SB3's DQN or PPO, sb3-contrib's
MaskablePPO, or the cross-entropy method, by ``train.algorithm``) on the batched vector env.

Examples::

    frontier-marl train training/config01.toml                 # the thesis's main run, 1e6 steps
    frontier-marl train config04 --steps 50000 --seed 1        # a name under training/ works too
    frontier-marl train config01 --set dqn.learning_rate=1e-4 --set env.map_mode=dynamic
    frontier-marl train --resume runs/config01/seed0           # continue (or extend with --steps)
    frontier-marl train explorer-ppo --steps 20000             # MaskablePPO on the slot scorer

The run folder (default ``runs/<name>/seed<seed>``) gets the model and its metadata, TensorBoard
logs (``tensorboard --logdir RUN/tb``), checkpoints (with DQN's replay buffer), and at the end a
30-episode deterministic evaluation beside greedy-distance (``evaluation.json``), an action
histogram and a learning curve. Ctrl-C saves a checkpoint; ``--resume`` continues from it.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from frontier_marl.cli.arguments import add_set_argument, non_negative_int, positive_int
from frontier_marl.config import EnvConfig
from frontier_marl.evaluation.model_evaluation import format_comparison
from frontier_marl.policies.model_files import find_checkpoint
from frontier_marl.training.experiment import Experiment, load_experiment, parse_override
from frontier_marl.training.results import TrainResult
from frontier_marl.training.settings import CEMSettings, RegressionSettings, TrainSettings


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "config",
        nargs="?",
        default=None,
        metavar="CONFIG",
        help="experiment TOML file, or its name under training/ (e.g. config01); "
        "optional with --resume",
    )
    parser.add_argument(
        "--steps",
        type=positive_int,
        default=None,
        metavar="N",
        help="total environment steps (overrides train.total_timesteps)",
    )
    parser.add_argument(
        "--seed",
        type=non_negative_int,
        default=None,
        metavar="S",
        help="training seed (overrides train.seed)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        metavar="DIR",
        help="run folder (default: runs/<name>/seed<seed>)",
    )
    parser.add_argument(
        "--resume",
        type=Path,
        default=None,
        metavar="CHECKPOINT_OR_RUN_DIR",
        help="continue a run from a checkpoint folder or a run's newest "
        "checkpoint (step count and replay buffer included)",
    )
    add_set_argument(
        parser,
        "override a config value: env.KEY, dqn.KEY or train.KEY "
        "(a bare KEY goes to the section that has it); repeatable",
    )
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    parser.add_argument("--verbose", action="store_true", help="print SB3's logger tables")


def _fail(message: str) -> int:
    print(f"frontier-marl train: error: {message}", file=sys.stderr)
    return 2


def _fresh(args: argparse.Namespace) -> tuple[Any, Path, None]:
    from frontier_marl.training.train import default_run_dir

    if args.config is None:
        raise ValueError("CONFIG is required (or --resume a run)")
    overrides = list(args.overrides)
    if args.steps is not None:
        overrides.append(f"train.total_timesteps={args.steps}")
    if args.seed is not None:
        overrides.append(f"train.seed={args.seed}")
    experiment = load_experiment(args.config, overrides)
    return experiment, args.out or default_run_dir(experiment), None


def _resumed(args: argparse.Namespace) -> tuple[Any, Path, Any]:
    from frontier_marl.training.train import resume_experiment

    checkpoint = find_checkpoint(args.resume)
    train_overrides: dict[str, Any] = {}
    for text in args.overrides:
        section, key, value = parse_override(text)
        if section != "train":
            raise ValueError(
                f"--set {text!r}: {section} settings cannot change when resuming "
                "(the checkpoint fixes the env and the algorithm's settings)"
            )
        train_overrides[key] = value
    if args.steps is not None:
        train_overrides["total_timesteps"] = args.steps
    if "seed" in train_overrides or args.seed is not None:
        raise ValueError("--seed cannot change when resuming (the run keeps its seed)")
    experiment = resume_experiment(checkpoint, train_overrides)
    if args.config is not None:
        named = load_experiment(args.config)
        if named.name != experiment.name:
            raise ValueError(
                f"CONFIG {args.config!r} is experiment {named.name!r}, but the checkpoint "
                f"belongs to {experiment.name!r}"
            )
    return experiment, args.out or checkpoint.run_dir, checkpoint


def _worlds(cfg: EnvConfig, settings: TrainSettings) -> tuple[str, str]:
    """The env the run trains on, and how many worlds it steps at once."""
    if settings.families:
        world = f"families {', '.join(settings.families)}, {cfg.map_mode} maps"
        worlds = f"{settings.n_envs} worlds per family"
        if settings.agents != (1,):
            sizes = ", ".join(map(str, settings.agents))
            worlds += f" and team size ({sizes} robots; validated with {settings.agents[0]})"
    else:
        world = f"{cfg.height}x{cfg.width}, r={cfg.perception_range}, {cfg.map_mode} map"
        worlds = f"{settings.n_envs} world(s)"
    return world, worlds


def _label_source(completions: int) -> str:
    """What a family's labels average over."""
    return f"{completions} completions" if completions else "the true map"


def _env_and_budget(experiment: Experiment) -> tuple[str, str]:
    """The ``env:`` line and the budget line of the start message."""
    cfg = experiment.env_config()
    settings = experiment.train
    world, worlds = _worlds(cfg, settings)
    budget = (
        f"{settings.total_timesteps} steps, seed {settings.seed}, {worlds} ({settings.vec_env})"
    )
    if settings.algorithm == "cost-regression":
        reg = RegressionSettings(**experiment.regression)
        world = f"families {', '.join(settings.families)}, frontier-rule's observation"
        rollouts = f"finished by {reg.finisher}"
        if reg.completions:
            rollouts = f"on {reg.completions} completions of the belief, {rollouts}"
        if reg.label_every > 1:
            rollouts = f"{rollouts}; one decision in {reg.label_every} labelled"
        own = "; ".join(
            f"{name}: {reg.label_episodes_of(name)}, one decision in {reg.label_every_of(name)}, "
            + _label_source(reg.completions_of(name))
            for name in reg.per_family
            if name in settings.families  # the others are not labelled
        )
        budget = (
            f"cost regression: {reg.rounds} rounds of {reg.label_episodes} labelled training "
            f"episodes per family{f' ({own})' if own else ''} (rollouts {rollouts}), "
            f"{reg.fit_epochs} epochs each, seed {settings.seed}"
        )
    if settings.algorithm == "cem":
        cem = CEMSettings(**experiment.cem)
        budget = (
            f"cross-entropy method: {cem.generations} generations of {cem.population} weight "
            f"vectors, {cem.episodes} training episodes per family each, seed {settings.seed}"
        )
    if settings.algorithm != "cost-regression":  # that one takes frontier-rule's observation
        world += f", reward={cfg.reward.kind}, observation={cfg.observation}"
    return world, budget


def _report(result: TrainResult) -> int:
    """Print what the training did and wrote; the exit code (130 when interrupted)."""
    print(
        f"trained {result.steps_this_session} steps in {result.wall_time_s:.1f} s "
        f"({result.steps_per_second:.0f} steps/s; CPU time {result.cpu_time_s:.1f} s); "
        f"total {result.num_timesteps} steps"
    )
    if result.interrupted:
        print(
            f"interrupted: checkpoint saved in {result.files['checkpoint']}\n"
            f"continue with: frontier-marl train --resume {result.run_dir}",
            file=sys.stderr,
        )
        return 130
    if result.evaluation is not None:
        print(format_comparison(result.evaluation))
    if result.best_evaluation is not None:
        chosen = result.best_evaluation.get("validation") or {}
        print(
            f"best validated policy (step {chosen.get('step')}, validation mean "
            f"{chosen.get('mean_reward', float('nan')):.2f}), same protocol:"
        )
        print(format_comparison(result.best_evaluation))
    for label, path in result.files.items():
        print(f"  {label}: {path}")
    return 0


def run(args: argparse.Namespace) -> int:
    try:
        experiment, run_dir, checkpoint = (
            _resumed(args) if args.resume is not None else _fresh(args)
        )
    except ValueError as exc:
        return _fail(str(exc))

    from frontier_marl.training.train import train

    world, budget = _env_and_budget(experiment)
    start = "" if checkpoint is None else f", resuming at step {checkpoint.step}"
    print(
        f"{experiment.name}: {experiment.description}\n"
        f"  env: {world}\n"
        f"  {budget}{start}\n"
        f"  run folder: {run_dir}"
    )
    try:
        result = train(
            experiment,
            run_dir,
            resume=checkpoint,
            progress_bar=not args.no_progress,
            verbose=1 if args.verbose else 0,
        )
    except ValueError as exc:
        return _fail(str(exc))
    return _report(result)
