"""Matplotlib figures of evaluation results (imported lazily by the commands).

Figures are drawn from result rows, i.e. the dicts of
:meth:`frontier_marl.evaluation.EvaluationResult.to_dict` (with curves), so a saved JSON file
can be re-plotted without rerunning anything.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from frontier_marl.evaluation.metrics import mean_curve


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def plot_baselines(
    rows: Sequence[Mapping[str, Any]],
    path: str | os.PathLike[str],
    title: str | None = None,
) -> None:
    """Write a two-panel PNG: mean total reward per policy with std error bars (and the
    thesis's figure beside it where the row has ``thesis_mean``), and coverage versus cells
    travelled (mean over episodes, with a +- std band). Team rows (``n_agents > 1``) add a
    third panel: coverage versus the longest single robot path (coverage versus time)."""
    if not rows:
        raise ValueError("rows must not be empty")
    plt = _pyplot()
    team = any(int(row.get("n_agents", 1)) > 1 for row in rows)
    fig, axes = plt.subplots(1, 3 if team else 2, figsize=(16 if team else 11, 4.2))
    bars, curves = axes[0], axes[1]
    try:
        names = [str(row["policy"]) for row in rows]
        colours = [f"C{i}" for i in range(len(rows))]
        _reward_panel(bars, rows, names, colours)
        _coverage_panel(curves, rows, "curve", colours, names)
        curves.set_xlabel("cells travelled (team total)")
        curves.set_title("coverage vs travel (mean ± std over episodes)", fontsize=9)
        if team:
            _coverage_panel(axes[2], rows, "makespan_curve", colours)
            axes[2].set_xlabel("longest single robot path (cells) = time")
            axes[2].set_title("coverage vs time (mean ± std over episodes)", fontsize=9)
        if title:
            fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        fig.savefig(os.fspath(path), dpi=110)
    finally:
        plt.close(fig)


def _reward_panel(
    bars: Any, rows: Sequence[Mapping[str, Any]], names: list[str], colours: list[str]
) -> None:
    """Mean total reward per policy (± std), the thesis's figure beside it where known, and
    each bar's count of episodes that reached the threshold."""
    x = np.arange(len(rows))
    means = [float(row["mean_reward"]) for row in rows]
    stds = [float(row["std_reward"]) for row in rows]
    has_thesis = any(row.get("thesis_mean") is not None for row in rows)
    width = 0.38 if has_thesis else 0.6
    offset = width / 2 if has_thesis else 0.0
    bars.bar(x - offset, means, width, yerr=stds, capsize=4, color=colours, label="ours")
    if has_thesis:
        _thesis_bars(bars, rows, width, offset)
    for i, row in enumerate(rows):
        bars.annotate(
            f"{row['terminations']}/{row['episodes']}",
            (i - offset, 0.0),
            textcoords="offset points",
            xytext=(0, 3 if means[i] >= 0 else -3),
            ha="center",
            va="bottom" if means[i] >= 0 else "top",
            fontsize=7,
            color="white" if abs(means[i]) > 1.0 else "black",
        )
    bars.set_xticks(x, names, rotation=15)
    bars.set_ylabel("total episode reward (mean ± std)")
    bars.axhline(0.0, color="0.5", linewidth=0.8)
    bars.set_title("total reward (in bar: episodes reaching the threshold)", fontsize=9)


def _thesis_bars(bars: Any, rows: Sequence[Mapping[str, Any]], width: float, offset: float) -> None:
    known = [i for i, row in enumerate(rows) if row.get("thesis_mean") is not None]
    t_x = [i + offset for i in known]
    t_mean = [float(rows[i]["thesis_mean"]) for i in known]
    t_std = [float(rows[i].get("thesis_std") or 0.0) for i in known]
    bars.bar(
        t_x,
        t_mean,
        width,
        yerr=t_std,
        capsize=4,
        color="0.75",
        edgecolor="0.3",
        hatch="//",
        label="thesis",
    )
    bars.legend(loc="best", fontsize=8)


def _episode_curves(row: Mapping[str, Any], key: str) -> list[np.ndarray]:
    """The per-episode curves ``key`` of a row (``curve`` for one robot, whose longest path is
    its only path)."""
    curves = []
    for episode in row.get("per_episode", []):
        points = episode.get(key) or episode.get("curve")
        if points:
            curves.append(np.asarray(points, dtype=float))
    return curves


def _coverage_panel(
    axis: Any,
    rows: Sequence[Mapping[str, Any]],
    key: str,
    colours: Sequence[str],
    labels: Sequence[str] | None = None,
) -> None:
    for i, row in enumerate(rows):
        episode_curves = _episode_curves(row, key)
        if not episode_curves:
            continue
        grid, mean, std = mean_curve(episode_curves)
        axis.plot(
            grid, mean, color=colours[i], label=str(row["policy"]) if labels is None else labels[i]
        )
        axis.fill_between(
            grid,
            np.clip(mean - std, 0, 1),
            np.clip(mean + std, 0, 1),
            color=colours[i],
            alpha=0.15,
            linewidth=0,
        )
    for level in (0.90, 0.99):
        axis.axhline(level, color="0.6", linestyle=":", linewidth=0.8)
    axis.set_ylabel("coverage of the reachable free region")
    axis.set_ylim(0.0, 1.02)
    if axis.lines:
        axis.legend(loc="lower right", fontsize=8)


def team_value(row: Mapping[str, Any], metric: str) -> tuple[float | None, float | None]:
    """Mean and std of a team metric of a result row, for one robot too.

    ``metric``: ``makespan``, ``overlap``, ``makespan@LEVEL`` or ``cells@LEVEL`` (LEVEL a key
    such as ``0.90``). One robot's makespan is its path and its overlap is 0.
    """
    single = int(row.get("n_agents", 1)) == 1
    if metric == "makespan":
        if single:
            return row["mean_travelled"], row["std_travelled"]
        return row["mean_makespan"], row["std_makespan"]
    if metric == "overlap":
        return (0.0, 0.0) if single else (row.get("mean_overlap"), row.get("std_overlap"))
    kind, _, level = metric.partition("@")
    if kind not in ("makespan", "cells") or not level:
        raise ValueError(f"unknown team metric {metric!r}")
    table = "cells_to_coverage" if kind == "cells" or single else "makespan_to_coverage"
    entry = row[table][level]
    return entry["mean"], entry["std"]


TEAM_METRICS: dict[str, str] = {
    "makespan@0.90": "makespan to 90 % (cells)",
    "makespan@0.99": "makespan to 99 % (cells)",
    "cells@0.90": "team cells travelled to 90 %",
    "cells@0.99": "team cells travelled to 99 %",
    "overlap": "overlap ratio (end of episode)",
}


def plot_team_comparison(
    rows: Sequence[Mapping[str, Any]],
    path: str | os.PathLike[str],
    title: str | None = None,
    metrics: Mapping[str, str] = TEAM_METRICS,
) -> None:
    """Grouped bars (x: team size, one bar per policy, std error bars) for each team metric
    (see :func:`team_value`), and below them coverage versus time for each team size."""
    if not rows:
        raise ValueError("rows must not be empty")
    plt = _pyplot()
    policies = list(dict.fromkeys(str(row["policy"]) for row in rows))
    sizes = sorted({int(row.get("n_agents", 1)) for row in rows})
    colour = {name: f"C{i}" for i, name in enumerate(policies)}
    columns = max(len(metrics), len(sizes))
    fig, axes = plt.subplots(2, columns, figsize=(3.4 * columns, 7.2), squeeze=False)
    try:
        width = 0.8 / len(policies)
        for axis, (metric, label) in zip(axes[0], metrics.items(), strict=False):
            for k, name in enumerate(policies):
                xs, means, stds = [], [], []
                for i, size in enumerate(sizes):
                    match = [
                        r for r in rows if r["policy"] == name and int(r.get("n_agents", 1)) == size
                    ]
                    if not match:
                        continue
                    mean, std = team_value(match[0], metric)
                    if mean is None:
                        continue
                    xs.append(i + (k - (len(policies) - 1) / 2) * width)
                    means.append(mean)
                    stds.append(std or 0.0)
                axis.bar(xs, means, width, yerr=stds, capsize=3, color=colour[name], label=name)
            axis.set_xticks(range(len(sizes)), [f"{n} robot{'s' if n > 1 else ''}" for n in sizes])
            axis.set_title(label, fontsize=9)
        axes[0][0].legend(fontsize=7, loc="best")
        for axis in axes[0][len(metrics) :]:
            axis.axis("off")
        for axis, size in zip(axes[1], sizes, strict=False):
            chosen = [r for r in rows if int(r.get("n_agents", 1)) == size]
            _coverage_panel(
                axis, chosen, "makespan_curve", [colour[str(r["policy"])] for r in chosen]
            )
            axis.set_xlabel("longest single robot path (cells) = time")
            axis.set_title(f"coverage vs time, {size} robot{'s' if size > 1 else ''}", fontsize=9)
        for axis in axes[1][len(sizes) :]:
            axis.axis("off")
        if title:
            fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        fig.savefig(os.fspath(path), dpi=110)
    finally:
        plt.close(fig)
