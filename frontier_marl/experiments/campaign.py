"""A training campaign on Ray Tune: a grid of experiment configs x seeds x budgets.

Each Ray Tune trial is one training run: :func:`run_trial` calls the same
:func:`frontier_marl.training.train.train` as ``frontier-marl train`` (``torch_threads=1``, no
progress bar) into its own run folder ``OUT/runs/<config>/seed<S>_steps<N>`` and reports the
run's summary row (:func:`frontier_marl.experiments.results.summary_row`). The driver collects
the rows into ``OUT/campaign.md``, ``campaign.csv`` and ``campaign.json``.

The experiments are read and validated by the driver and sent to the trials as dicts, so the
workers need the ``frontier_marl`` package but not the TOML files. Ray is an optional extra
(:mod:`frontier_marl.experiments.ray_tune`). By default a local Ray
instance is started (``ray.init()``, all cores); ``address`` connects to an existing cluster
(``"auto"`` or ``"ray://host:10001"``); an already initialised Ray is used as it is. On a
multi-node cluster ``out`` must be a folder every node can write (shared storage) for the run
folders; the table is built from the reported results either way.

Re-running a campaign into the same ``out`` reuses finished runs (their ``evaluation.json``)
and resumes interrupted ones from their newest checkpoint.

Ray and the training modules are imported where they are used: Ray is an optional extra, and
the CLI imports this module to build its parser.
"""

from __future__ import annotations

import itertools
import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from frontier_marl.experiments.ray_tune import (
    RayNotInstalledError,
    fit_trials,
    flat_scalars,
    require_ray,
)
from frontier_marl.experiments.results import (
    SUMMARY_COLUMNS,
    run_summary,
    sort_rows,
    summary_row,
    training_wall_time,
    write_table,
)
from frontier_marl.policies.metadata import load_metadata
from frontier_marl.policies.model_files import list_checkpoints, newest_good_checkpoint
from frontier_marl.training.experiment import experiment_from_dict, load_experiment
from frontier_marl.utils.parallel import init_ray

__all__ = ["CampaignResult", "RayNotInstalledError", "TrialSpec", "build_grid", "run_campaign"]

#: Extra columns of a campaign row (after
#: :data:`~frontier_marl.experiments.results.SUMMARY_COLUMNS`).
TRIAL_COLUMNS: tuple[str, ...] = ("status", "reused", "trial_wall_time_s", "node", "error")


@dataclass(frozen=True)
class TrialSpec:
    """One cell of the grid: an experiment (as a dict), a seed and a budget."""

    config: str
    seed: int
    steps: int
    experiment: dict[str, Any]
    run_dir: str
    eval_episodes: int

    @property
    def name(self) -> str:
        return f"{self.config}_seed{self.seed}_steps{self.steps}"


@dataclass
class CampaignResult:
    rows: list[dict[str, Any]]
    files: dict[str, Path] = field(default_factory=dict)
    wall_time_s: float = 0.0

    @property
    def failed(self) -> list[dict[str, Any]]:
        return [row for row in self.rows if row.get("status") != "ok"]


def build_grid(
    configs: Sequence[str | Path],
    seeds: Sequence[int],
    budgets: Sequence[int],
    out: str | Path,
    *,
    eval_episodes: int = 30,
    overrides: Sequence[str] = (),
) -> list[TrialSpec]:
    """Load and validate every config (``ValueError`` on a bad one) and list the trials."""
    for name, values, low in (("seeds", seeds, 0), ("steps", budgets, 1)):
        if not values:
            raise ValueError(f"--{name} must list at least one value")
        for value in values:
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise ValueError(f"--{name} values must be integers >= {low}, got {value!r}")
    if not configs:
        raise ValueError("--configs must name at least one config")
    if isinstance(eval_episodes, bool) or not isinstance(eval_episodes, int) or eval_episodes < 1:
        raise ValueError(f"--episodes must be an integer >= 1, got {eval_episodes!r}")
    out = Path(out).resolve()
    experiments = [load_experiment(config, overrides) for config in configs]
    names = [e.name for e in experiments]
    if len(set(names)) != len(names):
        raise ValueError(f"--configs names an experiment twice: {names}")
    trials = []
    for experiment, seed, steps in itertools.product(experiments, seeds, budgets):
        data = experiment.to_dict()
        data["train"].update(
            total_timesteps=int(steps),
            seed=int(seed),
            eval_episodes=eval_episodes,
            torch_threads=1,
        )
        run_dir = out / "runs" / experiment.name / f"seed{seed}_steps{steps}"
        trials.append(
            TrialSpec(experiment.name, int(seed), int(steps), data, str(run_dir), eval_episodes)
        )
    return trials


