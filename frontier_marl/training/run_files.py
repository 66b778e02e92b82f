"""The files of a run folder that record how it was trained: the logger outputs (TensorBoard,
``metrics.jsonl``, the console), one ``run.json`` entry per session, and the learning curve."""

from __future__ import annotations

import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

from stable_baselines3.common.logger import HumanOutputFormat, Logger, TensorBoardOutputFormat

from frontier_marl.training.callbacks import JsonLinesWriter, read_metrics, truncate_metrics
from frontier_marl.training.experiment import Experiment
from frontier_marl.training.plots import plot_family_validation
from frontier_marl.training.plots import plot_learning_curve as plot
from frontier_marl.training.validation import read_validation_log


def set_logger(model: Any, run_dir: Path, start_step: int, resumed: bool, verbose: int) -> None:
    """TensorBoard (``RUN/tb``), ``RUN/metrics.jsonl`` (cut back to ``start_step`` on resume)
    and, with ``verbose``, the console."""
    metrics = run_dir / "metrics.jsonl"
    if resumed:
        truncate_metrics(metrics, start_step)
    elif metrics.exists():
        metrics.unlink()
    outputs: list[Any] = [
        TensorBoardOutputFormat(str(run_dir / "tb")),
        JsonLinesWriter(metrics),
    ]
    if verbose:
        outputs.append(HumanOutputFormat(sys.stdout))
    model.set_logger(Logger(folder=str(run_dir), output_formats=outputs))


def record_session(
    run_dir: Path,
    experiment: Experiment,
    start: int,
    end: int,
    wall: float,
    cpu: float,
    interrupted: bool,
    resumed_from: Path | None,
) -> None:
    """Append this session (steps, wall and CPU time, interruption) to ``RUN/run.json``."""
    path = run_dir / "run.json"
    record = json.loads(path.read_text()) if path.is_file() else {"sessions": []}
    record["experiment"] = experiment.to_dict()
    record["sessions"].append(
        {
            "start_step": start,
            "end_step": end,
            "wall_time_s": round(wall, 3),
            "steps_per_second": round((end - start) / wall, 1) if wall > 0 else None,
            "cpu_time_s": round(cpu, 3),
            "interrupted": interrupted,
            "resumed_from": None if resumed_from is None else str(resumed_from),
            "machine": machine_name(),
            "finished_at": time.strftime("%Y-%m-%dT%H:%M:%S"),
        }
    )
    path.write_text(json.dumps(record, indent=2) + "\n")


def plot_learning_curve(run_dir: Path, experiment: Experiment, num_timesteps: int) -> Path:
    """``RUN/learning_curve.png`` from the run's metrics and validation logs (and, for a run
    validated on map families, ``RUN/validation_t99.png``)."""
    path = run_dir / "learning_curve.png"
    title = f"{experiment.name} (seed {experiment.train.seed}, {num_timesteps} steps)"
    validation = read_validation_log(run_dir)
    plot(read_metrics(run_dir / "metrics.jsonl"), path, title=title, validation=validation)
    if any("by_family" in record for record in validation):
        plot_family_validation(validation, run_dir / "validation_t99.png", title=title)
    return path


def machine_name() -> str:
    """The CPU model (from ``/proc/cpuinfo`` where there is one) and the core count: training
    results depend on the CPU (docs/results.md)."""
    model = platform.processor() or platform.machine()
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.is_file():
        for line in cpuinfo.read_text(errors="replace").splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return f"{model}, {os.cpu_count()} cores"
