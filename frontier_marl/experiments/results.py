"""Result tables of training runs, shared by ``frontier-marl reproduce`` and ``campaign``.

One *summary row* per evaluated run: the experiment, seed and budget, the model's mean and std
total reward over the deterministic evaluation episodes, terminations, action shares, the
degeneracy flag, greedy-distance on the same episodes, and the training wall time. Rows come
from an evaluation dict in memory (:func:`summary_row`, what a Ray trial reports) or from a run
folder on disk (:func:`run_summary`, :func:`collect_runs`), and are written as Markdown, CSV
and JSON (:func:`write_table`).

A row of a configuration the thesis reports gets its figure (:data:`frontier_marl.config.thesis.
DQN_RESULTS`) beside ours (``thesis`` column).
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from frontier_marl.config.thesis import dqn_result_text
from frontier_marl.utils.json_files import write_json

#: Columns of a summary table, in order.
SUMMARY_COLUMNS: tuple[str, ...] = (
    "config",
    "seed",
    "steps",
    "mean_reward",
    "std_reward",
    "terminations",
    "episodes",
    "action_shares",
    "degenerate",
    "dominant_action",
    "dominant_share",
    "greedy_distance_mean",
    "thesis",
    "wall_time_s",
    "run_dir",
)


def summary_row(
    evaluation: Mapping[str, Any],
    *,
    config: str,
    seed: int,
    steps: int | None = None,
    wall_time_s: float | None = None,
    run_dir: str | Path | None = None,
) -> dict[str, Any]:
    """One table row from an evaluation dict (what
    :func:`~frontier_marl.evaluation.model_evaluation.evaluate_model` returns and a run folder's
    ``evaluation.json`` holds)."""
    model = evaluation["model"]
    deg = model.get("degeneracy") or {}
    greedy = next(
        (row for row in evaluation.get("heuristics", []) if row["policy"] == "greedy-distance"),
        None,
    )
    return {
        "config": config,
        "seed": int(seed),
        "steps": int(evaluation.get("num_timesteps", 0) if steps is None else steps),
        "mean_reward": float(model["mean_reward"]),
        "std_reward": float(model["std_reward"]),
        "terminations": int(model["terminations"]),
        "episodes": int(model["episodes"]),
        "action_shares": [float(s) for s in model["action_shares"]],
        "degenerate": bool(deg.get("degenerate", False)),
        "dominant_action": deg.get("dominant_action"),
        "dominant_share": deg.get("dominant_share"),
        "greedy_distance_mean": None if greedy is None else float(greedy["mean_reward"]),
        "thesis": dqn_result_text(config),
        "wall_time_s": None if wall_time_s is None else round(float(wall_time_s), 2),
        "run_dir": None if run_dir is None else str(run_dir),
    }


def training_wall_time(run_dir: str | Path) -> float | None:
    """Summed wall time of every training session recorded in ``RUN/run.json``."""
    path = Path(run_dir) / "run.json"
    if not path.is_file():
        return None
    sessions = json.loads(path.read_text()).get("sessions", [])
    return float(sum(s.get("wall_time_s") or 0.0 for s in sessions))


def run_summary(run_dir: str | Path) -> dict[str, Any]:
    """The summary row of a finished run folder (``evaluation.json`` + ``run.json``)."""
    run_dir = Path(run_dir)
    path = run_dir / "evaluation.json"
    if not path.is_file():
        raise ValueError(f"no evaluation.json in {str(run_dir)!r} (is the run finished?)")
    evaluation = json.loads(path.read_text())
    record_path = run_dir / "run.json"
    experiment = (
        json.loads(record_path.read_text()).get("experiment", {}) if (record_path.is_file()) else {}
    )
    config = evaluation.get("experiment") or experiment.get("name") or run_dir.name
    seed = experiment.get("train", {}).get("seed", 0)
    return summary_row(
        evaluation,
        config=config,
        seed=seed,
        wall_time_s=training_wall_time(run_dir),
        run_dir=run_dir,
    )


def collect_runs(root: str | Path) -> list[dict[str, Any]]:
    """Summary rows of every run folder under ``root`` (those with ``evaluation.json``),
    sorted by config, budget and seed."""
    rows = [run_summary(path.parent) for path in Path(root).rglob("evaluation.json")]
    return sort_rows(rows)


def sort_rows(rows: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    return sorted((dict(r) for r in rows), key=lambda r: (r["config"], r["steps"], r["seed"]))


# --------------------------------------------------------------------------- formatting


def format_shares(shares: Sequence[float] | None) -> str:
    """``[0.506, 0.254, ...]`` -> ``"50.6/25.4/... %"``."""
    if not shares:
        return "—"
    return "/".join(f"{100 * s:.1f}" for s in shares) + " %"


def format_cell(key: str, value: Any) -> str:
    """A table cell: numbers rounded, shares as percentages, booleans as yes/no."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "—"
    if key == "action_shares":
        return format_shares(value)
    if isinstance(value, bool):
        return "yes" if value else "no"
    if key == "dominant_share":
        return f"{100 * value:.1f} %"
    if isinstance(value, float):
        return f"{value:.1f}" if key.endswith("_s") else f"{value:.2f}"
    return str(value) if value != "" else "—"


def format_markdown(
    rows: Sequence[Mapping[str, Any]], columns: Sequence[str] = SUMMARY_COLUMNS
) -> str:
    """A Markdown (GitHub) table of ``rows``."""
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for row in rows:
        cells = [format_cell(key, row.get(key)).replace("|", "\\|") for key in columns]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_csv(
    rows: Sequence[Mapping[str, Any]], path: str | Path, columns: Sequence[str] = SUMMARY_COLUMNS
) -> Path:
    """CSV with one row per run; action shares as ``0.506;0.254;...``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(columns), extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            out = dict(row)
            if isinstance(out.get("action_shares"), list | tuple):
                out["action_shares"] = ";".join(f"{s:.4f}" for s in out["action_shares"])
            writer.writerow({k: "" if out.get(k) is None else out.get(k) for k in columns})
    return path


def write_table(
    rows: Sequence[Mapping[str, Any]],
    stem: str | Path,
    *,
    title: str | None = None,
    columns: Sequence[str] = SUMMARY_COLUMNS,
    extra: Mapping[str, Any] | None = None,
) -> dict[str, Path]:
    """``STEM.md``, ``STEM.csv`` and ``STEM.json`` (``{"rows": [...], **extra}``)."""
    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    md = stem.with_suffix(".md")
    header = f"# {title}\n\n" if title else ""
    md.write_text(header + format_markdown(rows, columns), encoding="utf-8")
    files = {"markdown": md, "csv": write_csv(rows, stem.with_suffix(".csv"), columns)}
    files["json"] = write_json({**(extra or {}), "rows": list(rows)}, stem.with_suffix(".json"))
    return files