def run_trial(spec: TrialSpec) -> dict[str, Any]:
    """Train and evaluate one grid cell into ``spec.run_dir``; the run's summary row.

    A run folder that already holds a finished run with ``evaluation.json`` for this budget
    and number of episodes is reused; one with a checkpoint is resumed.
    """
    started = time.perf_counter()
    run_dir = Path(spec.run_dir)
    _check_same_experiment(run_dir, spec)
    if _finished(run_dir, spec):
        row = run_summary(run_dir)
        row["config"] = spec.config
        row["reused"] = True
    else:
        row = _train_trial(spec, run_dir)
        row["reused"] = False
    row["status"] = "ok"
    row["trial_wall_time_s"] = round(time.perf_counter() - started, 2)
    return row


def _train_trial(spec: TrialSpec, run_dir: Path) -> dict[str, Any]:
    """Train (resuming from the newest checkpoint) and evaluate; the run's summary row."""
    from frontier_marl.training.train import resume_experiment, train

    experiment = experiment_from_dict(spec.experiment, source=spec.config)
    checkpoint = newest_good_checkpoint(run_dir)
    if checkpoint is not None:
        settings = spec.experiment["train"]
        keys = ("total_timesteps", "eval_episodes", "torch_threads")
        experiment = resume_experiment(checkpoint, {key: settings[key] for key in keys})
    # the campaign owns its run folders: an unfinished run without a checkpoint restarts
    result = train(experiment, run_dir, resume=checkpoint, progress_bar=False, overwrite=True)
    if result.interrupted or result.evaluation is None:
        raise RuntimeError(
            f"training of {spec.name} was interrupted at step {result.num_timesteps}"
        )
    return summary_row(
        result.evaluation,
        config=spec.config,
        seed=spec.seed,
        steps=result.num_timesteps,
        wall_time_s=training_wall_time(run_dir) or result.wall_time_s,
        run_dir=run_dir,
    )


def _check_same_experiment(run_dir: Path, spec: TrialSpec) -> None:
    """Refuse to reuse or resume a run folder that holds another experiment's run."""
    sources = [run_dir / "model.zip", *(c.model for c in list_checkpoints(run_dir)[-1:])]
    for model in sources:
        meta = load_metadata(model) if model.is_file() else None
        saved = (meta or {}).get("experiment")
        if not saved:
            continue
        wanted = json.loads(json.dumps(spec.experiment))
        for key in ("env", "dqn", "ppo"):
            if json.loads(json.dumps(saved.get(key))) != wanted.get(key):
                raise ValueError(
                    f"{run_dir} holds a run whose [{key}] settings differ from {spec.config}'s "
                    "(changed config or --set?): choose another --out"
                )
        if saved.get("train", {}).get("seed") != spec.seed:
            raise ValueError(f"{run_dir} holds a run with another seed: choose another --out")


def _finished(run_dir: Path, spec: TrialSpec) -> bool:
    """Whether ``run_dir`` holds a finished, evaluated run of at least ``spec``'s budget."""
    path = run_dir / "evaluation.json"
    meta = run_dir / "model.json"
    if not (path.is_file() and meta.is_file()):
        return False
    evaluation = json.loads(path.read_text())
    steps = json.loads(meta.read_text()).get("num_timesteps", 0)
    return steps >= spec.steps and evaluation.get("episodes") == spec.eval_episodes


def _ray_trainable(config: dict[str, Any], trials: Sequence[TrialSpec]) -> None:
    """The Ray Tune function trainable: one grid cell, one final report."""
    from ray import tune

    tune.report(flat_scalars(run_trial(trials[config["trial"]])))


#: Keys of a trial's report kept in the table (Tune adds its own bookkeeping keys).
_ROW_KEYS = (*SUMMARY_COLUMNS, "reused", "status", "trial_wall_time_s")


def _row_from_report(report: dict[str, Any], spec: TrialSpec) -> dict[str, Any]:
    """The table row of a trial's last report (undoing :func:`~frontier_marl.experiments.
    ray_tune.flat_scalars`)."""
    row: dict[str, Any] = {}
    for key in _ROW_KEYS:
        value = report.get(key)
        if isinstance(value, float) and math.isnan(value):
            value = None
        row[key] = value
    if isinstance(row["action_shares"], str):
        row["action_shares"] = json.loads(row["action_shares"])
    for key in ("seed", "steps", "terminations", "episodes"):
        if row.get(key) is not None:
            row[key] = int(row[key])
    row["config"] = spec.config
    row["node"] = report.get("hostname")
    return row


def _failed_row(spec: TrialSpec, error: str) -> dict[str, Any]:
    return {
        "config": spec.config,
        "seed": spec.seed,
        "steps": spec.steps,
        "episodes": spec.eval_episodes,
        "run_dir": spec.run_dir,
        "status": "error",
        "error": error,
    }


