"""The benchmark's statistics, table and figure (see :mod:`frontier_marl.evaluation.benchmark.run`).

Per family and policy (one row):

* ``success``: episodes that reached 99 % of the reachable free cells before the limit;
* ``t99_mean``/``t99_std`` and ``t90_mean``/``t90_std``: cells travelled (a team: all robots'
  cells summed) until 99 % / 90 % coverage, mean and population std over the episodes that
  reached the level; ``t99_partial`` flags a mean over fewer than all episodes (a failed
  episode has no T99: it counts as a failure, never as a number);
* ``makespan99_mean``/``std``: the longest single robot path when the team first reached 99 %
  (T99 itself for one robot); ``overlap_mean``/``std``: area sensed more than once relative
  to the area known (0 for one robot);
* the paired relative difference to the family's best heuristic (:func:`paired_difference`):
  per episode ``(T99_policy - T99_best) / T99_best``, averaged over the episodes both reached
  99 %, with a 95 % Student-t confidence interval over those per-episode values. The best
  heuristic of a family is the heuristic with the most successes, then the lowest T99 mean.
* teams also get the same comparison for the makespan to 99 % (``best_heuristic_makespan``,
  the heuristic with the most successes, then the lowest makespan mean, and
  ``makespan_vs_best``): the team target of docs/beyond-the-thesis.md.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from frontier_marl.evaluation.metrics import mean_std
from frontier_marl.evaluation.plots import _pyplot
from frontier_marl.evaluation.records import EvaluationResult, level_key


def paired_difference(
    values: Sequence[float | None], baseline: Sequence[float | None], confidence: float = 0.95
) -> dict[str, Any]:
    """Mean per-episode relative difference ``(v - b) / b`` over the episodes where both
    values exist, and its Student-t confidence interval (sample std, ``n - 1`` degrees of
    freedom; no interval from fewer than two pairs). A pair whose baseline is 0 (a map seen
    whole at reset: T99 = 0) has no relative difference: it is left out and counted in
    ``undefined``."""
    if len(values) != len(baseline):
        raise ValueError(
            f"values and baseline must pair up episode by episode, got {len(values)} and "
            f"{len(baseline)}"
        )
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")
    both = [
        (float(v), float(b))
        for v, b in zip(values, baseline, strict=True)
        if v is not None and b is not None
    ]
    if any(b < 0 for _, b in both):
        raise ValueError("baseline values must be >= 0 for a relative difference")
    pairs = [(v, b) for v, b in both if b > 0]
    diffs = np.array([(v - b) / b for v, b in pairs])
    out: dict[str, Any] = {
        "pairs": len(diffs),
        "undefined": len(both) - len(pairs),
        "mean": None,
        "ci_low": None,
        "ci_high": None,
    }
    if len(diffs) == 0:
        return out
    mean = float(diffs.mean())
    out["mean"] = mean
    if len(diffs) > 1:
        from scipy.stats import t

        half = (
            float(t.ppf(0.5 + confidence / 2, len(diffs) - 1))
            * float(diffs.std(ddof=1))
            / math.sqrt(len(diffs))
        )
        out["ci_low"], out["ci_high"] = mean - half, mean + half
    return out


def _level(result: EvaluationResult, level: float, team: bool = False) -> list[float | None]:
    key = level_key(level)
    if team:
        return [e.makespan_to_coverage.get(key) for e in result.episodes]
    return [e.cells_to_coverage.get(key) for e in result.episodes]


def _stats(values: Sequence[float | None]) -> tuple[float | None, float | None]:
    reached = [v for v in values if v is not None]
    if not reached:
        return None, None
    return mean_std(reached)


def summary_row(result: EvaluationResult) -> dict[str, Any]:
    """One benchmark row (the fields of the module docstring, without the comparison) plus
    the per-episode records (without their per-step curves and action counts)."""
    t99 = _level(result, 0.99)
    t90 = _level(result, 0.90)
    team = result.n_agents > 1
    span99 = _level(result, 0.99, team=True) if team else t99
    overlaps = [0.0 if e.overlap is None else e.overlap for e in result.episodes]
    success = sum(v is not None for v in t99)
    t99_mean, t99_std = _stats(t99)
    t90_mean, t90_std = _stats(t90)
    span_mean, span_std = _stats(span99)
    overlap_mean, overlap_std = mean_std(overlaps)
    extra = dict(result.extra)
    episode_maps = extra.pop("episode_maps", [None] * len(result.episodes))
    per_episode = []
    for record, name in zip(result.episodes, episode_maps, strict=True):
        entry = record.to_dict(curve=False)
        del entry["action_counts"]  # one count per slot: 256 numbers for a heuristic
        entry["t99"] = record.cells_to_coverage.get(level_key(0.99))
        entry["t90"] = record.cells_to_coverage.get(level_key(0.90))
        entry["makespan99"] = (
            record.makespan_to_coverage.get(level_key(0.99)) if team else entry["t99"]
        )
        if name is not None:
            entry["map"] = name
        per_episode.append(entry)
    return {
        "policy": result.policy,
        "family": extra.pop("family", None),
        "agents": result.n_agents,
        "episodes": len(result.episodes),
        "success": success,
        "success_rate": success / len(result.episodes),
        "t99_mean": t99_mean,
        "t99_std": t99_std,
        "t99_partial": success < len(result.episodes),
        "t90_mean": t90_mean,
        "t90_std": t90_std,
        "makespan99_mean": span_mean,
        "makespan99_std": span_std,
        "overlap_mean": overlap_mean,
        "overlap_std": overlap_std,
        "n_slots": result.n_slots,
        "seeds": [e.seed for e in result.episodes],
        "end_reasons": result.end_reasons,
        **extra,
        "config": result.config,
        "per_episode": per_episode,
    }


def best_heuristic(
    rows: Sequence[Mapping[str, Any]], metric: str = "t99"
) -> Mapping[str, Any] | None:
    """The heuristic row with the most successes, then the lowest ``metric`` mean (``t99`` or
    ``makespan99``; None if no heuristic row reached 99 % at all)."""
    ranked = [r for r in rows if r.get("heuristic") and r[f"{metric}_mean"] is not None]
    if not ranked:
        return None
    return min(ranked, key=lambda r: (-r["success"], r[f"{metric}_mean"]))


#: metric -> (best row key, difference key) of :func:`compare`
COMPARISONS = {
    "t99": ("best_heuristic", "vs_best"),
    "makespan99": ("best_heuristic_makespan", "makespan_vs_best"),
}


def compare(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Add to every row ``best_heuristic`` (of its family) and ``vs_best``: the paired relative
    T99 difference to it (:func:`paired_difference`); for teams also ``best_heuristic_makespan``
    and ``makespan_vs_best``, the same for the makespan to 99 %. Returns the rows."""
    for name in dict.fromkeys(r["family"] for r in rows):
        family_rows = [r for r in rows if r["family"] == name]
        metrics = ["t99", "makespan99"] if family_rows[0]["agents"] > 1 else ["t99"]
        for metric in metrics:
            best_key, diff_key = COMPARISONS[metric]
            best = best_heuristic(family_rows, metric)
            for row in family_rows:
                row[best_key] = None if best is None else best["policy"]
                row[diff_key] = (
                    None
                    if best is None
                    else paired_difference(
                        [e[metric] for e in row["per_episode"]],
                        [e[metric] for e in best["per_episode"]],
                    )
                )
    return rows


