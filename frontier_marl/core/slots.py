"""Cluster slots: which frontier clusters a robot may choose, and in which order.

Rules (open choices of the thesis, documented in docs/thesis-mapping.md):

* A cluster is *live* for a robot when one of its cells is reachable from the robot through
  known-free cells; its navigation target is that reachable cell nearest the centroid (ties:
  raster order). Unreachable clusters are dropped (they never get a slot).
* When more live clusters exist than slots, the ``n_slots`` nearest (Euclidean distance from
  the robot to the centroid; ties by cluster index) get a slot.
* The slots shown are ordered by increasing distance (``sort_by_distance``) or by cluster
  index, i.e. raster order of the cluster's first cell. Ordering never changes which clusters
  are selected.
* Slots beyond the live clusters are padding: cluster -1, zero features, masked out.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontiers import Clusters
from frontier_marl.core.slot_kernels import robot_slot_fields

_ARRAYS = ("cluster", "valid", "centroid", "target", "distance", "size", "gain", "path_length")
_FIELDS = (*_ARRAYS, "mask")

#: The columns of a packed slot table (:meth:`SlotArrays.packed`; the env info's ``slots``):
#: one float64 row per slot, the integers exact, padding rows as in :class:`SlotTable`.
SLOT_COLUMNS = (
    "cluster",
    "valid",
    "centroid_row",
    "centroid_col",
    "target_row",
    "target_col",
    "distance",
    "path_length",
    "size",
    "gain",
)


@dataclass(eq=False, slots=True)
class SlotTable:
    """One robot's slots. Arrays have length ``n_slots``; padding rows hold zeros and -1.

    A table is built once per decision and shared (by the observation, the info and the action
    mask): treat its arrays as read-only.
    """

    cluster: np.ndarray  # int (n,), cluster index or -1 for padding
    valid: np.ndarray  # bool (n,)
    centroid: np.ndarray  # float (n, 2)
    target: np.ndarray  # int (n, 2), -1 for padding
    distance: np.ndarray  # float (n,), Euclidean robot -> centroid
    size: np.ndarray  # int (n,)
    gain: np.ndarray  # float (n,)
    path_length: np.ndarray  # int (n,), known-free shortest path robot -> target, -1 padding
    mask: np.ndarray  # int8 (n,): the live slots, or slot 0 (the idle action) if none is live
    live: int  # how many slots hold a cluster (the first ``live`` ones)

    @classmethod
    def from_arrays(cls, **arrays: np.ndarray) -> SlotTable:
        """A table from the arrays of :data:`_ARRAYS` (live slots first), with its ``live``
        count and action mask derived."""
        live = int(np.count_nonzero(arrays["valid"]))
        mask = np.asarray(arrays["valid"], dtype=np.int8).copy()
        if not live:
            mask[0] = 1
        return cls(**arrays, mask=mask, live=live)

    def __eq__(self, other: object) -> bool:
        """Equal when every field is: same live count and identical arrays."""
        if not isinstance(other, SlotTable):
            return NotImplemented
        return self.live == other.live and all(
            np.array_equal(getattr(self, name), getattr(other, name)) for name in (*_ARRAYS, "mask")
        )

    __hash__ = None  # type: ignore[assignment]  # mutable-looking arrays: not hashable

    def rows(self) -> list[dict[str, Any]]:
        """The live slots as plain dicts (slot, cluster, centroid, target, distance,
        path_length, size, gain), for reading and printing rather than for speed."""
        return [
            {
                "slot": slot,
                "cluster": int(self.cluster[slot]),
                "centroid": (float(self.centroid[slot, 0]), float(self.centroid[slot, 1])),
                "target": (int(self.target[slot, 0]), int(self.target[slot, 1])),
                "distance": float(self.distance[slot]),
                "path_length": int(self.path_length[slot]),
                "size": int(self.size[slot]),
                "gain": float(self.gain[slot]),
            }
            for slot in range(self.live)
        ]

    def action_mask(self) -> np.ndarray:
        """int8 mask of the actions worth taking: the live slots, or slot 0 (idle) if none."""
        return self.mask

    @classmethod
    def from_packed(cls, packed: np.ndarray, mask: np.ndarray) -> SlotTable:
        """The table of a packed ``(n_slots, 10)`` array (:data:`SLOT_COLUMNS`) and its action
        mask: the same values, in the table's dtypes."""
        rows = np.asarray(packed)
        if rows.ndim != 2 or rows.shape[1] != len(SLOT_COLUMNS):
            raise ValueError(f"a packed slot table has shape (n_slots, 10), got {rows.shape}")

        def whole(columns: Any) -> np.ndarray:
            return np.array(rows[:, columns], dtype=np.int64, order="C")

        valid = rows[:, 1] != 0
        return cls(
            cluster=whole(0),
            valid=valid,
            centroid=np.array(rows[:, 2:4], order="C"),
            target=whole(slice(4, 6)),
            distance=np.array(rows[:, 6]),
            size=whole(8),
            gain=np.array(rows[:, 9]),
            path_length=whole(7),
            mask=np.asarray(mask),
            live=int(np.count_nonzero(valid)),
        )


