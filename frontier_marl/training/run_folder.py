"""A run folder belongs to one training session at a time.

``RUN/.lock`` is created exclusively (``O_CREAT | O_EXCL``: atomic on a local disk and on
NFS v3 and later) when a session starts and removed when it ends; it records the owner's
process id, host and start time. A second session into the same folder is refused with a
message naming the owner. A lock left by a process that no longer runs on this host (a
``kill -9``, a power cut) is stale: it is reported and taken over. A lock from another host
cannot be checked from here and is never taken over: the message says how to remove it.

A fresh run (no ``--resume``) is also refused in a folder that holds any file a run writes
(a model, logs, an evaluation, checkpoints), so nothing of an earlier run or of the user's is
overwritten.
"""

from __future__ import annotations

import json
import os
import socket
import sys
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

LOCK_FILE = ".lock"

#: What a run writes into its folder (train.py's docstring lists each).
RUN_OUTPUTS = (
    "model.zip",
    "model.pt",
    "model.json",
    "evaluation.json",
    "actions.png",
    "learning_curve.png",
    "validation_t99.png",
    "metrics.jsonl",
    "validation.jsonl",
    "run.json",
    "cem.json",
    "cem.jsonl",
    "tb",
    "checkpoints",
    "best",
    "labels",
)


class RunFolderError(ValueError):
    """The run folder cannot be used by this session."""


def existing_outputs(run_dir: Path) -> list[str]:
    """The files and folders of :data:`RUN_OUTPUTS` that ``run_dir`` already holds."""
    return [name for name in RUN_OUTPUTS if (run_dir / name).exists()]


@contextmanager
def own_run_folder(run_dir: Path, fresh: bool, overwrite: bool = False) -> Iterator[None]:
    """Hold ``run_dir`` for one session (created if needed). ``fresh``: a new run, refused
    where earlier outputs lie unless ``overwrite`` (a workflow replacing its own unfinished
    run). :class:`RunFolderError` names what is wrong."""
    try:
        run_dir.mkdir(parents=True, exist_ok=True)
        lock = _acquire(run_dir / LOCK_FILE)
    except OSError as error:  # no permission, a file in the way, a read-only disk
        reason = (error.strerror or str(error)).lower()
        raise RunFolderError(
            f"cannot write the run folder {str(run_dir)!r}: {reason} ({error.filename}); "
            "choose another --out"
        ) from None
    try:
        found = existing_outputs(run_dir)
        if fresh and found and not overwrite:
            raise RunFolderError(
                f"run folder {str(run_dir)!r} already holds a run ({', '.join(found)}): "
                f"continue it with --resume {run_dir}, or choose another --out"
            )
        yield
    finally:
        _release(lock)


def _acquire(path: Path) -> Path:
    record = {
        "pid": os.getpid(),
        "host": socket.gethostname(),
        "started_at": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "command": " ".join(sys.argv),
    }
    for _ in range(2):
        try:
            handle = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            owner = _owner(path)
            if not _stale(owner):
                raise RunFolderError(_busy_message(path, owner)) from None
            warnings.warn(
                f"run folder {str(path.parent)!r}: taking over the stale lock of process "
                f"{owner.get('pid')} (started {owner.get('started_at')}), which no longer runs",
                stacklevel=3,
            )
            path.unlink(missing_ok=True)
            continue
        with os.fdopen(handle, "w") as out:
            json.dump(record, out)
        return path
    raise RunFolderError(f"run folder {str(path.parent)!r}: could not take its lock {path}")


def _release(path: Path) -> None:
    if _owner(path).get("pid") == os.getpid():
        path.unlink(missing_ok=True)


def _owner(path: Path) -> dict[str, object]:
    try:
        owner = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return owner if isinstance(owner, dict) else {}


def _stale(owner: dict[str, object]) -> bool:
    """Whether the lock's owner is a process of this host that no longer runs."""
    pid = owner.get("pid")
    if owner.get("host") != socket.gethostname() or not isinstance(pid, int):
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:  # it runs, as another user
        return False
    return False


def _busy_message(path: Path, owner: dict[str, object]) -> str:
    if not owner:  # being written this instant, or damaged
        return (
            f"run folder {str(path.parent)!r} is locked by another session ({path}): "
            "choose another --out"
        )
    return (
        f"run folder {str(path.parent)!r} is in use by process {owner.get('pid')} on "
        f"{owner.get('host')} since {owner.get('started_at')} ({owner.get('command')}): wait "
        f"for it to end or choose another --out (if that process is gone, delete {path})"
    )
