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

from frontier_marl.metrics import mean_curve


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
    travelled (mean over episodes, with a +- std band)."""
    if not rows:
        raise ValueError("rows must not be empty")
    plt = _pyplot()
    fig, (bars, curves) = plt.subplots(1, 2, figsize=(11, 4.2))
    try:
        names = [str(row["policy"]) for row in rows]
        x = np.arange(len(rows))
        means = [float(row["mean_reward"]) for row in rows]
        stds = [float(row["std_reward"]) for row in rows]
        has_thesis = any(row.get("thesis_mean") is not None for row in rows)
        width = 0.38 if has_thesis else 0.6
        offset = width / 2 if has_thesis else 0.0
        colours = [f"C{i}" for i in range(len(rows))]
        bars.bar(x - offset, means, width, yerr=stds, capsize=4, color=colours, label="ours")
        if has_thesis:
            known = [i for i, row in enumerate(rows) if row.get("thesis_mean") is not None]
            t_x = [i + offset for i in known]
            t_mean = [float(rows[i]["thesis_mean"]) for i in known]
            t_std = [float(rows[i].get("thesis_std") or 0.0) for i in known]
            bars.bar(t_x, t_mean, width, yerr=t_std, capsize=4, color="0.75",
                     edgecolor="0.3", hatch="//", label="thesis")
            bars.legend(loc="best", fontsize=8)
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

        for i, row in enumerate(rows):
            episode_curves = [
                np.asarray(ep["curve"], dtype=float)
                for ep in row.get("per_episode", [])
                if ep.get("curve")
            ]
            if not episode_curves:
                continue
            grid, mean, std = mean_curve(episode_curves)
            curves.plot(grid, mean, color=colours[i], label=names[i])
            curves.fill_between(
                grid, np.clip(mean - std, 0, 1), np.clip(mean + std, 0, 1),
                color=colours[i], alpha=0.18, linewidth=0,
            )
        for level in (0.90, 0.99):
            curves.axhline(level, color="0.6", linestyle=":", linewidth=0.8)
        curves.set_xlabel("cells travelled (team total)")
        curves.set_ylabel("coverage of the reachable free region")
        curves.set_ylim(0.0, 1.02)
        curves.set_title("coverage vs travel (mean ± std over episodes)", fontsize=9)
        if curves.lines:
            curves.legend(loc="lower right", fontsize=8)
        if title:
            fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        fig.savefig(os.fspath(path), dpi=110)
    finally:
        plt.close(fig)
