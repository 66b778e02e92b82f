"""The tables of the multi-robot experiment (:mod:`frontier_marl.experiments.multi_robot`): team
metrics per row, how the episodes ended, and the paired comparison of each coordinated policy
with independent greedy distance on the same episodes."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from frontier_marl.evaluation.plots import team_value

BASELINE = "greedy-distance"


def endings_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """Markdown table: final coverage and end reasons of every row."""
    lines = [
        "| map | robots | policy | final coverage | end reasons |",
        "|---|---|---|---|---|",
    ]
    for row in rows:
        reasons = ", ".join(f"{k} {v}" for k, v in sorted(row["end_reasons"].items()))
        lines.append(
            f"| {row['setting']} | {row['n_agents']} | {row['policy']} "
            f"| {row['mean_final_coverage']:.3f} | {reasons} |"
        )
    return "\n".join(lines)


def _cell(row: Mapping[str, Any], metric: str, digits: int = 1) -> str:
    mean, std = team_value(row, metric)
    if mean is None:
        return "—"
    kind, _, level = metric.partition("@")
    reached = ""
    if level:
        table = (
            "cells_to_coverage"
            if kind == "cells" or row["n_agents"] == 1
            else ("makespan_to_coverage")
        )
        entry = row[table][level]
        if entry["reached"] < row["episodes"]:
            reached = f" ({entry['reached']}/{row['episodes']})"
    return f"{mean:.{digits}f} ± {std:.{digits}f}{reached}"


def results_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """Markdown table: every row's team metrics (mean ± std over episodes)."""
    lines = [
        "| map | robots | policy | team cells → 90 % | team cells → 99 % | makespan → 90 % "
        "| makespan → 99 % | overlap | decisions |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        lines.append(
            f"| {row['setting']} | {row['n_agents']} | {row['policy']} "
            f"| {_cell(row, 'cells@0.90')} | {_cell(row, 'cells@0.99')} "
            f"| {_cell(row, 'makespan@0.90')} | {_cell(row, 'makespan@0.99')} "
            f"| {_cell(row, 'overlap', 3)} | {row['mean_steps']:.1f} |"
        )
    return "\n".join(lines)


def _per_episode(row: Mapping[str, Any], metric: str) -> np.ndarray:
    """Per-episode values of a team metric (NaN where a level was not reached)."""
    episodes = row["per_episode"]
    single = row["n_agents"] == 1
    if metric == "overlap":
        values = [0.0 if single else e["overlap"] for e in episodes]
    else:
        kind, _, level = metric.partition("@")
        table = "cells_to_coverage" if kind == "cells" or single else "makespan_to_coverage"
        values = [e[table][level] for e in episodes]
    return np.array([np.nan if v is None else float(v) for v in values])


COMPARED = {
    "overlap": "overlap",
    "makespan@0.90": "makespan → 90 %",
    "makespan@0.99": "makespan → 99 %",
    "cells@0.99": "team cells → 99 %",
}


def _paired(ours: np.ndarray, theirs: np.ndarray) -> dict[str, Any]:
    """One metric against the baseline on the episodes where both have a value: the means,
    the relative change with its 95 % half-width, and wins/ties/losses."""
    both = ~np.isnan(ours) & ~np.isnan(theirs)
    if not both.any():  # e.g. a policy that never reached the level
        paired: dict[str, Any] = {"mean": None, "baseline_mean": None, "episodes": 0}
        paired.update(change=None, ci95=None, wins=0, ties=0, losses=0)
        return paired
    mean_ours, mean_theirs = float(ours[both].mean()), float(theirs[both].mean())
    diff = ours[both] - theirs[both]
    half = 1.96 * float(diff.std(ddof=1)) / np.sqrt(len(diff)) if len(diff) > 1 else None
    return {
        "mean": mean_ours,
        "baseline_mean": mean_theirs,
        "episodes": int(both.sum()),
        "change": (mean_ours - mean_theirs) / mean_theirs if mean_theirs else None,
        "ci95": half / mean_theirs if half is not None and mean_theirs else None,
        "wins": int(np.sum(ours[both] < theirs[both])),
        "ties": int(np.sum(ours[both] == theirs[both])),
        "losses": int(np.sum(ours[both] > theirs[both])),
    }


def comparison(rows: Sequence[Mapping[str, Any]], baseline: str = BASELINE) -> list[dict]:
    """Each coordinated policy against ``baseline`` on the same episodes, per setting and team
    size > 1: relative change of the mean (negative = better) with the half-width of its 95 %
    confidence interval (normal approximation of the paired per-episode differences), and
    paired wins/ties/losses."""
    out = []
    for row in rows:
        if row["policy"] == baseline or row["n_agents"] == 1:
            continue
        base = next(
            r
            for r in rows
            if r["policy"] == baseline
            and r["setting"] == row["setting"]
            and r["n_agents"] == row["n_agents"]
        )
        entry: dict[str, Any] = {
            "setting": row["setting"],
            "n_agents": row["n_agents"],
            "policy": row["policy"],
        }
        for metric in COMPARED:
            entry[metric] = _paired(_per_episode(row, metric), _per_episode(base, metric))
        out.append(entry)
    return out


def comparison_table(entries: Sequence[Mapping[str, Any]]) -> str:
    header = "| map | robots | policy | " + " | ".join(COMPARED.values()) + " |"
    lines = [header, "|---|---|---|" + "---|" * len(COMPARED)]
    for e in entries:
        cells = []
        for metric in COMPARED:
            m = e[metric]
            if m["episodes"] == 0:
                cells.append("— (no paired episode)")
                continue
            change = "—" if m["change"] is None else f"{m['change']:+.1%}"
            if m["ci95"] is not None:
                change += f" ± {m['ci95']:.1%}"
            cells.append(f"{change} ({m['wins']}/{m['ties']}/{m['losses']})")
        lines.append(
            f"| {e['setting']} | {e['n_agents']} | {e['policy']} | " + " | ".join(cells) + " |"
        )
    return "\n".join(lines)


def without_curves(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The rows with the per-episode curves left out (the plots keep them)."""
    return [
        {
            **row,
            "per_episode": [
                {k: v for k, v in e.items() if k not in ("curve", "makespan_curve")}
                for e in row["per_episode"]
            ],
        }
        for row in rows
    ]
