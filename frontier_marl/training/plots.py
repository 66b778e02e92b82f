"""Figures of a training run: action histogram and learning curve (PNG, matplotlib Agg)."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from frontier_marl.evaluation.model_evaluation import DEGENERACY_THRESHOLD


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def plot_action_histogram(
    rows: Sequence[Mapping[str, Any]], path: str | os.PathLike[str], title: str | None = None
) -> None:
    """Grouped bars: share of each slot per policy row, with the degeneracy threshold."""
    if not rows:
        raise ValueError("rows must not be empty")
    plt = _pyplot()
    n_slots = max(len(row["action_shares"]) for row in rows)
    x = np.arange(n_slots)
    width = 0.8 / len(rows)
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    try:
        for i, row in enumerate(rows):
            shares = np.zeros(n_slots)
            shares[: len(row["action_shares"])] = row["action_shares"]
            offset = (i - (len(rows) - 1) / 2) * width
            label = f"{row['policy']} ({row['mean_reward']:.2f} ± {row['std_reward']:.2f})"
            ax.bar(x + offset, shares, width, label=label, color=f"C{i}")
        _finish_share_axes(ax, x, title or "actions chosen (deterministic evaluation)")
        fig.tight_layout()
        fig.savefig(os.fspath(path), dpi=110)
    finally:
        plt.close(fig)


def _finish_share_axes(ax: Any, x: np.ndarray, title: str) -> None:
    """Degeneracy line, slot ticks, labels and legend of an action-share bar chart."""
    ax.axhline(
        DEGENERACY_THRESHOLD,
        color="C3",
        linestyle="--",
        linewidth=1,
        label=f"degeneracy threshold ({DEGENERACY_THRESHOLD:.0%})",
    )
    ax.set_xticks(x, [f"slot {k}" for k in x])
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("share of decisions")
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title(title, fontsize=9)


def _series(rows: Sequence[Mapping[str, Any]], key: str) -> tuple[np.ndarray, np.ndarray]:
    pairs = [(row["step"], row[key]) for row in rows if key in row]
    if not pairs:
        return np.zeros(0), np.zeros(0)
    steps, values = zip(*pairs, strict=True)
    return np.asarray(steps, float), np.asarray(values, float)


def plot_learning_curve(
    metrics: Sequence[Mapping[str, Any]],
    path: str | os.PathLike[str],
    title: str | None = None,
    reference: Mapping[str, float] | None = None,
    validation: Sequence[Mapping[str, Any]] = (),
) -> None:
    """Three panels against training steps: mean episode reward (SB3's rolling
    ``rollout/ep_rew_mean``), TD loss (``train/loss``, log scale) and epsilon
    (``rollout/exploration_rate``). ``reference`` maps labels to horizontal reward lines;
    ``validation`` records (``step``, ``mean_reward``) add the greedy policy's scores."""
    plot_learning_curves([("", metrics, validation)], path, title, reference)


#: (label, metrics rows, validation records) of one run of :func:`plot_learning_curves`.
RunCurves = tuple[str, Sequence[Mapping[str, Any]], Sequence[Mapping[str, Any]]]


def _plot_run(axes: Sequence[Any], i: int, run: RunCurves) -> None:
    """One run's reward, validation, loss and epsilon curves, in colour ``C{i}``."""
    reward, loss, eps = axes
    label, metrics, validation = run
    colour = f"C{i}"
    prefix = f"{label}: " if label else ""
    steps, values = _series(metrics, "rollout/ep_rew_mean")
    reward.plot(steps, values, color=colour, label=f"{prefix}training episodes (epsilon-greedy)")
    steps, values = _series(validation, "mean_reward")
    if len(steps):
        reward.plot(
            steps,
            values,
            color=colour,
            marker=".",
            linewidth=0.6,
            linestyle="--",
            label=f"{prefix}greedy, validation",
        )
    steps, values = _series(metrics, "train/loss")
    loss.plot(steps, values, color=colour, linewidth=0.8, label=label or None)
    steps, values = _series(metrics, "rollout/exploration_rate")
    eps.plot(steps, values, color=colour)


