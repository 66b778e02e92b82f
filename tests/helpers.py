"""Hand-made slot tables and infos for the policy tests."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from frontier_marl.core.slots import SlotTable


def live_slot(
    gain: float = 1.0,
    distance: float = 1.0,
    path_length: int | None = None,
    target: tuple[int, int] = (0, 0),
    cluster: int | None = None,
) -> dict[str, Any]:
    """One live slot; the path length defaults to the distance rounded up."""
    return {
        "gain": float(gain),
        "distance": float(distance),
        "path_length": int(np.ceil(distance)) if path_length is None else path_length,
        "target": target,
        "cluster": cluster,
    }


def slot_table(live: Sequence[dict[str, Any]], n_slots: int = 4) -> SlotTable:
    """A table whose first slots are ``live`` (as made by :func:`live_slot`), then padding; a
    slot's cluster defaults to its index and its centroid to its target."""
    n = len(live)
    target = np.full((n_slots, 2), -1, dtype=np.int64)
    centroid = np.zeros((n_slots, 2))
    cluster = np.full(n_slots, -1, dtype=np.int64)
    for i, row in enumerate(live):
        target[i] = row["target"]
        centroid[i] = row["target"]
        cluster[i] = i if row["cluster"] is None else row["cluster"]

    def column(key: str, dtype: Any, pad: float) -> np.ndarray:
        return np.array([row[key] for row in live] + [pad] * (n_slots - n), dtype=dtype)

    gain = column("gain", float, 0.0)
    return SlotTable.from_arrays(
        cluster=cluster,
        valid=np.arange(n_slots) < n,
        centroid=centroid,
        target=target,
        distance=column("distance", float, 0.0),
        size=gain.astype(np.int64),
        gain=gain,
        path_length=column("path_length", np.int64, -1),
    )


def info_with(live: Sequence[dict[str, Any]], n_slots: int = 4, **extra: Any) -> dict[str, Any]:
    """A robot's info holding ``slot_table(live)`` and its action mask."""
    table = slot_table(live, n_slots)
    return {"slots": table, "action_mask": table.mask, **extra}


def silent(model: Any) -> Any:
    """``model`` with a logger that writes nothing (SB3's default makes a ``SB3-*`` folder in
    the temp directory on every ``learn``)."""
    from stable_baselines3.common.logger import Logger

    model.set_logger(Logger(folder=None, output_formats=[]))
    return model
