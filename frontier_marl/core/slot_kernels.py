"""The compiled slot table of one robot: which frontier clusters it can reach, their targets
and path lengths from one distance field, the nearest ``n_slots`` of them, in order, padded
(the fields of :class:`~frontier_marl.core.slots.SlotTable`, see that module for the rules).
"""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.grid import FREE
from frontier_marl.core.planning import fill_distance_field


@compiled
def nearest_targets(
    rows: np.ndarray,
    cols: np.ndarray,
    cluster: np.ndarray,
    centroids: np.ndarray,
    eligible: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Per cluster, its eligible cell nearest the centroid (ties: raster order).

    Returns ``(has_target, targets)``: bool (K,) and int (K, 2) cells (rows of -1 where none).
    """
    count = len(centroids)
    has_target = np.zeros(count, dtype=np.bool_)
    targets = np.full((count, 2), -1, dtype=np.int64)
    best = np.full(count, np.inf)
    for i in range(len(cluster)):
        if not eligible[i]:
            continue
        k = cluster[i]
        d_row = rows[i] - centroids[k, 0]
        d_col = cols[i] - centroids[k, 1]
        dist2 = d_row * d_row + d_col * d_col
        if dist2 < best[k]:
            best[k] = dist2
            has_target[k] = True
            targets[k, 0] = rows[i]
            targets[k, 1] = cols[i]
    return has_target, targets


@compiled
def robot_slot_fields(
    belief: np.ndarray,
    row: int,
    col: int,
    rows: np.ndarray,
    cols: np.ndarray,
    cell_cluster: np.ndarray,
    centroids: np.ndarray,
    sizes: np.ndarray,
    gains: np.ndarray,
    n_slots: int,
    sort: bool,
) -> tuple[
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    np.ndarray,
    int,
]:
    """The slot table's fields for the robot at (row, col), in fresh arrays
    (:func:`fill_robot_slots`)."""
    cluster = np.empty(n_slots, dtype=np.int64)
    valid = np.empty(n_slots, dtype=np.bool_)
    centroid = np.empty((n_slots, 2))
    target = np.empty((n_slots, 2), dtype=np.int64)
    slot_distance = np.empty(n_slots)
    size = np.empty(n_slots, dtype=np.int64)
    gain = np.empty(n_slots)
    path_length = np.empty(n_slots, dtype=np.int64)
    mask = np.empty(n_slots, dtype=np.int8)
    live = fill_robot_slots(
        belief, row, col, rows, cols, cell_cluster, centroids, sizes, gains, sort,
        np.empty(belief.shape, dtype=np.int64), np.empty(belief.size, dtype=np.int64),
        cluster, valid, centroid, target, slot_distance, size, gain, path_length, mask,
    )  # fmt: skip
    return cluster, valid, centroid, target, slot_distance, size, gain, path_length, mask, live


@compiled
def fill_robot_slots(
    belief: np.ndarray,
    row: int,
    col: int,
    rows: np.ndarray,
    cols: np.ndarray,
    cell_cluster: np.ndarray,
    centroids: np.ndarray,
    sizes: np.ndarray,
    gains: np.ndarray,
    sort: bool,
    field: np.ndarray,
    queue: np.ndarray,
    cluster: np.ndarray,
    valid: np.ndarray,
    centroid: np.ndarray,
    target: np.ndarray,
    slot_distance: np.ndarray,
    size: np.ndarray,
    gain: np.ndarray,
    path_length: np.ndarray,
    mask: np.ndarray,
) -> int:
    """The slot table's fields for the robot at (row, col) into the given arrays (their
    length is the number of slots; ``field`` (H, W) and ``queue`` (H W,) are scratch); returns
    the number of live slots. Reachability and path lengths come from one distance field,
    then targets, selection of the nearest, order, padding."""
    n_slots = len(cluster)
    fill_distance_field(belief, FREE, row, col, field, queue)
    eligible = np.empty(len(rows), dtype=np.bool_)
    for i in range(len(rows)):
        eligible[i] = field[rows[i], cols[i]] >= 0
    has_target, targets = nearest_targets(rows, cols, cell_cluster, centroids, eligible)
    live = np.flatnonzero(has_target)
    distance = np.empty(len(live))
    for i in range(len(live)):
        distance[i] = np.hypot(centroids[live[i], 0] - row, centroids[live[i], 1] - col)
    if len(live) > n_slots:
        keep = np.sort(np.argsort(distance, kind="mergesort")[:n_slots])
        live = live[keep]
        distance = distance[keep]
    if sort and len(live) > 1:
        order = np.argsort(distance, kind="mergesort")
        live = live[order]
        distance = distance[order]
    cluster[:] = -1
    valid[:] = False
    centroid[:] = 0.0
    target[:] = -1
    slot_distance[:] = 0.0
    size[:] = 0
    gain[:] = 0.0
    path_length[:] = -1
    for slot in range(len(live)):
        k = live[slot]
        cluster[slot] = k
        valid[slot] = True
        centroid[slot, 0] = centroids[k, 0]
        centroid[slot, 1] = centroids[k, 1]
        target[slot, 0] = targets[k, 0]
        target[slot, 1] = targets[k, 1]
        slot_distance[slot] = distance[slot]
        size[slot] = sizes[k]
        gain[slot] = gains[k]
        path_length[slot] = field[targets[k, 0], targets[k, 1]]
    mask[:] = 0
    mask[: len(live)] = 1
    if len(live) == 0:
        mask[0] = 1
    return len(live)
