"""The thesis's main comparison, end to end: configuration 1 (DQN) against the heuristics.

:func:`reproduce` trains ``training/config01.toml`` (thesis-20x20, static map, Reward 2) for
each of ``seeds`` (default 0, 1, 2; all at once in worker processes, see
:mod:`frontier_marl.training.workers`) with :func:`frontier_marl.training.train.train`, whose
final evaluation is the thesis protocol (deterministic, ``episodes`` episodes with reset seeds
``0 .. episodes-1``) of the final model and, with the config's validation, of the
best-validated policy (the one the table reports, the final model beside it); runs the
heuristic baselines on the same env and the same episodes with
:func:`frontier_marl.workflows.baselines.run_baselines`; and writes, under ``out``::

    OUT/comparison.md, comparison.json     ours beside the thesis's figures (SPEC section 6):
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
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from frontier_marl.evaluation.metrics import action_shares, mean_std
from frontier_marl.thesis import CONFIG01_MIN_MEAN as MIN_MEAN
from frontier_marl.thesis import DQN_RESULTS
from frontier_marl.training.evaluate_model import degeneracy
from frontier_marl.workflows.results import (
    format_shares,
    summary_row,
    training_wall_time,
)

DEFAULT_CONFIG = "config01"
#: Seeds trained by default: the issue asks for at least three runs and their spread.
DEFAULT_SEEDS: tuple[int, ...] = (0, 1, 2)
HEURISTICS: tuple[str, ...] = ("greedy-distance", "greedy-gain", "cost-utility", "random")

#: The issue's bar for a genuine reproduction of configuration 1 at 1e6 steps: no action above
#: 70 % of steps, at least three actions above 2 %, mean at least the thesis's mean - 1 std.
GENUINE_MAX_SHARE = 0.70
GENUINE_MIN_SHARE = 0.02
GENUINE_MIN_ACTIONS = 3

#: Columns of the comparison table: (key, header).
COLUMNS: tuple[tuple[str, str], ...] = (
    ("policy", "policy"),
    ("ours", "ours: mean ± std"),
    ("thesis", "thesis: mean ± std"),
    ("terminations", "terminations (ours)"),
    ("thesis_terminations", "terminations (thesis)"),
    ("action_shares", "action shares (ours)"),
    ("thesis_action_shares", "action shares (thesis)"),
    ("degenerate", "degenerate"),
)


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


def _check_int(name: str, value: Any, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)


def comparison_row(
    row: Mapping[str, Any], kind: str, thesis: Mapping[str, Any] | None, name: str | None = None
) -> dict[str, Any]:
    """A compact row of the comparison table from an evaluation row
    (:meth:`~frontier_marl.evaluation.EvaluationResult.to_dict`), with the thesis's figures."""
    deg = _degeneracy(row)
    thesis = thesis or {}
    return {
        "policy": name or row["policy"],
        "kind": kind,
        "mean_reward": float(row["mean_reward"]),
        "std_reward": float(row["std_reward"]),
        "terminations": int(row["terminations"]),
        "episodes": int(row["episodes"]),
        "action_shares": [float(s) for s in row["action_shares"]],
        "degenerate": bool(deg["degenerate"]),
        "dominant_action": deg["dominant_action"],
        "dominant_share": deg["dominant_share"],
        "mean_travelled": row.get("mean_travelled"),
        "thesis_mean": thesis.get("mean"),
        "thesis_std": thesis.get("std"),
        "thesis_terminations": thesis.get("terminations"),
        "thesis_episodes": thesis.get("episodes"),
        "thesis_action_shares": thesis.get("action_shares"),
    }


def genuine_checks(policies: Sequence[Mapping[str, Any]], mean: float) -> dict[str, bool]:
    """The issue's acceptance checks (meant for the full 1e6-step budget): every seed's policy
    is genuine (``policies``: evaluation rows with ``action_shares``), and the mean reward over
    all seeds' episodes (``mean``) reaches the bar."""
    return {
        "max_share_at_most_70pct": all(
            max(row["action_shares"]) <= GENUINE_MAX_SHARE for row in policies
        ),
        "three_actions_above_2pct": all(
            sum(s > GENUINE_MIN_SHARE for s in row["action_shares"]) >= GENUINE_MIN_ACTIONS
            for row in policies
        ),
        "mean_at_least_13.1": bool(mean >= MIN_MEAN),
    }