@dataclass(slots=True)
class SlotArrays:
    """The slots of many robots: the fields of :class:`~frontier_marl.core.slots.SlotTable`
    with leading axes, ``(N, K)`` (world, robot) in a batch or ``(M,)`` for M robots."""

    cluster: np.ndarray  # int (N, K, S)
    valid: np.ndarray  # bool (N, K, S)
    centroid: np.ndarray  # float (N, K, S, 2)
    target: np.ndarray  # int (N, K, S, 2)
    distance: np.ndarray  # float (N, K, S)
    size: np.ndarray  # int (N, K, S)
    gain: np.ndarray  # float (N, K, S)
    path_length: np.ndarray  # int (N, K, S)
    mask: np.ndarray  # int8 (N, K, S)
    live: np.ndarray  # int (N, K)

    @classmethod
    def stack(cls, tables: Sequence[SlotTable]) -> SlotArrays:
        """The tables of M robots as ``(M, ...)`` arrays."""
        fields = {name: np.stack([getattr(t, name) for t in tables]) for name in _FIELDS}
        return cls(**fields, live=np.array([t.live for t in tables], dtype=np.int64))

    def packed(self) -> np.ndarray:
        """The fields as one float64 array ``(..., n_slots, 10)`` in :data:`SLOT_COLUMNS`'s
        order (the mask is left out: it is the action mask)."""
        out = np.empty((*self.cluster.shape, len(SLOT_COLUMNS)))
        _pack(
            self.cluster,
            self.valid,
            self.centroid,
            self.target,
            self.distance,
            self.path_length,
            self.size,
            self.gain,
            out,
        )
        return out

    def table(self, row: int) -> SlotTable:
        """Robot ``row``'s :class:`SlotTable` (views) of ``(M, ...)`` arrays."""
        fields = {name: getattr(self, name)[row] for name in _FIELDS}
        return SlotTable(**fields, live=int(self.live[row]))

    def world(self, index: int) -> SlotArrays:
        """The robots of world ``index`` of a batch as ``(K, ...)`` arrays (views)."""
        fields = {name: getattr(self, name)[index] for name in (*_FIELDS, "live")}
        return SlotArrays(**fields)

    def rows(self, worlds: np.ndarray | slice) -> SlotArrays:
        """The robots of ``worlds`` of a batch as ``(M, ...)`` arrays, world after world."""
        fields = {name: getattr(self, name)[worlds] for name in (*_FIELDS, "live")}
        count = fields["live"].size
        return SlotArrays(
            **{name: value.reshape(count, *value.shape[2:]) for name, value in fields.items()}
        )

    @classmethod
    def empty(cls, n_worlds: int, n_agents: int, n_slots: int) -> SlotArrays:
        """Uninitialised arrays for :meth:`Worlds.slots` to fill."""
        shape = (n_worlds, n_agents, n_slots)
        return cls(
            cluster=np.empty(shape, dtype=np.int64),
            valid=np.empty(shape, dtype=bool),
            centroid=np.empty((*shape, 2)),
            target=np.empty((*shape, 2), dtype=np.int64),
            distance=np.empty(shape),
            size=np.empty(shape, dtype=np.int64),
            gain=np.empty(shape),
            path_length=np.empty(shape, dtype=np.int64),
            mask=np.empty(shape, dtype=np.int8),
            live=np.empty(shape[:2], dtype=np.int64),
        )


@compiled
def _pack(
    cluster: np.ndarray,
    valid: np.ndarray,
    centroid: np.ndarray,
    target: np.ndarray,
    distance: np.ndarray,
    path_length: np.ndarray,
    size: np.ndarray,
    gain: np.ndarray,
    out: np.ndarray,
) -> None:
    """:meth:`SlotArrays.packed` into ``out`` (a C-contiguous ``(..., n_slots, 10)`` array)."""
    rows = out.reshape(-1, out.shape[-1])
    c, v, d, p = cluster.ravel(), valid.ravel(), distance.ravel(), path_length.ravel()
    xy, cell, s, g = centroid.ravel(), target.ravel(), size.ravel(), gain.ravel()
    for i in range(rows.shape[0]):
        rows[i, 0] = c[i]
        rows[i, 1] = v[i]
        rows[i, 2] = xy[2 * i]
        rows[i, 3] = xy[2 * i + 1]
        rows[i, 4] = cell[2 * i]
        rows[i, 5] = cell[2 * i + 1]
        rows[i, 6] = d[i]
        rows[i, 7] = p[i]
        rows[i, 8] = s[i]
        rows[i, 9] = g[i]


def commit_to_previous(
    mask: np.ndarray,
    target: np.ndarray,
    valid: np.ndarray,
    previous: np.ndarray,
    progressed: np.ndarray,
    rule: str = "until-progress",
) -> np.ndarray:
    """Action masks ``(..., S)`` narrowed to the slot of each robot's ``previous`` target cell
    ``(..., 2)`` (row -1: none) where a live slot still holds that target and, for
    ``until-progress``, the robot's last step revealed nothing (``progressed`` False;
    ``until-reached`` keeps it regardless); the other robots' masks unchanged."""
    same = valid & (target == previous[..., None, :]).all(axis=-1) & (previous[..., None, 0] >= 0)
    keep = same.any(axis=-1)
    if rule == "until-progress":
        keep &= ~progressed
    return np.where(keep[..., None], same.astype(mask.dtype), mask)


def robot_slots(
    belief: np.ndarray,
    position: tuple[int, int],
    clusters: Clusters,
    gains: np.ndarray,
    n_slots: int,
    sort_by_distance: bool,
) -> SlotTable:
    """The slots of the robot standing at ``position`` (row, col) on ``belief``."""
    *arrays, live = robot_slot_fields(
        belief,
        int(position[0]),
        int(position[1]),
        clusters.cell_rows,
        clusters.cell_cols,
        clusters.cell_cluster,
        clusters.centroids,
        clusters.sizes,
        gains,
        n_slots,
        sort_by_distance,
    )
    return SlotTable(*arrays, live=live)
