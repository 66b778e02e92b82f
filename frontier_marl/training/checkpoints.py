"""Saving checkpoints of a run (the layout, and reading them:
:mod:`frontier_marl.policies.model_files`). A checkpoint is written to a temporary folder
and renamed, so an interrupted save never leaves a half checkpoint behind."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

from frontier_marl.policies.metadata import save_metadata
from frontier_marl.policies.model_files import (
    BUFFER_FILE,
    CHECKPOINTS,
    CHECKSUMS_FILE,
    MODEL_FILE,
    Checkpoint,
    file_digest,
    list_checkpoints,
)


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
    digests = {f.name: file_digest(f) for f in sorted(tmp.iterdir()) if f.is_file()}
    (tmp / CHECKSUMS_FILE).write_text(json.dumps(digests, indent=1) + "\n")
    if final.exists():
        shutil.rmtree(final)
    tmp.rename(final)
    if keep > 0:
        for old in list_checkpoints(run_dir)[:-keep]:
            shutil.rmtree(old.path, ignore_errors=True)
    return Checkpoint(final)
