"""The compiled loops of :class:`~frontier_marl.core.worlds.Worlds` over a batch of worlds: the
walk of every robot, the end of a recluster, the slots of every robot, the known-cell counts.
Each calls the one implementation of its operation for world after world."""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.grid import FREE, UNKNOWN
from frontier_marl.core.movement import walk
from frontier_marl.core.slot_kernels import fill_robot_slots
from frontier_marl.core.slots import _pack


@compiled
def walk_worlds(
    active: np.ndarray,
    true: np.ndarray,
    belief: np.ndarray,
    seen: np.ndarray,
    positions: np.ndarray,
    travelled: np.ndarray,
    goals: np.ndarray,
    plan_cells: np.ndarray,
    plan_meta: np.ndarray,
    version: np.ndarray,
    cells_per_step: int,
    offsets: np.ndarray,
    between: np.ndarray,
    new_cells: np.ndarray,
    walked: np.ndarray,
    walked_len: np.ndarray,
    reached: np.ndarray,
    search: tuple,
) -> None:
    """:func:`~frontier_marl.core.movement.walk` for every active world (``search``: the
    planner's scratch, shared by the worlds)."""
    for n in range(len(active)):
        if not active[n]:
            continue
        version[n] = walk(
            true[n],
            belief[n],
            seen[n],
            positions[n],
            travelled[n],
            goals[n],
            plan_cells[n],
            plan_meta[n],
            version[n],
            cells_per_step,
            offsets,
            between,
            new_cells[n],
            walked[n],
            walked_len[n],
            reached[n],
            search,
        )


@compiled
def settle_clusters(
    stale: np.ndarray,
    by_size: bool,
    sizes: np.ndarray,
    n_clusters: np.ndarray,
    version: np.ndarray,
    gains: np.ndarray,
    clustered_version: np.ndarray,
) -> None:
    """The end of a recluster of the ``stale`` worlds: their clusters' gains are their sizes
    (``by_size``; otherwise they are set already) and they are clustered as of ``version``."""
    for n in stale:
        if by_size:
            gains[n, : n_clusters[n]] = sizes[n, : n_clusters[n]]
        clustered_version[n] = version[n]


@compiled
def all_slots(
    worlds: np.ndarray,
    belief: np.ndarray,
    positions: np.ndarray,
    cell_rows: np.ndarray,
    cell_cols: np.ndarray,
    cell_cluster: np.ndarray,
    n_cells: np.ndarray,
    centroids: np.ndarray,
    sizes: np.ndarray,
    gains: np.ndarray,
    n_clusters: np.ndarray,
    sort: bool,
    cluster: np.ndarray,
    valid: np.ndarray,
    centroid: np.ndarray,
    target: np.ndarray,
    distance: np.ndarray,
    size: np.ndarray,
    gain: np.ndarray,
    path_length: np.ndarray,
    mask: np.ndarray,
    live: np.ndarray,
    packed: np.ndarray,
) -> None:
    """:func:`~frontier_marl.core.slot_kernels.fill_robot_slots` of every robot of ``worlds``,
    into the outputs, and the same slots packed
    (:meth:`~frontier_marl.core.slots.SlotArrays.packed`) into ``packed`` (N, K, S, 10)."""
    field = np.empty(belief.shape[1:], dtype=np.int64)  # the distance fields' scratch
    queue = np.empty(belief.shape[1] * belief.shape[2], dtype=np.int64)
    for n in worlds:
        cells, count = n_cells[n], n_clusters[n]
        for k in range(positions.shape[1]):
            live[n, k] = fill_robot_slots(
                belief[n],
                positions[n, k, 0],
                positions[n, k, 1],
                cell_rows[n, :cells],
                cell_cols[n, :cells],
                cell_cluster[n, :cells],
                centroids[n, :count],
                sizes[n, :count],
                gains[n, :count],
                sort,
                field,
                queue,
                cluster[n, k],
                valid[n, k],
                centroid[n, k],
                target[n, k],
                distance[n, k],
                size[n, k],
                gain[n, k],
                path_length[n, k],
                mask[n, k],
            )
            _pack(
                cluster[n, k], valid[n, k], centroid[n, k], target[n, k], distance[n, k],
                path_length[n, k], size[n, k], gain[n, k], packed[n, k],
            )  # fmt: skip


@compiled
def count_known(belief: np.ndarray, region: np.ndarray) -> np.ndarray:
    """Per world, the known cells of ``belief`` inside the bool mask ``region``."""
    out = np.zeros(belief.shape[0], dtype=np.int64)
    for n in range(belief.shape[0]):
        count = 0
        for r in range(belief.shape[1]):
            for c in range(belief.shape[2]):
                if region[n, r, c] and belief[n, r, c] != UNKNOWN:
                    count += 1
        out[n] = count
    return out


@compiled
def count_states(belief: np.ndarray, free_only: bool) -> np.ndarray:
    """Per world, the known cells of ``belief`` (the free ones only with ``free_only``)."""
    out = np.zeros(belief.shape[0], dtype=np.int64)
    for n in range(belief.shape[0]):
        count = 0
        for r in range(belief.shape[1]):
            for c in range(belief.shape[2]):
                state = belief[n, r, c]
                if state == FREE if free_only else state != UNKNOWN:
                    count += 1
        out[n] = count
    return out
