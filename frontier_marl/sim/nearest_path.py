"""Nearest-path's next target in one compiled call, for the rollouts of
:mod:`frontier_marl.sim.rollouts`.

:func:`nearest_path_goal` makes the robot's frontier clusters as
:meth:`~frontier_marl.core.worlds.Worlds.refresh_clusters` makes them, but labelled by a
union-find over the frontier cells alone (numbered as ``scipy.ndimage.label`` numbers them),
from a frontier mask the caller keeps up to date where the belief changed (both in
:mod:`frontier_marl.core.frontier_union`). It finds the slot nearest by path with a
breadth-first search that stops as soon as the answer is sure; when it cannot be, it builds
the slots as the env does (:func:`~frontier_marl.core.slot_kernels.robot_slot_fields`) and takes
:func:`nearest_path` of them.
"""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontier_union import label_frontier_cells, update_frontier
from frontier_marl.core.frontiers import cluster_stats, split_and_renumber
from frontier_marl.core.grid import FREE
from frontier_marl.core.slot_kernels import nearest_targets, robot_slot_fields


class DecisionScratch:
    """The scratch of :func:`nearest_path_goal` for grids of ``shape``, made once per batch
    of rollouts: four int64 buffers of a cell each, an (H, W) grid and a flat buffer that
    hold -1 between calls, and the frontier mask of the world being decided with its
    per-row counts (:func:`start_frontier`, then
    :func:`~frontier_marl.core.frontier_union.update_frontier` where its belief changed)."""

    def __init__(self, shape: tuple[int, int]) -> None:
        cells = shape[0] * shape[1]
        self.buffers = tuple(np.empty(cells, dtype=np.int64) for _ in range(4))
        self.owner = np.full(shape, -1, dtype=np.int64)
        self.distance = np.full(cells, -1, dtype=np.int64)
        self.frontier = np.zeros(shape, dtype=np.bool_)
        self.row_count = np.zeros(shape[0], dtype=np.int64)

    def arrays(self) -> tuple[np.ndarray, ...]:
        """(rows, cols, label, parent, owner grid, distance, frontier, row counts), in that
        order."""
        return (*self.buffers, self.owner, self.distance, self.frontier, self.row_count)


@compiled
def start_frontier(belief: np.ndarray, scratch: tuple) -> None:
    """Make the frontier mask of ``scratch`` (:meth:`DecisionScratch.arrays`) that of
    ``belief``, from scratch."""
    frontier, row_count = scratch[6], scratch[7]
    frontier[:] = False
    row_count[:] = 0
    update_frontier(belief, frontier, row_count, 0, belief.shape[0], 0, belief.shape[1])


@compiled
def nearest_path(
    valid: np.ndarray, target: np.ndarray, distance: np.ndarray, path_length: np.ndarray
) -> np.ndarray:
    """The target of the live slot of shortest path (ties: nearest centroid, lower slot);
    (-1, -1) if none is live."""
    best = -1
    for s in range(len(valid)):
        if not valid[s]:
            continue
        if (
            best < 0
            or path_length[s] < path_length[best]
            or (path_length[s] == path_length[best] and distance[s] < distance[best])
        ):
            best = s
    out = np.full(2, -1, dtype=np.int64)
    if best >= 0:
        out[0] = target[best, 0]
        out[1] = target[best, 1]
    return out


@compiled
def nearest_path_goal(
    belief: np.ndarray,
    row: int,
    col: int,
    connectivity: int,
    max_cluster_cells: int,
    n_slots: int,
    scratch: tuple,
) -> np.ndarray:
    """:class:`NearestPathBase`'s target for the robot at (row, col) on ``belief``: its
    frontier clusters as :meth:`Worlds.refresh_clusters` makes them (labelled by
    :func:`~frontier_marl.core.frontier_union.label_frontier_cells`, split above
    ``max_cluster_cells``), its slots, the nearest by path; (-1, -1) if none is live.
    ``scratch``: :meth:`DecisionScratch.arrays`, its frontier mask that of ``belief``."""
    rows, cols, label, parent, index, distance, frontier, row_count = scratch
    cells, count = label_frontier_cells(
        frontier, row_count, connectivity, rows, cols, label, parent, index
    )
    cell_rows, cell_cols, cluster = rows[:cells], cols[:cells], label[:cells]
    if max_cluster_cells > 0 and cells > 0:
        cluster, count = split_and_renumber(
            cell_rows, cell_cols, cluster.copy(), count, max_cluster_cells
        )
    sizes, centroids = cluster_stats(cell_rows, cell_cols, cluster, count)
    if count <= n_slots:  # every live cluster gets a slot: a bounded search decides
        goal = _nearest_by_bounded_search(
            belief, row, col, cell_rows, cell_cols, cluster, centroids, parent, index, distance
        )
        if goal[0] != -2:
            return goal
    result = robot_slot_fields(
        belief, row, col, cell_rows, cell_cols, cluster, centroids, sizes,
        sizes.astype(np.float64), n_slots, False,
    )  # fmt: skip
    return nearest_path(result[1], result[3], result[4], result[7])