def _mean_std(mean: float | None, std: float | None, digits: int = 1) -> str:
    return "—" if mean is None else f"{mean:.{digits}f} ± {std:.{digits}f}"


def _versus(row: Mapping[str, Any], metric: str = "t99") -> str:
    best_key, diff_key = COMPARISONS[metric]
    diff = row.get(diff_key)
    if row.get(best_key) == row["policy"]:
        return "best"
    if diff and diff["mean"] is None and diff.get("undefined"):
        return f"undefined (best T99 = 0 in {diff['undefined']})"
    if not diff or diff["mean"] is None:
        return "—"
    text = f"{diff['mean']:+.1%}"
    if diff["ci_low"] is not None:
        text += f" [{diff['ci_low']:+.1%}, {diff['ci_high']:+.1%}]"
    notes = [f"{diff['pairs']} pairs"] if diff["pairs"] < row["episodes"] else []
    if diff.get("undefined"):
        notes.append(f"{diff['undefined']} undefined: best T99 = 0")
    return text + (f" ({', '.join(notes)})" if notes else "")


def format_table(rows: Sequence[Mapping[str, Any]], markdown: bool = False) -> str:
    """The rows as a plain-text (or Markdown) table; a T99 over fewer than all episodes is
    marked with ``*``."""
    team = any(r["agents"] > 1 for r in rows)
    header = ["family", "policy", "success", "T99", "T90", "T99 vs best [95 % CI]"]
    if team:
        header += ["makespan→99 %", "makespan vs best [95 % CI]", "overlap"]
    lines = [header]
    for r in rows:
        t99 = _mean_std(r["t99_mean"], r["t99_std"]) + ("*" if r["t99_partial"] else "")
        line = [
            r["family"],
            r["policy"],
            f"{r['success']}/{r['episodes']}",
            t99,
            _mean_std(r["t90_mean"], r["t90_std"]),
            _versus(r),
        ]
        if team:
            line += [
                _mean_std(r["makespan99_mean"], r["makespan99_std"]),
                _versus(r, "makespan99"),
                _mean_std(r["overlap_mean"], r["overlap_std"], 3),
            ]
        lines.append(line)
    if markdown:
        out = ["| " + " | ".join(lines[0]) + " |", "|" + "---|" * len(header)]
        out += ["| " + " | ".join(line) + " |" for line in lines[1:]]
        return "\n".join(out)
    widths = [max(len(line[i]) for line in lines) for i in range(len(header))]
    text = []
    for k, line in enumerate(lines):
        text.append("  ".join(c.ljust(w) for c, w in zip(line, widths, strict=True)).rstrip())
        if k == 0:
            text.append("  ".join("-" * w for w in widths))
    return "\n".join(text)


