"""Several training runs at once, one worker process each, with one progress bar per run.

:func:`train_runs` trains a list of :class:`TrainJob` (e.g. the seeds of one configuration)
with :func:`frontier_marl.training.train.train`. Each run is the same as a run trained alone in
its own process (same seeds, same results); only the wall time changes. With ``workers=1`` or
one job the runs train in this process, one after the other.

Ctrl-C stops every run cleanly: the worker processes ignore SIGINT themselves; the parent asks
them, through a shared event, to end the session like Ctrl-C would (checkpoint and model
saved, no evaluation; a run already in its final evaluation finishes it), and runs not yet
started are skipped. ``--resume`` continues them. When one run fails, the others are stopped
the same way and its error is raised.
"""

from __future__ import annotations

import multiprocessing as mp
import queue
import signal
import sys
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frontier_marl.policies.model_files import Checkpoint
from frontier_marl.training.callbacks import Periodic
from frontier_marl.training.experiment import Experiment
from frontier_marl.training.train import train
from frontier_marl.utils.progress import progress_bar

#: How often (environment steps) a worker reports its progress and looks for a stop request.
REPORT_EVERY = 1000


@dataclass(frozen=True)
class TrainJob:
    """One run: the experiment, its folder, the checkpoint to resume (or None), a label, and
    whether a fresh run may replace an unfinished one's files (``train``'s ``overwrite``)."""

    experiment: Experiment
    run_dir: Path
    checkpoint: Checkpoint | None = None
    label: str = ""
    overwrite: bool = False


@dataclass
class TrainOutcome:
    """What came of the jobs, in their order: a ``TrainResult``, or None for a run that was
    skipped (stopped before it started); ``interrupted`` when a stop was requested."""

    results: list[Any]
    interrupted: bool


def train_runs(jobs: Sequence[TrainJob], workers: int, progress: bool = True) -> TrainOutcome:
    """Train ``jobs`` with up to ``workers`` processes at a time (see the module docstring)."""
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    if workers == 1 or len(jobs) == 1:
        return _train_here(jobs, progress)
    return _train_in_workers(jobs, workers, progress)


def _train_here(jobs: Sequence[TrainJob], progress: bool) -> TrainOutcome:
    results: list[Any] = []
    for job in jobs:
        result = train(
            job.experiment,
            job.run_dir,
            resume=job.checkpoint,
            progress_bar=progress,
            overwrite=job.overwrite,
        )
        results.append(result)
        if result.interrupted:
            results += [None] * (len(jobs) - len(results))
            return TrainOutcome(results, True)
    return TrainOutcome(results, False)


# --- worker side -----------------------------------------------------------------------------

_REPORTS: Any = None  # the parent's queue of (job index, steps, phase)
_STOP: Any = None  # the parent's stop event


def _init_worker(reports: Any, stop: Any) -> None:
    global _REPORTS, _STOP
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides when to stop
    _REPORTS, _STOP = reports, stop


def _run_job(index: int, job: TrainJob) -> Any:
    """Train one job in a worker; None when a stop was requested before it started."""
    if _STOP.is_set():
        return None

    def report(model: Any) -> None:
        _REPORTS.put((index, int(model.num_timesteps), "training"))
        if _STOP.is_set():
            raise KeyboardInterrupt  # train() ends the session as on Ctrl-C

    result = train(
        job.experiment,
        job.run_dir,
        resume=job.checkpoint,
        progress_bar=False,
        callbacks=[Periodic(REPORT_EVERY, report)],
        overwrite=job.overwrite,
    )
    _REPORTS.put((index, result.num_timesteps, "done"))
    return result


# --- parent side -----------------------------------------------------------------------------


def _train_in_workers(jobs: Sequence[TrainJob], workers: int, progress: bool) -> TrainOutcome:
    context = mp.get_context("spawn")  # fork would copy torch's threads and locks
    reports, stop = context.Queue(), context.Event()
    bars = _Bars(jobs, progress)
    interrupted = False
    with ProcessPoolExecutor(
        workers, mp_context=context, initializer=_init_worker, initargs=(reports, stop)
    ) as pool:
        futures = [pool.submit(_run_job, i, job) for i, job in enumerate(jobs)]
        while True:
            try:
                if all(f.done() for f in futures):
                    break
                if any(f.done() and f.exception() for f in futures):
                    stop.set()  # one run failed: the others save a checkpoint and end
                _drain(reports, bars, timeout=0.5)
            except KeyboardInterrupt:
                stop.set()
                running = sum(not f.done() for f in futures)
                print(
                    f"\n{'still ' if interrupted else ''}stopping: waiting for {running} "
                    "run(s) to save a checkpoint",
                    file=sys.stderr,
                )
                interrupted = True
        _drain(reports, bars, timeout=0.0)
    bars.close()
    results = [f.result() for f in futures]  # a worker's error is raised here, as it was
    interrupted = interrupted or any(r is None or r.interrupted for r in results)
    return TrainOutcome(results, interrupted)


def _drain(reports: Any, bars: _Bars, timeout: float) -> None:
    """Apply every waiting report to the bars (waiting up to ``timeout`` for the first)."""
    try:
        item = reports.get(timeout=timeout) if timeout > 0 else reports.get_nowait()
        while True:
            bars.update(*item)
            item = reports.get_nowait()
    except queue.Empty:
        pass


class _Bars:
    """One progress bar per job (nothing when progress is off)."""

    def __init__(self, jobs: Sequence[TrainJob], progress: bool) -> None:
        self._bars: list[Any] = []
        if not progress:
            return

        for i, job in enumerate(jobs):
            start = 0 if job.checkpoint is None else job.checkpoint.step
            self._bars.append(
                progress_bar(
                    job.experiment.train.total_timesteps,
                    initial=start,
                    desc=job.label or f"run {i}",
                    position=i,
                    unit="step",
                    smoothing=0.05,
                )
            )

    def update(self, index: int, steps: int, phase: str) -> None:
        if not self._bars:
            return
        bar = self._bars[index]
        bar.update(steps - bar.n)
        if phase == "done":
            bar.set_postfix_str("evaluated" if steps >= bar.total else "stopped")
        elif steps >= bar.total:
            bar.set_postfix_str("evaluating")

    def close(self) -> None:
        for bar in self._bars:
            bar.close()
