"""Checkpoints of a run: ``RUN/checkpoints/step_000050000/{model.zip, model.json,
replay_buffer.pkl}``. A checkpoint is written to a temporary folder and renamed, so an
interrupted save never leaves a half checkpoint behind."""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frontier_marl.training.metadata import load_metadata, save_metadata

CHECKPOINTS = "checkpoints"
MODEL_FILE = "model.zip"
BUFFER_FILE = "replay_buffer.pkl"


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


def save_checkpoint(
    model: Any, run_dir: Path, meta: dict[str, Any], keep: int = 2, replay_buffer: bool = True
) -> Checkpoint:
    """Save ``model`` (+ its replay buffer, if it has one, and ``meta``) at its current step;
    keep the newest ``keep`` checkpoints (0 keeps all)."""
    folder = Path(run_dir) / CHECKPOINTS
    folder.mkdir(parents=True, exist_ok=True)
    final = folder / f"step_{int(model.num_timesteps):09d}"
    tmp = folder / f".tmp_{final.name}"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir()
    model.save(tmp / MODEL_FILE)
    save_metadata(meta, tmp / "model.json")
    if replay_buffer and hasattr(model, "save_replay_buffer"):
        model.save_replay_buffer(tmp / BUFFER_FILE)
    if final.exists():
        shutil.rmtree(final)
    tmp.rename(final)
    if keep > 0:
        for old in list_checkpoints(run_dir)[:-keep]:
            shutil.rmtree(old.path, ignore_errors=True)
    return Checkpoint(final)


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


def find_checkpoint(path: str | Path) -> Checkpoint:
    """A checkpoint folder, or the newest checkpoint of a run folder."""
    path = Path(path)
    if path.is_file() and path.name == MODEL_FILE:
        path = path.parent
    if not path.is_dir():
        raise ValueError(f"--resume: {str(path)!r} is not a run or checkpoint folder")
    if (path / MODEL_FILE).is_file() and path.name.startswith("step_"):
        return Checkpoint(path)
    checkpoints = list_checkpoints(path)
    if not checkpoints:
        raise ValueError(
            f"--resume: no checkpoint in {str(path)!r} (expected {CHECKPOINTS}/step_*/{MODEL_FILE})"
        )
    return checkpoints[-1]
