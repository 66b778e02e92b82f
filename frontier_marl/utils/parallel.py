"""The package's one way to spread independent tasks over cores or a Ray cluster.

:func:`map_tasks` applies a function to a list of tasks and returns the results in task order,
whatever order they finished in: with ``jobs=1`` in this process, with ``jobs=N`` in ``N``
worker processes, with ``ray_address`` on a Ray cluster. The function and the tasks must be
picklable for worker processes (module-level functions, plain data); each task should be
deterministic on its own (e.g. one episode from its seed), so the results do not depend on
where or when it ran.

Worker processes are forked where that is safe (:func:`start_method`: Linux, a parent on one
Python thread and without torch; they start at once), else forked by a ``forkserver`` (a clean
server process that first imports the modules this process uses: a few seconds, once), else
spawned. A task that raises makes :func:`map_tasks` raise that exception with a note naming the
task (the tasks not started are cancelled); a worker process that dies raises
:class:`WorkerDied` naming the first unfinished task. Nothing waits forever on a lost worker.
Ray is an optional extra (``pip install "frontier-marl[ray]"``).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import pickle
import sys
import threading
import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

from frontier_marl.utils.progress import progress_bar

T = TypeVar("T")
R = TypeVar("R")

RAY_HINT = 'Ray is not installed: pip install "frontier-marl[ray]"'
#: Variables that keep each worker's numeric libraries on one thread (jobs use the cores).
ONE_THREAD = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS")
#: Libraries a fork server imports once for all workers when this process has imported them.
HEAVY = ("torch", "stable_baselines3", "sb3_contrib")


class WorkerDied(RuntimeError):
    """A worker process ended without a result (killed, out of memory, crashed)."""


class RayMissingError(ImportError):
    """``ray_address`` was given but Ray is not installed."""


def default_jobs() -> int:
    """All the cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def check_jobs(jobs: int | None, option: str = "jobs") -> int:
    """``jobs`` as a count of processes (``None``: :func:`default_jobs`); ValueError naming
    ``option`` for anything below 1."""
    if jobs is None:
        return default_jobs()
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"{option} must be an integer >= 1, got {jobs!r}")
    return jobs


def map_tasks(
    fn: Callable[[T], R],
    tasks: Sequence[T],
    jobs: int | None = 1,
    *,
    ray_address: str | None = None,
    progress: bool = False,
    desc: str | None = None,
    unit: str = "task",
    label: Callable[[T], str] = str,
    on_done: Callable[[int, R], None] | None = None,
) -> list[R]:
    """``[fn(task) for task in tasks]``, computed in ``jobs`` processes (``None``: every core)
    or on the Ray cluster at ``ray_address``; see the module docstring.

    ``progress`` shows one bar over all tasks; ``label(task)`` names a task in errors and on
    the bar; ``on_done(index, result)`` is called in this process as each task finishes.
    """
    jobs = check_jobs(jobs)
    tasks = list(tasks)
    done = _Done(tasks, label, on_done, progress, desc=desc, unit=unit)
    try:
        if ray_address is not None:
            return _on_ray(fn, tasks, ray_address, label, done)
        if jobs == 1 or len(tasks) <= 1:
            return _here(fn, tasks, label, done)
        return _in_processes(fn, tasks, min(jobs, len(tasks)), label, done)
    finally:
        done.close()


class _Done:
    """Reports finished tasks: the bar (made by :meth:`start`, once the workers exist: its
    monitor thread would make forking unsafe) and ``on_done``."""

    def __init__(
        self, tasks: list, label: Callable, on_done: Callable | None, progress: bool, **bar: Any
    ) -> None:
        self.tasks, self.label, self.on_done = tasks, label, on_done
        self.progress, self.options = progress, bar
        self.bar: Any = None

    def start(self) -> None:
        if self.progress and self.bar is None:
            self.bar = progress_bar(len(self.tasks), **self.options)

    def __call__(self, index: int, result: Any) -> None:
        self.start()
        if self.bar is not None:
            self.bar.set_postfix_str(self.label(self.tasks[index]), refresh=False)
            self.bar.update(1)
        if self.on_done is not None:
            self.on_done(index, result)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _here(fn: Callable, tasks: list, label: Callable, done: _Done) -> list:
    done.start()
    results = []
    for index, task in enumerate(tasks):
        try:
            results.append(fn(task))
        except Exception as error:
            error.add_note(f"while running {label(task)}")
            raise
        done(index, results[-1])
    return results


# --------------------------------------------------------------------------- processes


