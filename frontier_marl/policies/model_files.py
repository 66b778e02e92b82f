"""Where a saved model lies: a run folder's ``model.zip`` and its checkpoints
``RUN/checkpoints/step_000050000/{model.zip, model.json, replay_buffer.pkl, checksums.json}``.

This is the reading side of the layout; training writes it
(:func:`frontier_marl.training.checkpoints.save_checkpoint`). ``checksums.json`` holds the
SHA-256 of every other file of the checkpoint: a checkpoint damaged after it was written (a
full disk, a crash mid-copy) is recognised, and resuming falls back to the previous one with a
warning naming the damaged one.
"""

from __future__ import annotations

import hashlib
import json
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frontier_marl.policies.metadata import load_metadata

CHECKPOINTS = "checkpoints"
MODEL_FILE = "model.zip"
BUFFER_FILE = "replay_buffer.pkl"
CHECKSUMS_FILE = "checksums.json"


@dataclass(frozen=True)
class Checkpoint:
    """A checkpoint folder: the model, its metadata, and (optionally) the replay buffer."""

    path: Path

    @property
    def model(self) -> Path:
        return self.path / MODEL_FILE

    @property
    def replay_buffer(self) -> Path:
        return self.path / BUFFER_FILE

    @property
    def step(self) -> int:
        return int(self.path.name.removeprefix("step_"))

    @property
    def run_dir(self) -> Path:
        return self.path.parent.parent

    def metadata(self) -> dict[str, Any]:
        meta = load_metadata(self.model)
        if meta is None:
            raise ValueError(f"checkpoint {self.path} has no model.json metadata")
        return meta


def list_checkpoints(run_dir: str | Path) -> list[Checkpoint]:
    """Complete checkpoints of a run, oldest first."""
    folder = Path(run_dir) / CHECKPOINTS
    if not folder.is_dir():
        return []
    found = [
        Checkpoint(p)
        for p in folder.iterdir()
        if p.is_dir() and p.name.startswith("step_") and (p / MODEL_FILE).is_file()
    ]
    return sorted(found, key=lambda c: c.step)


def file_digest(path: Path) -> str:
    """The SHA-256 of a file, hex."""
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def checkpoint_problems(checkpoint: Checkpoint) -> list[str]:
    """What is wrong with a checkpoint's files (empty: it is whole). Without a checksums file
    (checkpoints written before them) the model's zip is tested for damage."""
    sums = checkpoint.path / CHECKSUMS_FILE
    if not sums.is_file():
        try:
            with zipfile.ZipFile(checkpoint.model) as archive:
                bad = archive.testzip()
        except (OSError, zipfile.BadZipFile) as error:
            return [f"{MODEL_FILE} is not a readable zip ({error})"]
        return [] if bad is None else [f"{MODEL_FILE} member {bad} is damaged"]
    try:
        expected = json.loads(sums.read_text())
    except ValueError:
        return [f"{CHECKSUMS_FILE} is damaged"]
    problems = []
    for name, digest in expected.items():
        path = checkpoint.path / name
        if not path.is_file():
            problems.append(f"{name} is missing")
        elif file_digest(path) != digest:
            problems.append(f"{name} does not match its checksum")
    return problems


def newest_good_checkpoint(run_dir: str | Path) -> Checkpoint | None:
    """The newest whole checkpoint of a run (None if it has none); each newer damaged one is
    named in a warning."""
    for checkpoint in reversed(list_checkpoints(run_dir)):
        problems = checkpoint_problems(checkpoint)
        if not problems:
            return checkpoint
        warnings.warn(
            f"checkpoint {checkpoint.path} is damaged ({'; '.join(problems)}): "
            "falling back to the previous checkpoint",
            stacklevel=2,
        )
    return None


def find_checkpoint(path: str | Path) -> Checkpoint:
    """A checkpoint folder, or the newest checkpoint of a run folder."""
    path = Path(path)
    if path.is_file() and path.name == MODEL_FILE:
        path = path.parent
    if not path.is_dir():
        raise ValueError(f"--resume: {str(path)!r} is not a run or checkpoint folder")
    if (path / MODEL_FILE).is_file() and path.name.startswith("step_"):
        checkpoint = Checkpoint(path)
        problems = checkpoint_problems(checkpoint)
        if problems:
            raise ValueError(
                f"--resume: checkpoint {path} is damaged ({'; '.join(problems)}); resume from "
                f"the run folder {checkpoint.run_dir} to fall back to an earlier checkpoint"
            )
        return checkpoint
    if not list_checkpoints(path):
        raise ValueError(
            f"--resume: no checkpoint in {str(path)!r} (expected {CHECKPOINTS}/step_*/{MODEL_FILE})"
        )
    checkpoint = newest_good_checkpoint(path)
    if checkpoint is None:
        raise ValueError(f"--resume: every checkpoint in {str(path)!r} is damaged")
    return checkpoint