def _mean_std(mean: float | None, std: float | None) -> str:
    if mean is None:
        return "—"
    return f"{mean:.2f} ± {std:.2f}" if std is not None else f"{mean:.2f}"


def _cells(row: Mapping[str, Any]) -> dict[str, str]:
    thesis_term = row["thesis_terminations"]
    return {
        "policy": row["policy"],
        "ours": _mean_std(row["mean_reward"], row["std_reward"]),
        "thesis": _mean_std(row["thesis_mean"], row["thesis_std"]),
        "terminations": f"{row['terminations']}/{row['episodes']}",
        "thesis_terminations": "—"
        if thesis_term is None
        else f"{thesis_term}/{row['thesis_episodes']}",
        "action_shares": format_shares(row["action_shares"]),
        "thesis_action_shares": format_shares(row["thesis_action_shares"]),
        "degenerate": "yes" if row["degenerate"] else "no",
    }


def format_comparison_markdown(table: Mapping[str, Any]) -> str:
    """The comparison as Markdown: setting, table, seed spread, acceptance checks."""
    setting, training = table["setting"], table["training"]
    seeds = training["seeds"]
    walls = ", ".join(f"{run['wall_time_s']:.0f}" for run in training["runs"])
    if len(seeds) == 1:
        runs = f"seed {seeds[0]}, {training['steps']} training steps"
        walls = f"{walls} s of training"
        reports = f"The DQN row is the run's {training['runs'][0]['reported_policy']}"
    else:
        runs = (
            f"seeds {', '.join(map(str, seeds))} ({training['jobs']} runs at a time), "
            f"{training['steps']} training steps each"
        )
        walls = f"training wall time per run {walls} s"
        reports = f"The DQN rows are each run's {training['reported_policy']}"
    lines = [
        f"# {table['title']}",
        "",
        f"{setting['preset']} ({setting['height']}x{setting['width']}, "
        f"r={setting['perception_range']}), {setting['map_mode']} map "
        f"(map_seed {setting['map_seed']}), {setting['episodes']} deterministic episodes "
        f"(reset seeds {setting['seeds'][0]}..{setting['seeds'][1]}), the same episodes for "
        "every policy.",
        f"DQN: {training['config']} ({training['description']}), {runs} (thesis: "
        f"{training['thesis_steps']}), {walls}. {reports}.",
        "",
        "| " + " | ".join(header for _key, header in COLUMNS) + " |",
        "|" + "---|" * len(COLUMNS),
    ]
    for row in table["rows"]:
        cells = _cells(row)
        lines.append("| " + " | ".join(cells[key] for key, _header in COLUMNS) + " |")
    spread = table["seed_spread"]
    if len(seeds) > 1:
        means = ", ".join(f"{m:.2f}" for m in spread["means"])
        lines += [
            "",
            f"Across seeds: {spread['mean']:.2f} ± {spread['std']:.2f} (mean ± std of the "
            f"{len(seeds)} seeds' means: {means}); {spread['at_least_min_mean']} of "
            f"{len(seeds)} at or above {MIN_MEAN} on their own.",
        ]
    checks = table["checks"]
    lines += ["", f"Checks of the DQN row (the issue's bar for {training['thesis_steps']} steps):"]
    lines += [f"- {name}: {'pass' if ok else 'FAIL'}" for name, ok in checks.items()]
    if len(seeds) > 1:
        lines.append(
            f"- (the share checks apply to every seed's policy; the mean is over all "
            f"{len(seeds)} seeds' episodes)"
        )
    if training["steps"] < training["thesis_steps"]:
        lines.append(
            f"- note: trained for {training['steps']} steps, fewer than the thesis's "
            f"{training['thesis_steps']}; the DQN row is not expected to match."
        )
    return "\n".join(lines) + "\n"


