"""The thesis's main comparison, end to end: configuration 1 (DQN) against the heuristics.

:func:`reproduce` trains ``training/config01.toml`` (thesis-20x20, static map, Reward 2) for
each of ``seeds`` (default 0, 1, 2; all at once in worker processes, see
:mod:`frontier_marl.training.workers`) with :func:`frontier_marl.training.train.train`, whose
final evaluation is the thesis protocol (deterministic, ``episodes`` episodes with reset seeds
``0 .. episodes-1``) of the final model and, with the config's validation, of the
best-validated policy (the one the table reports, the final model beside it); runs the
heuristic baselines on the same env and the same episodes with
:func:`frontier_marl.experiments.baselines.run_baselines`; and writes, under ``out``::

    OUT/comparison.md, comparison.json     ours beside the thesis's figures (docs/results.md):
                                           the seeds' policies pooled, each seed, the final
                                           models, the heuristics; the spread across seeds
    OUT/comparison_rewards.png             mean ± std per policy, thesis bars beside;
                                           coverage versus cells travelled
    OUT/comparison_actions.png             the DQN's action shares beside the thesis's
    OUT/learning_curve.png                 episode reward / TD loss / epsilon, one colour per
                                           seed, with reference lines
    OUT/baselines.json                     the heuristic rows with per-episode records
    OUT/config01_seed<S>/                  each seed's training run (model, evaluation.json, tb/)

The acceptance checks ask every seed's policy to be genuine and the mean over all seeds'
episodes to reach 13.1. ``resume=True`` continues interrupted runs from their newest
checkpoints (or re-evaluates finished ones); a seed with nothing to continue starts fresh.

The training modules (torch, SB3) are imported where they are used: the CLI imports this
module to build its parser, and ``frontier-marl --help`` should not wait for torch.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.evaluation.plots import plot_baselines
from frontier_marl.experiments.baselines import dumps_rows, run_baselines
from frontier_marl.experiments.comparison import (
    comparison_table,
    format_comparison_markdown,
    reported_evaluation,
)
from frontier_marl.policies.model_files import find_checkpoint, list_checkpoints
from frontier_marl.training.experiment import load_experiment
from frontier_marl.training.plots import plot_action_comparison, plot_learning_curves
from frontier_marl.training.validation import read_validation_log
from frontier_marl.utils.checks import check_int
from frontier_marl.utils.json_files import write_json

DEFAULT_CONFIG = "config01"
#: Seeds trained by default: at least three runs, to report their spread (docs/results.md).
DEFAULT_SEEDS: tuple[int, ...] = (0, 1, 2)
HEURISTICS: tuple[str, ...] = ("greedy-distance", "greedy-gain", "cost-utility", "random")


@dataclass
class ReproduceResult:
    """What :func:`reproduce` produced (``table`` is the content of ``comparison.json``;
    ``trains`` holds one ``TrainResult`` per seed, None for a run stopped before it began)."""

    out: Path
    run_dirs: list[Path]
    interrupted: bool
    table: dict[str, Any] | None = None
    files: dict[str, Path] = field(default_factory=dict)
    trains: list[Any] = field(default_factory=list)


def _check_seeds(seeds: Sequence[int]) -> list[int]:
    checked = [check_int("seeds", seed, 0) for seed in seeds]
    if not checked:
        raise ValueError("seeds must name at least one seed")
    if len(set(checked)) != len(checked):
        raise ValueError(f"seeds must be distinct, got {list(seeds)!r}")
    return checked


@dataclass(frozen=True)
class _Plan:
    """The checked budget of a reproduction: where, how long, which seeds, how many at once."""

    out: Path
    steps: int
    seeds: list[int]
    jobs: int
    episodes: int

    @classmethod
    def checked(
        cls, out: str | Path, steps: int, seeds: Sequence[int], jobs: int | None, episodes: int
    ) -> _Plan:
        """Check the arguments of :func:`reproduce` (``ValueError`` on a bad one)."""
        steps = check_int("steps", steps, 1)
        checked_seeds = _check_seeds(seeds)
        jobs = len(checked_seeds) if jobs is None else check_int("jobs", jobs, 1)
        episodes = check_int("episodes", episodes, 1)
        return cls(Path(out), steps, checked_seeds, min(jobs, len(checked_seeds)), episodes)

    @property
    def train_settings(self) -> dict[str, Any]:
        """The ``[train]`` settings every seed's run gets."""
        return {"total_timesteps": self.steps, "eval_episodes": self.episodes, "eval_seed": 0}

    def log_start(self, train_jobs: Sequence[Any], log: Callable[[str], None]) -> None:
        """Log what is trained (and resumed) and how it is evaluated."""
        experiment, seeds = train_jobs[0].experiment, self.seeds
        at_once = "" if len(seeds) == 1 else f" ({self.jobs} runs at a time)"
        start = "".join(
            f", seed {job.experiment.train.seed} resuming at step {job.checkpoint.step}"
            for job in train_jobs
            if job.checkpoint is not None
        )
        log(
            f"[1/3] training {experiment.name} ({experiment.description}): {self.steps} steps, "
            f"seed{'s' if len(seeds) > 1 else ''} {', '.join(map(str, seeds))}{at_once}{start} "
            f"-> {self.out}"
        )
        log(f"      then the thesis evaluation: {self.episodes} deterministic episodes, static map")


