"""The comparison table of ``frontier-marl reproduce``: the DQN beside the thesis's figures.

Rows pool the seeds' evaluations (the reported policies, then the final models), list each
seed, then the heuristics; :func:`genuine_checks` applies the acceptance bar (no dominant
action, several actions used, the pooled mean at least the thesis's mean minus one std) and
:func:`format_comparison_markdown` writes ``comparison.md``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from frontier_marl.config.thesis import CONFIG01_MIN_MEAN as MIN_MEAN
from frontier_marl.config.thesis import DQN_RESULTS
from frontier_marl.evaluation.metrics import action_shares, mean_std
from frontier_marl.evaluation.model_evaluation import degeneracy
from frontier_marl.experiments.results import format_shares, summary_row, training_wall_time

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


def _training_text(training: Mapping[str, Any]) -> tuple[str, str, str]:
    """The runs, their wall times and what the DQN rows report, as phrases."""
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
    return runs, walls, reports


def _after_table_lines(table: Mapping[str, Any]) -> list[str]:
    """The lines below the table: the seed spread (several seeds) and the checks."""
    training = table["training"]
    seeds = training["seeds"]
    lines: list[str] = []
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
    lines += ["", f"Checks of the DQN row (the bar for {training['thesis_steps']} steps):"]
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
    return lines


def format_comparison_markdown(table: Mapping[str, Any]) -> str:
    """The comparison as Markdown: setting, table, seed spread, acceptance checks."""
    setting, training = table["setting"], table["training"]
    runs, walls, reports = _training_text(training)
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
    lines += _after_table_lines(table)
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


def _dqn_rows(
    name: str, seeds: Sequence[int], trained: Sequence[Any], thesis_dqn: Mapping[str, Any] | None
) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """The DQN rows (pooled or single, each seed's, the final models under validation) and
    the evaluation row the first of them reports."""
    # With validation (train.validate_every) each run reports its best-validated policy,
    # chosen on held-out episodes, never the protocol's; the final models are shown below.
    reported = [reported_evaluation(t) for t in trained]
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
    if _validated(trained):
        label = f"DQN {name}, final model{'s' if several else ''}"
        final_row = pool_evaluations(finals, label) if several else finals[0]
        rows.append(comparison_row(final_row, "dqn", None, name=label))
    return rows, dqn_row


def _validated(trained: Sequence[Any]) -> bool:
    """Whether every run reports a best-validated policy."""
    return all(t.best_evaluation is not None for t in trained)


def _heuristic_rows(baseline_rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    rows = []
    for row in baseline_rows:
        thesis = None
        if row.get("thesis_mean") is not None:
            thesis = {"mean": row["thesis_mean"], "std": row["thesis_std"], "episodes": 30}
        rows.append(comparison_row(row, "heuristic", thesis))
    return rows


def _training_runs(seeds: Sequence[int], trained: Sequence[Any]) -> list[dict[str, Any]]:
    """One entry per run: its folder, steps, wall time, speed and reported policy."""
    runs = []
    for seed, t in zip(seeds, trained, strict=True):
        r = reported_evaluation(t)
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
    return runs


def _setting(experiment: Any) -> dict[str, Any]:
    """The evaluation setting: map, sensor, reward and episodes."""
    cfg = experiment.env_config()
    episodes = experiment.train.eval_episodes
    return {
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
    }


def _training(
    experiment: Any, seeds: Sequence[int], jobs: int, trained: Sequence[Any]
) -> dict[str, Any]:
    """The training: config, seeds, budget against the thesis's, and each run."""
    return {
        "config": experiment.name,
        "description": experiment.description,
        "reported_policy": (
            "best-validated policy (chosen on held-out episodes, never the protocol's)"
            if _validated(trained)
            else "final model"
        ),
        "seeds": list(seeds),
        "jobs": jobs,
        "steps": min(t.num_timesteps for t in trained),
        "thesis_steps": (DQN_RESULTS.get(experiment.name) or {}).get("steps", 1_000_000),
        "runs": _training_runs(seeds, trained),
        "source": experiment.source,
    }


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
    rows, dqn_row = _dqn_rows(name, seeds, trained, DQN_RESULTS.get(name))
    rows += _heuristic_rows(baseline_rows)
    models = [reported_evaluation(t)["model"] for t in trained]
    spread = seed_spread(seeds, models)
    training = _training(experiment, seeds, jobs, trained)
    table = {
        "title": f"Thesis comparison: {name} (DQN) and the heuristic baselines",
        "setting": _setting(experiment),
        "training": training,
        "summaries": [
            summary_row(
                reported_evaluation(t),
                config=name,
                seed=seed,
                steps=t.num_timesteps,
                wall_time_s=run["wall_time_s"],
                run_dir=t.run_dir,
            )
            for seed, t, run in zip(seeds, trained, training["runs"], strict=True)
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
