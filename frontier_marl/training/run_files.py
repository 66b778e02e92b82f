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


def start_session(
    run_dir: Path, experiment: Experiment, start: int, resumed_from: Path | None
) -> int:
    """Record a session in ``RUN/run.json`` as it starts (so a crash cannot lose it); returns
    its index. A session still marked running was killed without ending: it is marked so."""
    record = read_run_record(run_dir)
    for session in record["sessions"]:
        if session.get("status") == "running":
            session["status"] = "killed"  # its process ended without recording an end
    record["experiment"] = experiment.to_dict()
    record["sessions"].append(
        {
            "start_step": start,
            "status": "running",
            "resumed_from": None if resumed_from is None else str(resumed_from),
            "machine": machine_name(),
            "pid": os.getpid(),
            "started_at": time.strftime("%Y-%m-%dT%H:%M:%S"),
        }
    )
    _write_record(run_dir, record)
    return len(record["sessions"]) - 1


def end_session(
    run_dir: Path, index: int, end: int, wall: float, cpu: float, interrupted: bool
) -> None:
    """Complete session ``index`` of ``RUN/run.json``: steps, wall and CPU time, interruption."""
    record = read_run_record(run_dir)
    session = record["sessions"][index]
    start = session["start_step"]
    session.update(
        {
            "end_step": end,
            "status": "interrupted" if interrupted else "finished",
            "wall_time_s": round(wall, 3),
            "steps_per_second": round((end - start) / wall, 1) if wall > 0 else None,
            "cpu_time_s": round(cpu, 3),
            "interrupted": interrupted,
            "finished_at": time.strftime("%Y-%m-%dT%H:%M:%S"),
        }
    )
    _write_record(run_dir, record)


def read_run_record(run_dir: Path) -> dict[str, Any]:
    """``RUN/run.json`` (the experiment and its sessions), or an empty record."""
    path = run_dir / "run.json"
    if not path.is_file():
        return {"sessions": []}
    try:
        return json.loads(path.read_text())
    except ValueError as error:
        raise ValueError(f"run record {path} is not valid JSON ({error})") from None


def _write_record(run_dir: Path, record: dict[str, Any]) -> None:
    """Write ``RUN/run.json`` through a temporary file, so a crash leaves the old or the new."""
    path = run_dir / "run.json"
    temporary = path.with_name(".run.json.tmp")
    temporary.write_text(json.dumps(record, indent=2) + "\n")
    temporary.replace(path)


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