def pool_evaluations(rows: Sequence[Mapping[str, Any]], policy: str) -> dict[str, Any]:
    """One evaluation row (as in ``evaluation.json``'s ``model``) holding the episodes of
    several runs' rows together: e.g. every seed's policy on the protocol's episodes."""
    rewards = [float(r) for row in rows for r in row["rewards"]]
    counts = np.sum([row["action_counts"] for row in rows], axis=0, dtype=np.int64)
    episodes = [int(row["episodes"]) for row in rows]
    mean, std = mean_std(rewards)
    shares = action_shares(counts.tolist())
    return {
        "policy": policy,
        "episodes": len(rewards),
        "n_agents": 1,
        "mean_reward": mean,
        "std_reward": std,
        "rewards": rewards,
        "terminations": sum(int(row["terminations"]) for row in rows),
        "action_counts": counts.tolist(),
        "action_shares": shares,
        # degenerate when any run is (pooling a degenerate run with genuine ones can hide it)
        "degeneracy": {
            **degeneracy(shares),
            "degenerate": any(_degeneracy(row)["degenerate"] for row in rows),
        },
        "mean_travelled": float(
            np.average([row["mean_travelled"] for row in rows], weights=episodes)
        ),
        "per_episode": [e for row in rows for e in row.get("per_episode", [])],
    }


def _degeneracy(row: Mapping[str, Any]) -> dict[str, Any]:
    return row.get("degeneracy") or degeneracy(row["action_shares"])