def reproduce(
    out: str | Path = "runs/reproduce",
    *,
    steps: int = 1_000_000,
    seeds: Sequence[int] = DEFAULT_SEEDS,
    jobs: int | None = None,
    episodes: int = 30,
    resume: bool = False,
    progress: bool = True,
    config: str | Path = DEFAULT_CONFIG,
    heuristics: Sequence[str] = HEURISTICS,
    log: Callable[[str], None] = print,
) -> ReproduceResult:
    """Train every seed (``jobs`` at a time, default all), evaluate and compare (see the
    module docstring). Raises ``ValueError`` on bad input or when ``out`` already holds a run
    and ``resume`` is false; nothing is trained then."""
    from frontier_marl.training.workers import train_runs

    plan = _Plan.checked(out, steps, seeds, jobs, episodes)
    settings = plan.train_settings
    train_jobs = [_train_job(config, s, settings, plan.out, resume, log) for s in plan.seeds]
    experiment = train_jobs[0].experiment
    plan.log_start(train_jobs, log)
    if plan.jobs > 1:
        _warm_kernels(experiment)  # compile (or load) the kernels once, before the workers
    outcome = train_runs(train_jobs, plan.jobs, progress)
    trained = outcome.results
    result = ReproduceResult(
        out=plan.out,
        run_dirs=[j.run_dir for j in train_jobs],
        interrupted=outcome.interrupted,
        trains=trained,
    )
    if outcome.interrupted or any(t is None or t.evaluation is None for t in trained):
        result.interrupted = True
        return result
    episodes = plan.episodes
    log(f"[2/3] heuristic baselines on the same {episodes} episodes: {', '.join(heuristics)}")
    baseline_rows = run_baselines(dict(experiment.env), list(heuristics), episodes, 0, progress)
    log("[3/3] comparison table and figures")
    result.table, reported = comparison_table(
        experiment, plan.seeds, plan.jobs, trained, baseline_rows
    )
    result.files.update(_write_tables(plan.out, result.table, baseline_rows))
    result.files.update(
        _figures(plan.out, result.table, reported, baseline_rows, trained, experiment.name)
    )
    return result


def _write_tables(
    out: Path, table: Mapping[str, Any], baseline_rows: Sequence[Mapping[str, Any]]
) -> dict[str, Path]:
    """comparison.md, comparison.json and baselines.json."""
    out.mkdir(parents=True, exist_ok=True)
    files = {"markdown": out / "comparison.md"}
    files["markdown"].write_text(format_comparison_markdown(table), encoding="utf-8")
    files["json"] = write_json(table, out / "comparison.json")
    files["baselines"] = out / "baselines.json"
    files["baselines"].write_text(dumps_rows(baseline_rows))
    return files