def start_method() -> str:
    """``fork`` where it is safe and instant (Linux, this process on one Python thread and
    without torch, whose thread pools do not survive a fork), else ``forkserver`` (a clean
    server process forks the workers), else ``spawn``."""
    if sys.platform == "linux" and threading.active_count() == 1 and "torch" not in sys.modules:
        return "fork"
    return "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"


def _preload(fn: Callable) -> list[str]:
    """What the fork server imports before it forks the workers: the package's modules this
    process has imported, ``fn``'s module and the heavy optional libraries already in use."""
    own = [name for name in sys.modules if name.startswith("frontier_marl.")]
    heavy = [name for name in HEAVY if name in sys.modules]
    return ["frontier_marl", *sorted(own), getattr(fn, "__module__", "frontier_marl"), *heavy]


def _one_thread() -> None:
    """Worker initializer: numeric libraries on one thread each."""
    for name in ONE_THREAD:
        os.environ.setdefault(name, "1")
    torch = sys.modules.get("torch")  # only if already imported: torch is an optional extra
    if torch is not None:
        torch.set_num_threads(1)


def _check_picklable(fn: Callable, tasks: list, label: Callable) -> None:
    """ValueError naming the function or task that pickle cannot send (a lambda, say)."""
    named = [(getattr(fn, "__qualname__", repr(fn)), fn), *((label(t), t) for t in tasks)]
    for name, item in named:
        try:
            pickle.dumps(item)
        except Exception as error:
            raise ValueError(
                f"{name} cannot be sent to worker processes ({error}): use jobs=1"
            ) from None


def _in_processes(fn: Callable, tasks: list, jobs: int, label: Callable, done: _Done) -> list:
    _check_picklable(fn, tasks, label)
    context = mp.get_context(start_method())
    if context.get_start_method() == "forkserver":
        context.set_forkserver_preload(_preload(fn))
    pool = ProcessPoolExecutor(jobs, mp_context=context, initializer=_one_thread)
    try:
        with warnings.catch_warnings():  # Python 3.12+ warns of numpy's idle BLAS threads
            warnings.filterwarnings("ignore", ".*fork.*", DeprecationWarning)
            futures = {pool.submit(fn, task): i for i, task in enumerate(tasks)}
        done.start()
        results: list[Any] = [None] * len(tasks)
        pending: set[Future] = set(futures)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in sorted(finished, key=futures.__getitem__):
                index = futures[future]
                results[index] = _result(future, tasks, index, label)
                done(index, results[index])
        return results
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _result(future: Future, tasks: list, index: int, label: Callable) -> Any:
    try:
        return future.result()
    except BrokenProcessPool:
        raise WorkerDied(
            "a worker process died (killed, out of memory or crashed; or a script without "
            f"`if __name__ == '__main__':`); the first unfinished task was {label(tasks[index])}"
        ) from None
    except Exception as error:
        error.add_note(f"raised in a worker process by {label(tasks[index])}")
        raise


# --------------------------------------------------------------------------- Ray


def require_ray() -> Any:
    """The ``ray`` module, or :class:`RayMissingError` with the install hint."""
    try:
        import ray
    except ImportError as exc:
        raise RayMissingError(RAY_HINT) from exc
    return ray


def _call(fn: Callable, task: Any) -> Any:
    """``fn(task)``: what Ray runs (a Python function, whatever ``fn`` is)."""
    return fn(task)


def init_ray(address: str | None) -> bool:
    """Start Ray, or connect to ``address``, unless it is already initialised; whether this
    call did (ConnectionError naming the address)."""
    ray = require_ray()
    if ray.is_initialized():
        return False
    try:
        ray.init(
            address=address, include_dashboard=False, log_to_driver=False, configure_logging=False
        )
    except ConnectionError as exc:
        raise ConnectionError(f"ray address {address!r}: cannot connect to Ray: {exc}") from exc
    return True


def _on_ray(fn: Callable, tasks: list, address: str, label: Callable, done: _Done) -> list:
    ray = require_ray()
    started = init_ray(address)
    try:
        remote = ray.remote(num_cpus=1)(_call)
        refs = [remote.remote(fn, task) for task in tasks]
        done.start()
        index = {ref: i for i, ref in enumerate(refs)}
        pending = list(refs)
        results: list[Any] = [None] * len(tasks)
        while pending:
            (ref,), pending = ray.wait(pending, num_returns=1)
            i = index[ref]
            try:
                results[i] = ray.get(ref)
            except Exception as error:
                for other in pending:
                    ray.cancel(other)
                error.add_note(f"raised on Ray by {label(tasks[i])}")
                raise
            done(i, results[i])
        return results
    finally:
        if started:
            ray.shutdown()