@dataclass(frozen=True)
class _CampaignSettings:
    """The arguments of :func:`run_campaign` that reach the log line and the table."""

    configs: Sequence[str | Path]
    seeds: Sequence[int]
    budgets: Sequence[int]
    out: Path
    address: str | None
    cpus_per_trial: float
    max_concurrent: int | None
    eval_episodes: int
    overrides: Sequence[str]

    def __post_init__(self) -> None:
        if not self.cpus_per_trial > 0:
            raise ValueError(f"--cpus-per-trial must be > 0, got {self.cpus_per_trial!r}")
        if self.max_concurrent is not None and self.max_concurrent < 1:
            raise ValueError(f"--max-concurrent must be >= 1, got {self.max_concurrent!r}")

    def table_extra(self, wall: float) -> dict[str, Any]:
        """The campaign's settings and wall time, as recorded in ``campaign.json``."""
        return {
            "configs": [str(c) for c in self.configs],
            "seeds": list(self.seeds),
            "budgets": list(self.budgets),
            "eval_episodes": self.eval_episodes,
            "overrides": list(self.overrides),
            "address": self.address,
            "cpus_per_trial": self.cpus_per_trial,
            "max_concurrent": self.max_concurrent,
            "wall_time_s": round(wall, 2),
        }


def _init_ray(address: str | None, log: Callable[[str], None]) -> bool:
    """Start or connect to Ray unless it is already initialised; whether it was started."""
    try:
        started = init_ray(address)
    except ConnectionError as exc:
        raise ValueError(f"--address {address}: {exc}") from exc
    if not started and address is not None:
        log(f"note: Ray is already initialised; ignoring --address {address}")
    return started


def _log_start(
    settings: _CampaignSettings, trials: Sequence[TrialSpec], log: Callable[[str], None]
) -> None:
    """Log the trials, the cluster's CPUs, the per-trial resources and the output folder."""
    import ray

    resources = ray.cluster_resources()
    address, max_concurrent = settings.address, settings.max_concurrent
    log(
        f"campaign: {len(trials)} trial(s) on Ray ({resources.get('CPU', 0):.0f} CPUs"
        f"{', ' + address if address else ', local'}), {settings.cpus_per_trial} CPU(s) per trial"
        f"{f', at most {max_concurrent} at once' if max_concurrent else ''} -> {settings.out}"
    )


def _grid_row(result: Any, trials: Sequence[TrialSpec]) -> dict[str, Any]:
    """The table row of one Ray Tune result: its report, or a failed row."""
    spec = trials[int(result.config["trial"])]
    if result.error is not None:
        lines = str(result.error).strip().splitlines() or [type(result.error).__name__]
        return _failed_row(spec, lines[-1].strip())
    if not result.metrics or "mean_reward" not in result.metrics:
        return _failed_row(spec, "the trial reported no result")
    return _row_from_report(dict(result.metrics), spec)


def _fit(
    tune: Any, settings: _CampaignSettings, trials: list[TrialSpec], progress: bool, shutdown: bool
) -> Any:
    """Run the trials on Ray Tune; shut Ray down afterwards if ``shutdown`` (Ray started here)."""
    import ray

    try:
        names = [spec.name for spec in trials]
        return fit_trials(
            tune,
            _ray_trainable,
            names,
            settings.out,
            settings.cpus_per_trial,
            settings.max_concurrent,
            progress,
            trials=list(trials),
        )
    finally:
        if shutdown:
            ray.shutdown()


def run_campaign(
    configs: Sequence[str | Path],
    seeds: Sequence[int],
    budgets: Sequence[int],
    out: str | Path = "runs/campaign",
    *,
    address: str | None = None,
    cpus_per_trial: float = 1,
    max_concurrent: int | None = None,
    eval_episodes: int = 30,
    overrides: Sequence[str] = (),
    progress: bool = True,
    log: Callable[[str], None] = print,
) -> CampaignResult:
    """Run the grid on Ray Tune and write the table (see the module docstring).

    Raises :class:`RayNotInstalledError` without ``ray[tune]`` and ``ValueError`` on bad
    input (before Ray starts).
    """
    tune = require_ray()
    settings = _CampaignSettings(
        configs,
        seeds,
        budgets,
        Path(out).resolve(),
        address,
        cpus_per_trial,
        max_concurrent,
        eval_episodes,
        overrides,
    )  # checks the Ray options before the configs are read
    trials = build_grid(
        configs, seeds, budgets, out, eval_episodes=eval_episodes, overrides=overrides
    )
    settings.out.mkdir(parents=True, exist_ok=True)
    started_ray = _init_ray(address, log)
    _log_start(settings, trials, log)
    started = time.perf_counter()
    grid = _fit(tune, settings, trials, progress, started_ray)
    rows = sort_rows([_grid_row(result, trials) for result in grid])
    wall = time.perf_counter() - started
    files = write_table(
        rows,
        settings.out / "campaign",
        title=f"Campaign: {len(trials)} trial(s), {eval_episodes} evaluation episodes each",
        columns=(*SUMMARY_COLUMNS, *TRIAL_COLUMNS),
        extra=settings.table_extra(wall),
    )
    return CampaignResult(rows=rows, files=files, wall_time_s=wall)