def _train_job(
    config: str | Path,
    seed: int,
    settings: Mapping[str, Any],
    out: Path,
    resume: bool,
    log: Callable[[str], None],
) -> Any:
    """The training job of one seed: a fresh run, or the run in ``out`` to resume."""
    from frontier_marl.training.train import resume_experiment
    from frontier_marl.training.workers import TrainJob

    experiment = load_experiment(
        config, [f"train.{k}={v}" for k, v in {**settings, "seed": seed}.items()]
    )
    cfg = experiment.env_config()
    if cfg.map_mode != "static":
        raise ValueError(f"the thesis protocol needs a static map; {config} has {cfg.map_mode!r}")
    run_dir = out / f"{experiment.name}_seed{seed}"
    checkpoint, overwrite = None, False
    if list_checkpoints(run_dir) or (run_dir / "model.zip").exists():
        if not resume:
            raise ValueError(
                f"{str(run_dir)!r} already holds a run: add --resume to continue it (or to "
                "re-evaluate a finished one), or choose another --out"
            )
        checkpoint = find_checkpoint(run_dir)
        experiment = resume_experiment(checkpoint, dict(settings))
    elif resume:
        log(f"nothing to resume in {run_dir}: starting a fresh run")
        overwrite = True  # what an unfinished run left there (a log, its run.json)
    return TrainJob(experiment, run_dir, checkpoint, label=f"seed {seed}", overwrite=overwrite)


def _warm_kernels(experiment: Any) -> None:
    """One reset and step of the env, so the compiled kernels are on disk before several
    worker processes load them at once."""
    env = FrontierParallelEnv(config=experiment.env_config())
    env.reset(seed=0)
    env.step({agent: 0 for agent in env.agents})
    env.close()


def _where(table: Mapping[str, Any]) -> str:
    """The setting and the training, for the figures' titles."""
    setting, training = table["setting"], table["training"]
    seeds = training["seeds"]
    return (
        f"{setting['preset']}, {setting['map_mode']} map, {setting['episodes']} "
        f"episodes; DQN {training['steps']} steps, seed{'s' if len(seeds) > 1 else ''} "
        f"{', '.join(map(str, seeds))}"
    )


def _reward_rows(
    table: Mapping[str, Any], reported: Mapping[str, Any], trained: Sequence[Any]
) -> list[dict[str, Any]]:
    """The DQN rows of the rewards figure: the reported one with the thesis's figures, and
    each seed's when there are several."""
    dqn = table["rows"][0]
    seeds = table["training"]["seeds"]
    model_row = {
        **reported,
        "policy": dqn["policy"],
        "thesis_mean": dqn["thesis_mean"],
        "thesis_std": dqn["thesis_std"],
    }
    seed_rows = []
    if len(seeds) > 1:
        seed_rows = [
            {**reported_evaluation(t)["model"], "policy": f"DQN seed {seed}"}
            for seed, t in zip(seeds, trained, strict=True)
        ]
    return [model_row, *seed_rows]


def _reference_lines(table: Mapping[str, Any]) -> dict[str, float]:
    """The learning curve's reference lines: the thesis's DQN and our greedy distance."""
    dqn = table["rows"][0]
    reference = {}
    if dqn["thesis_mean"] is not None:
        reference[f"thesis DQN, evaluation ({dqn['thesis_mean']:.2f})"] = dqn["thesis_mean"]
    greedy = next((r for r in table["rows"] if r["policy"] == "greedy-distance"), None)
    if greedy is not None:
        reference[f"greedy-distance, ours ({greedy['mean_reward']:.2f})"] = greedy["mean_reward"]
    return reference


def _figures(
    out: Path,
    table: Mapping[str, Any],
    reported: Mapping[str, Any],
    baseline_rows: Sequence[Mapping[str, Any]],
    trained: Sequence[Any],
    name: str,
) -> dict[str, Path]:
    from frontier_marl.training.callbacks import read_metrics

    dqn, training = table["rows"][0], table["training"]
    where = _where(table)
    files = {
        "rewards_figure": out / "comparison_rewards.png",
        "actions_figure": out / "comparison_actions.png",
        "learning_curve": out / "learning_curve.png",
    }
    plot_baselines(
        [*_reward_rows(table, reported, trained), *baseline_rows],
        files["rewards_figure"],
        title=f"ours beside the thesis ({where})",
    )
    plot_action_comparison(
        dqn["action_shares"],
        dqn["thesis_action_shares"] or [],
        files["actions_figure"],
        labels=(f"ours ({training['steps']} steps)", "thesis (1e6 steps)"),
        title=f"{dqn['policy']}: share of each slot ({dqn['episodes']} deterministic episodes)",
    )
    curves = [
        (f"seed {seed}", read_metrics(t.run_dir / "metrics.jsonl"), read_validation_log(t.run_dir))
        for seed, t in zip(training["seeds"], trained, strict=True)
    ]
    reference = _reference_lines(table)
    plot_learning_curves(
        curves, files["learning_curve"], title=f"{name} ({where})", reference=reference
    )
    return files