def plot_benchmark(
    rows: Sequence[Mapping[str, Any]], path: str | os.PathLike[str], title: str | None = None
) -> None:
    """A PNG with one panel per family: T99 mean per policy with std error bars, the success
    count above each bar (hatched where some episodes failed: the mean is over the
    successful ones), the family's best heuristic in green."""
    if not rows:
        raise ValueError("rows must not be empty")
    plt = _pyplot()
    families = list(dict.fromkeys(r["family"] for r in rows))
    fig, axes = plt.subplots(
        1, len(families), figsize=(3.2 + 2.6 * len(families), 4.2), squeeze=False
    )
    for ax, name in zip(axes[0], families, strict=True):
        chosen = [r for r in rows if r["family"] == name]
        x = np.arange(len(chosen))
        means = [np.nan if r["t99_mean"] is None else r["t99_mean"] for r in chosen]
        stds = [0.0 if r["t99_std"] is None else r["t99_std"] for r in chosen]
        bars = ax.bar(x, means, yerr=stds, capsize=4, color="tab:blue", alpha=0.8)
        for bar, row in zip(bars, chosen, strict=True):
            if row["t99_partial"]:
                bar.set_hatch("//")
            if row.get("best_heuristic") == row["policy"]:
                bar.set_color("tab:green")
            top = 0.0 if row["t99_mean"] is None else row["t99_mean"] + (row["t99_std"] or 0)
            label = f"{row['success']}/{row['episodes']}"
            ax.annotate(label, (bar.get_x() + bar.get_width() / 2, top), ha="center", fontsize=7)
        ax.set_xticks(x, [r["policy"] for r in chosen], rotation=35, ha="right", fontsize=8)
        ax.set_title(f"{name} ({chosen[0]['episodes']} episodes)", fontsize=9)
        ax.set_ylabel("T99: cells travelled to 99 %")
    if title:
        fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