def _finish_curve_axes(
    axes: Sequence[Any], runs: Sequence[RunCurves], reference: Mapping[str, float] | None
) -> None:
    """Reference lines, legends, scales, titles and labels of the three panels."""
    reward, loss, eps = axes
    styles = (":", "-.", (0, (5, 2)), (0, (1, 3)))
    for i, (label, value) in enumerate((reference or {}).items()):
        reward.axhline(
            value, color="0.25", linestyle=styles[i % len(styles)], linewidth=1, label=label
        )
    if reward.lines and (reference or len(runs) > 1 or any(v for _l, _m, v in runs)):
        reward.legend(fontsize=7, loc="lower right")
    reward.set_title("episode reward (rolling mean of 100)", fontsize=9)
    values = np.concatenate([_series(m, "train/loss")[1] for _l, m, _v in runs] or [[]])
    if len(values) and np.all(values > 0):
        loss.set_yscale("log")
    if len(runs) > 1:
        loss.legend(fontsize=7, loc="upper right")
    loss.set_title("TD loss (Huber)", fontsize=9)
    eps.set_ylim(0, 1.05)
    eps.set_title("epsilon", fontsize=9)
    for ax in axes:
        ax.set_xlabel("environment steps")
        if not ax.lines:
            ax.text(
                0.5,
                0.5,
                "no data yet",
                ha="center",
                va="center",
                transform=ax.transAxes,
                color="0.5",
            )


def plot_learning_curves(
    runs: Sequence[RunCurves],
    path: str | os.PathLike[str],
    title: str | None = None,
    reference: Mapping[str, float] | None = None,
) -> None:
    """:func:`plot_learning_curve` with several runs overlaid, one colour each: ``runs`` holds
    (label, metrics rows, validation records) per run, e.g. one per seed."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    try:
        for i, run in enumerate(runs):
            _plot_run(axes, i, run)
        _finish_curve_axes(axes, runs, reference)
        if title:
            fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        fig.savefig(os.fspath(path), dpi=110)
    finally:
        plt.close(fig)


def plot_action_comparison(
    shares: Sequence[float],
    reference: Sequence[float],
    path: str | os.PathLike[str],
    labels: tuple[str, str] = ("ours", "thesis"),
    title: str | None = None,
) -> None:
    """Two bars per slot: our action shares beside a reference (e.g. the thesis's), with the
    degeneracy threshold."""
    if not shares:
        raise ValueError("shares must not be empty")
    plt = _pyplot()
    n_slots = max(len(shares), len(reference))
    x = np.arange(n_slots)
    ours = np.zeros(n_slots)
    ours[: len(shares)] = shares
    ref = np.zeros(n_slots)
    ref[: len(reference)] = reference
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    try:
        width = 0.38
        ax.bar(x - width / 2, ours, width, color="C0", label=labels[0])
        ax.bar(
            x + width / 2, ref, width, color="0.75", edgecolor="0.3", hatch="//", label=labels[1]
        )
        for xs, values in ((x - width / 2, ours), (x + width / 2, ref)):
            for xi, value in zip(xs, values, strict=True):
                ax.text(xi, value + 0.01, f"{value:.1%}", ha="center", va="bottom", fontsize=7)
        _finish_share_axes(ax, x, title or "action shares")
        fig.tight_layout()
        fig.savefig(os.fspath(path), dpi=110)
    finally:
        plt.close(fig)


def plot_family_validation(
    records: Sequence[Mapping[str, Any]],
    path: str | os.PathLike[str],
    title: str | None = None,
    xlabel: str = "training steps",
) -> None:
    """T99 (a team: the makespan) relative to the reference heuristic on the validation
    episodes, per family and overall, against training steps (records of
    :class:`~frontier_marl.training.family_validation.FamilyValidator`); 0 is parity, below it
    the policy travels less."""
    rows = [r for r in records if "by_family" in r]
    if not rows:
        raise ValueError("no family validation records")
    plt = _pyplot()
    steps = np.array([r["step"] for r in rows], float)
    fig, ax = plt.subplots(figsize=(7.0, 3.8))
    try:
        for name in rows[0]["by_family"]:
            values = [100 * r["by_family"][name] for r in rows]
            ax.plot(steps, values, marker=".", linewidth=0.8, label=name)
        overall = [100 * r.get("vs_reference", r.get("t99_vs_nearest_path")) for r in rows]
        reference = rows[0].get("reference", "nearest-path")
        metric = "makespan" if rows[0].get("metric") == "makespan99" else "T99"
        ax.plot(steps, overall, color="black", linewidth=2.0, label="all families")
        ax.axhline(0.0, color="grey", linewidth=0.8)
        ax.axhline(-5.0, color="green", linewidth=0.8, linestyle="--", label="-5 % (target)")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"{metric} vs {reference} (%)")
        ax.set_title(title or f"validation: {metric} to 99 % coverage against {reference}")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(path, dpi=120)
    finally:
        plt.close(fig)