def seed_spread(seeds: Sequence[int], rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Each seed's mean reward, their mean and population std, and how many reach the bar."""
    means = [float(row["mean_reward"]) for row in rows]
    mean, std = mean_std(means)
    return {
        "seeds": list(seeds),
        "means": means,
        "mean": mean,
        "std": std,
        "min": min(means),
        "max": max(means),
        "at_least_min_mean": sum(m >= MIN_MEAN for m in means),
    }


def _check_seeds(seeds: Sequence[int]) -> list[int]:
    checked = [_check_int("seeds", seed, 0) for seed in seeds]
    if not checked:
        raise ValueError("seeds must name at least one seed")
    if len(set(checked)) != len(checked):
        raise ValueError(f"seeds must be distinct, got {list(seeds)!r}")
    return checked


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
    from frontier_marl.training.train import write_json
    from frontier_marl.training.workers import train_runs
    from frontier_marl.workflows.baselines import dumps_rows, run_baselines

    steps = _check_int("steps", steps, 1)
    seeds = _check_seeds(seeds)
    jobs = len(seeds) if jobs is None else _check_int("jobs", jobs, 1)
    episodes = _check_int("episodes", episodes, 1)
    out = Path(out)
    settings = {"total_timesteps": steps, "eval_episodes": episodes, "eval_seed": 0}
    train_jobs = [_train_job(config, seed, settings, out, resume, log) for seed in seeds]
    experiment = train_jobs[0].experiment
    jobs = min(jobs, len(seeds))

    at_once = "" if len(seeds) == 1 else f" ({jobs} runs at a time)"
    start = "".join(
        f", seed {job.experiment.train.seed} resuming at step {job.checkpoint.step}"
        for job in train_jobs
        if job.checkpoint is not None
    )
    log(
        f"[1/3] training {experiment.name} ({experiment.description}): {steps} steps, "
        f"seed{'s' if len(seeds) > 1 else ''} {', '.join(map(str, seeds))}{at_once}{start} "
        f"-> {out}"
    )
    log(f"      then the thesis evaluation: {episodes} deterministic episodes, static map")
    if jobs > 1:
        _warm_kernels(experiment)  # compile (or load) the kernels once, before the workers
    outcome = train_runs(train_jobs, jobs, progress)
    run_dirs = [j.run_dir for j in train_jobs]
    trained = outcome.results
    result = ReproduceResult(
        out=out, run_dirs=run_dirs, interrupted=outcome.interrupted, trains=trained
    )
    if outcome.interrupted or any(t is None or t.evaluation is None for t in trained):
        result.interrupted = True
        return result

    log(f"[2/3] heuristic baselines on the same {episodes} episodes: {', '.join(heuristics)}")
    env_kwargs = dict(experiment.env)
    baseline_rows = run_baselines(env_kwargs, list(heuristics), episodes, 0, progress)

    log("[3/3] comparison table and figures")
    table, reported = comparison_table(experiment, seeds, jobs, trained, baseline_rows)
    result.table = table
    files = result.files
    out.mkdir(parents=True, exist_ok=True)
    files["markdown"] = out / "comparison.md"
    files["markdown"].write_text(format_comparison_markdown(table), encoding="utf-8")
    files["json"] = write_json(table, out / "comparison.json")
    files["baselines"] = out / "baselines.json"
    files["baselines"].write_text(dumps_rows(baseline_rows))
    files.update(_figures(out, table, reported, baseline_rows, trained, experiment.name))
    return result


def _train_job(
    config: str | Path,
    seed: int,
    settings: Mapping[str, Any],
    out: Path,
    resume: bool,
    log: Callable[[str], None],
) -> Any:
    """The training job of one seed: a fresh run, or the run in ``out`` to resume."""
    from frontier_marl.training.checkpoints import find_checkpoint, list_checkpoints
    from frontier_marl.training.experiment import load_experiment
    from frontier_marl.training.train import resume_experiment
    from frontier_marl.training.workers import TrainJob

    experiment = load_experiment(
        config, [f"train.{k}={v}" for k, v in {**settings, "seed": seed}.items()]
    )
    cfg = experiment.env_config()
    if cfg.map_mode != "static":
        raise ValueError(f"the thesis protocol needs a static map; {config} has {cfg.map_mode!r}")
    run_dir = out / f"{experiment.name}_seed{seed}"
    checkpoint = None
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
    return TrainJob(experiment, run_dir, checkpoint, label=f"seed {seed}")


def _warm_kernels(experiment: Any) -> None:
    """One reset and step of the env, so the compiled kernels are on disk before several
    worker processes load them at once."""
    from frontier_marl.envs.parallel import FrontierParallelEnv

    env = FrontierParallelEnv(config=experiment.env_config())
    env.reset(seed=0)
    env.step({agent: 0 for agent in env.agents})
    env.close()


def comparison_table(
    experiment: Any,
    seeds: Sequence[int],
    jobs: int,
    trained: Sequence[Any],
    baseline_rows: Sequence[Mapping[str, Any]],
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The content of ``comparison.json``, and the evaluation row the DQN row reports (the
    runs' episodes pooled when there are several seeds)."""
    name = experiment.name
    cfg = experiment.env_config()
    episodes = experiment.train.eval_episodes
    thesis_dqn = DQN_RESULTS.get(name)
    # With validation (train.validate_every) each run reports its best-validated policy,
    # chosen on held-out episodes, never the protocol's; the final models are shown below.
    reported = [reported_evaluation(t) for t in trained]
    validated = all(t.best_evaluation is not None for t in trained)
    models = [r["model"] for r in reported]
    finals = [t.evaluation["model"] for t in trained]
    several = len(seeds) > 1
    dqn_row = pool_evaluations(models, f"DQN {name}") if several else models[0]
    rows = [comparison_row(dqn_row, "dqn", thesis_dqn, name=f"DQN {name}")]
    if several:
        for seed, r in zip(seeds, reported, strict=True):
            step = f" (step {r['validation']['step']})" if "validation" in r else ""
            rows.append(
                comparison_row(r["model"], "dqn", None, name=f"DQN {name}, seed {seed}{step}")
            )
    if validated:
        label = f"DQN {name}, final model{'s' if several else ''}"
        final_row = pool_evaluations(finals, label) if several else finals[0]
        rows.append(comparison_row(final_row, "dqn", None, name=label))
    for row in baseline_rows:
        thesis = None
        if row.get("thesis_mean") is not None:
            thesis = {"mean": row["thesis_mean"], "std": row["thesis_std"], "episodes": 30}
        rows.append(comparison_row(row, "heuristic", thesis))

    runs = []
    for seed, t, r in zip(seeds, trained, reported, strict=True):
        wall = training_wall_time(t.run_dir) or t.wall_time_s
        runs.append(
            {
                "seed": seed,
                "run_dir": str(t.run_dir),
                "steps": t.num_timesteps,
                "wall_time_s": round(wall, 2),
                "steps_per_second": round(t.num_timesteps / wall, 1) if wall > 0 else None,
                "reported_policy": _selection(r),
                "mean_reward": float(r["model"]["mean_reward"]),
                "final_mean_reward": float(t.evaluation["model"]["mean_reward"]),
            }
        )
    spread = seed_spread(seeds, models)
    table = {
        "title": f"Thesis comparison: {name} (DQN) and the heuristic baselines",
        "setting": {
            "preset": experiment.env.get("preset", "thesis-20x20"),
            "height": cfg.height,
            "width": cfg.width,
            "perception_range": cfg.perception_range,
            "map_mode": cfg.map_mode,
            "map_seed": cfg.map_seed,
            "reward": cfg.reward.kind,
            "episodes": episodes,
            "seeds": [0, episodes - 1],
            "deterministic": True,
        },
        "training": {
            "config": name,
            "description": experiment.description,
            "reported_policy": (
                "best-validated policy (chosen on held-out episodes, never the protocol's)"
                if validated
                else "final model"
            ),
            "seeds": list(seeds),
            "jobs": jobs,
            "steps": min(t.num_timesteps for t in trained),
            "thesis_steps": (thesis_dqn or {}).get("steps", 1_000_000),
            "runs": runs,
            "source": experiment.source,
        },
        "summaries": [
            summary_row(
                r,
                config=name,
                seed=seed,
                steps=t.num_timesteps,
                wall_time_s=run["wall_time_s"],
                run_dir=t.run_dir,
            )
            for seed, t, r, run in zip(seeds, trained, reported, runs, strict=True)
        ],
        "seed_spread": spread,
        "rows": rows,
        "checks": genuine_checks(models, spread["mean"]),
    }
    return table, dqn_row


def reported_evaluation(trained: Any) -> dict[str, Any]:
    """The evaluation a run reports: its best-validated policy's, else its final model's."""
    return trained.evaluation if trained.best_evaluation is None else trained.best_evaluation


def _selection(evaluation: Mapping[str, Any]) -> str:
    if "validation" not in evaluation:
        return "final model"
    validation = evaluation["validation"]
    return (
        f"best-validated policy (step {validation['step']}, validation mean "
        f"{validation['mean_reward']:.2f} on reset seeds {validation['seed']}+)"
    )


def _figures(
    out: Path,
    table: Mapping[str, Any],
    reported: Mapping[str, Any],
    baseline_rows: Sequence[Mapping[str, Any]],
    trained: Sequence[Any],
    name: str,
) -> dict[str, Path]:
    from frontier_marl.evaluation.plots import plot_baselines
    from frontier_marl.training.callbacks import read_metrics
    from frontier_marl.training.plots import plot_action_comparison, plot_learning_curves
    from frontier_marl.training.validation import read_validation_log

    dqn = table["rows"][0]
    setting, training = table["setting"], table["training"]
    seeds = training["seeds"]
    where = (
        f"{setting['preset']}, {setting['map_mode']} map, {setting['episodes']} "
        f"episodes; DQN {training['steps']} steps, seed{'s' if len(seeds) > 1 else ''} "
        f"{', '.join(map(str, seeds))}"
    )
    model_row = {
        **reported,
        "policy": dqn["policy"],
        "thesis_mean": dqn["thesis_mean"],
        "thesis_std": dqn["thesis_std"],
    }
    files = {
        "rewards_figure": out / "comparison_rewards.png",
        "actions_figure": out / "comparison_actions.png",
        "learning_curve": out / "learning_curve.png",
    }
    seed_rows = []
    if len(seeds) > 1:
        seed_rows = [
            {**reported_evaluation(t)["model"], "policy": f"DQN seed {seed}"}
            for seed, t in zip(seeds, trained, strict=True)
        ]
    plot_baselines(
        [model_row, *seed_rows, *baseline_rows],
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
    reference = {}
    if dqn["thesis_mean"] is not None:
        reference[f"thesis DQN, evaluation ({dqn['thesis_mean']:.2f})"] = dqn["thesis_mean"]
    greedy = next((r for r in table["rows"] if r["policy"] == "greedy-distance"), None)
    if greedy is not None:
        reference[f"greedy-distance, ours ({greedy['mean_reward']:.2f})"] = greedy["mean_reward"]
    plot_learning_curves(
        [
            (
                f"seed {seed}",
                read_metrics(t.run_dir / "metrics.jsonl"),
                read_validation_log(t.run_dir),
            )
            for seed, t in zip(seeds, trained, strict=True)
        ],
        files["learning_curve"],
        title=f"{name} ({where})",
        reference=reference,
    )
    return files