@compiled
def _nearest_by_bounded_search(
    belief: np.ndarray,
    row: int,
    col: int,
    cell_rows: np.ndarray,
    cell_cols: np.ndarray,
    cluster: np.ndarray,
    centroids: np.ndarray,
    queue: np.ndarray,
    owner: np.ndarray,
    distance: np.ndarray,
) -> np.ndarray:
    """:func:`_nearest_path` of the slots of every cluster, found by a breadth-first search
    from (row, col) that stops as soon as the answer is sure; (-2, -2) when it cannot be
    (the caller then builds the slots). ``queue``/``distance`` (H*W; ``distance`` all -1) and
    ``owner`` ((H, W), all -1) are scratch, left as found.

    A cluster's slot target is its reachable cell nearest the centroid. Its cell nearest the
    centroid of all, once the search reaches it, is that target, at a known path length. A
    cluster none of whose cells the search has reached has its target further than the
    search has gone. So once every cell within the best known path length is reached and
    every cluster is one of those two kinds, the best is the answer. A cluster reached, but
    not at that cell, may have it unreachable and its target nearer: then the search goes on,
    and if it ends so, it cannot decide."""
    height, width = belief.shape
    count = len(centroids)
    has, nearest = nearest_targets(
        cell_rows, cell_cols, cluster, centroids, np.ones(len(cluster), dtype=np.bool_)
    )
    star = np.where(has, nearest[:, 0] * width + nearest[:, 1], -1)
    for i in range(len(cluster)):
        owner[cell_rows[i], cell_cols[i]] = cluster[i]
    hit = np.zeros(count, dtype=np.bool_)
    settled = np.zeros(count, dtype=np.bool_)
    unsure = 0  # clusters reached, but not at their star cell
    best, best_path, best_distance = -1, 0, 0.0
    queue[0] = row * width + col
    distance[queue[0]] = 0
    head, tail = 0, 1
    while head < tail:
        if best >= 0 and unsure == 0 and distance[queue[head]] > best_path:
            break
        cell = queue[head]
        head += 1
        r, c = cell // width, cell % width
        k = owner[r, c]
        if k >= 0:
            before = hit[k] and not settled[k]
            hit[k] = True
            if cell == star[k]:
                settled[k] = True
                d = distance[cell]
                gap = np.hypot(centroids[k, 0] - row, centroids[k, 1] - col)
                if best < 0 or d < best_path or (d == best_path and (
                    gap < best_distance or (gap == best_distance and k < best)
                )):  # fmt: skip
                    best, best_path, best_distance = k, d, gap
            unsure += (hit[k] and not settled[k]) - before
        d = distance[cell] + 1
        # the neighbours written out: faster than a loop over a tuple of them
        if r > 0 and distance[cell - width] < 0 and belief[r - 1, c] == FREE:
            distance[cell - width] = d
            queue[tail] = cell - width
            tail += 1
        if r + 1 < height and distance[cell + width] < 0 and belief[r + 1, c] == FREE:
            distance[cell + width] = d
            queue[tail] = cell + width
            tail += 1
        if c > 0 and distance[cell - 1] < 0 and belief[r, c - 1] == FREE:
            distance[cell - 1] = d
            queue[tail] = cell - 1
            tail += 1
        if c + 1 < width and distance[cell + 1] < 0 and belief[r, c + 1] == FREE:
            distance[cell + 1] = d
            queue[tail] = cell + 1
            tail += 1
    for i in range(tail):
        distance[queue[i]] = -1
    for i in range(len(cluster)):
        owner[cell_rows[i], cell_cols[i]] = -1
    out = np.full(2, -2, dtype=np.int64)
    if unsure == 0:
        out[:] = -1
        if best >= 0:
            out[0] = star[best] // width
            out[1] = star[best] % width
    return out
