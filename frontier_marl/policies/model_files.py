"""Where a saved model lies: a run folder's ``model.zip`` and its checkpoints
``RUN/checkpoints/step_000050000/{model.zip, model.json, replay_buffer.pkl}``.

This is the reading side of the layout; training writes it
(:func:`frontier_marl.training.checkpoints.save_checkpoint`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frontier_marl.policies.metadata import load_metadata

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
