"""A training run folder as one small JSON summary: what a doc may cite, without the artefacts.

    python training/summarize_runs.py runs/config01/seed0 --out training/results
    python training/summarize_runs.py runs/reproduce/config01_seed* --out training/results/x

Writes ``OUT/<run folder name>.json`` with the experiment (config), every training session
(steps, wall and CPU time, the machine when the run recorded it, else ``--machine``), the
library versions, the protocol evaluation rows of the final model and of the best-validated
policy (per-episode records, without per-step coverage curves), the validation scores, other
small JSON tables of the folder (such as ``evaluate_checkpoints.py``'s), and the learning curve
as window statistics (``--window`` steps: count, mean and max of the TD loss,
mean episode reward and exploration rate), from which the docs' TD-loss figures are computed.
Model zips, replay buffers, checkpoints, TensorBoard files, metrics logs and plots stay out.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from frontier_marl.experiments.baselines import without_curves
from frontier_marl.training.callbacks import read_metrics
from frontier_marl.utils.json_files import write_json


def strip_curves(row: dict[str, Any]) -> dict[str, Any]:
    """An evaluation row without its resolved env config and per-step curves."""
    return {k: v for k, v in without_curves(row).items() if k != "config"}


def evaluation_summary(path: Path) -> dict[str, Any] | None:
    """The rows of an ``evaluation.json`` (None if absent)."""
    if not path.is_file():
        return None
    data = json.loads(path.read_text())
    keep = ("num_timesteps", "episodes", "seed", "deterministic", "validation", "experiment")
    return {
        **{k: data[k] for k in keep if k in data},
        "rows": [strip_curves(row) for row in data.get("rows", [])],
    }


def windows(metrics: Iterable[dict[str, Any]], size: int) -> list[dict[str, Any]]:
    """Window statistics of the logged TD loss, episode reward and exploration rate."""
    keys = {
        "td_loss": "train/loss",
        "episode_reward": "rollout/ep_rew_mean",
        "exploration_rate": "rollout/exploration_rate",
    }
    groups: dict[int, dict[str, list[float]]] = {}
    for entry in metrics:
        group = groups.setdefault(int(entry["step"]) // size, {name: [] for name in keys})
        for name, key in keys.items():
            value = entry.get(key)
            if isinstance(value, int | float) and math.isfinite(value):
                group[name].append(float(value))
    out = []
    for index in sorted(groups):
        row: dict[str, Any] = {"start": index * size, "end": (index + 1) * size}
        for name, values in groups[index].items():
            row[f"{name}_count"] = len(values)
            row[f"{name}_mean"] = sum(values) / len(values) if values else None
        losses = groups[index]["td_loss"]
        row["td_loss_max"] = max(losses) if losses else None
        out.append(row)
    return out


def read_json_lines(path: Path) -> list[dict[str, Any]]:
    if not path.is_file():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def summarize(run_dir: Path, machine: str | None, window: int) -> dict[str, Any]:
    """The summary of one run folder (see the module docstring)."""
    run = json.loads((run_dir / "run.json").read_text()) if (run_dir / "run.json").is_file() else {}
    meta_path = run_dir / "model.json"
    meta = json.loads(meta_path.read_text()) if meta_path.is_file() else {}
    sessions = run.get("sessions", [])
    recorded = {s.get("machine") for s in sessions if s.get("machine")}
    metrics_path = run_dir / "metrics.jsonl"
    summary: dict[str, Any] = {
        "run": run_dir.name,
        "experiment": run.get("experiment", meta.get("experiment")),
        "num_timesteps": meta.get("num_timesteps"),
        "sessions": sessions,
        "wall_time_s": round(sum(s.get("wall_time_s", 0.0) for s in sessions), 3),
        "machine": ", ".join(sorted(recorded)) if recorded else machine,
        "versions": meta.get("versions"),
        "evaluation": evaluation_summary(run_dir / "evaluation.json"),
        "best": evaluation_summary(run_dir / "best" / "evaluation.json"),
        "validation": read_json_lines(run_dir / "validation.jsonl"),
        "learning_curve": {
            "window": window,
            "windows": windows(read_metrics(metrics_path), window)
            if metrics_path.is_file()
            else [],
        },
    }
    for folder, prefix in ((run_dir, ""), (run_dir / "best", "best_")):
        for extra in sorted(folder.glob("evaluation_*.json")):  # e.g. a static-map evaluation
            summary[prefix + extra.stem] = evaluation_summary(extra)
    for extra in sorted(run_dir.glob("*.json")):  # e.g. evaluate_checkpoints.py's table
        if extra.name not in ("run.json", "model.json") and not extra.name.startswith("eval"):
            summary[extra.stem] = json.loads(extra.read_text())
    return summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path, help="run folders (with run.json)")
    parser.add_argument("--out", type=Path, required=True, help="folder of the summaries")
    parser.add_argument("--machine", default=None, help="the machine, if the run did not record it")
    parser.add_argument("--window", type=int, default=50_000, help="learning-curve window (steps)")
    args = parser.parse_args(argv)
    for run_dir in args.runs:
        if not (run_dir / "run.json").is_file() and not (run_dir / "evaluation.json").is_file():
            parser.error(f"{run_dir} is not a training run folder (no run.json)")
        summary = summarize(run_dir, args.machine, args.window)
        path = write_json(summary, args.out / f"{run_dir.name}.json")
        print(f"wrote {path} ({path.stat().st_size / 1024:.0f} kB)")
    return 0
