"""Cluster slots: which frontier clusters a robot may choose, and in which order.

Rules (open choices of the thesis, documented in docs/thesis-mapping.md):

* A cluster is *live* for a robot when one of its cells is reachable from the robot through
  known-free cells; its navigation target is that reachable cell nearest the centroid.
  Unreachable clusters are dropped (they never get a slot).
* When more live clusters exist than slots, the ``n_slots`` nearest (Euclidean distance from
  the robot to the centroid; ties by cluster index) get a slot.
* The slots shown are ordered by increasing distance (``sort_by_distance``) or by cluster
  index, i.e. raster order of the cluster's first cell. Ordering never changes which clusters
  are selected.
* Slots beyond the live clusters are padding: cluster -1, zero features, masked out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from frontier_marl.core import kernels


@dataclass(frozen=True)
class SlotTable:
    """One robot's slots. Arrays have length ``n_slots``; padding rows hold zeros and -1."""

    cluster: np.ndarray  # int (n,), cluster index or -1 for padding
    valid: np.ndarray  # bool (n,)
    centroid: np.ndarray  # float (n, 2)
    target: np.ndarray  # int (n, 2), -1 for padding
    distance: np.ndarray  # float (n,), Euclidean robot -> centroid
    size: np.ndarray  # int (n,)
    gain: np.ndarray  # float (n,)

    live: int  # how many slots hold a cluster (the first ``live`` ones)

    def action_mask(self) -> np.ndarray:
        """int8 mask of the actions worth taking: the live slots, or slot 0 (idle) if none."""
        mask = self.valid.astype(np.int8)
        if not self.live:
            mask[0] = 1
        return mask


def build_slots(
    position: np.ndarray,
    centroids: np.ndarray,
    sizes: np.ndarray,
    gains: np.ndarray,
    has_target: np.ndarray,
    targets: np.ndarray,
    n_slots: int,
    sort_by_distance: bool,
) -> SlotTable:
    """Select and order the slots of one robot at ``position`` (row, col)."""
    if kernels.ENABLED:
        arrays = kernels.slot_arrays(
            float(position[0]),
            float(position[1]),
            centroids,
            sizes,
            gains,
            has_target,
            targets,
            n_slots,
            sort_by_distance,
        )
        return SlotTable(*arrays, live=int(np.count_nonzero(arrays[1])))
    live, distance = _select_numpy(position, centroids, has_target, n_slots, sort_by_distance)
    centroid_live = centroids[live]
    k = len(live)
    pad = n_slots - k
    valid = np.zeros(n_slots, dtype=bool)
    valid[:k] = True
    return SlotTable(
        cluster=np.concatenate([live, np.full(pad, -1, dtype=np.int64)]),
        valid=valid,
        centroid=np.concatenate([centroid_live, np.zeros((pad, 2))]),
        target=np.concatenate([targets[live], np.full((pad, 2), -1, dtype=np.int64)]),
        distance=np.concatenate([distance, np.zeros(pad)]),
        size=np.concatenate([sizes[live], np.zeros(pad, dtype=np.int64)]),
        gain=np.concatenate([gains[live], np.zeros(pad)]),
        live=k,
    )


def _select_numpy(
    position: np.ndarray,
    centroids: np.ndarray,
    has_target: np.ndarray,
    n_slots: int,
    sort_by_distance: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """(cluster indices, distances) of the slots (the reference of ``kernels.slot_arrays``)."""
    live = np.flatnonzero(has_target)
    distance = np.hypot(centroids[live, 0] - position[0], centroids[live, 1] - position[1])
    if len(live) > n_slots:
        keep = np.sort(np.argsort(distance, kind="stable")[:n_slots])
        live, distance = live[keep], distance[keep]
    if sort_by_distance and len(live) > 1:
        order = np.argsort(distance, kind="stable")
        live, distance = live[order], distance[order]
    return live, distance
