"""Compiled kernels for the hot spots of one decision step (optional, needs numba).

Each kernel is a loop version of a numpy/scipy reference function elsewhere in the core and
returns bit-identical results (same tie-breaking, same floating-point operations in the same
order); ``tests/test_kernels.py`` checks that on random beliefs and whole episodes. The core
(``frontiers``, ``slots``, ``planning``, ``sensing``, ``world``) calls them instead of its
reference code when :data:`ENABLED` is true:

* numba is installed (``pip install "frontier-marl[fast]"``; the ``train`` extra includes it), and
* the environment variable ``FRONTIER_MARL_NO_NUMBA`` is unset or ``0``.

Clustering itself stays ``scipy.ndimage.label`` in both modes. Without numba the functions
below stay plain Python and the core does not call them.
"""

from __future__ import annotations

import heapq
import math
import os
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np

from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN

F = TypeVar("F", bound=Callable[..., Any])

try:
    import numba

    NUMBA_AVAILABLE = True
except ImportError:  # pragma: no cover - depends on the installation
    numba = None
    NUMBA_AVAILABLE = False

#: True when the core runs the compiled kernels (see the module docstring).
ENABLED: bool = NUMBA_AVAILABLE and os.environ.get("FRONTIER_MARL_NO_NUMBA", "0") in ("", "0")


def _compile(function: F) -> F:
    """``numba.njit`` with an on-disk cache (without one if no cache folder is writable), or
    the plain function without numba."""
    if numba is None:
        return function
    try:
        return numba.njit(cache=True, nogil=True)(function)  # type: ignore[no-any-return]
    except RuntimeError:  # numba found no writable cache location: compile in every process
        return numba.njit(nogil=True)(function)  # type: ignore[no-any-return]


@_compile
def frontier_cells(belief: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mask, rows, cols) of the frontier cells, cells in raster order."""
    height, width = belief.shape
    mask = np.zeros((height, width), dtype=np.bool_)
    rows = np.empty(height * width, dtype=np.int64)
    cols = np.empty(height * width, dtype=np.int64)
    n = 0
    for r in range(height):
        for c in range(width):
            if belief[r, c] != FREE:
                continue
            if (
                (r > 0 and belief[r - 1, c] == UNKNOWN)
                or (r + 1 < height and belief[r + 1, c] == UNKNOWN)
                or (c > 0 and belief[r, c - 1] == UNKNOWN)
                or (c + 1 < width and belief[r, c + 1] == UNKNOWN)
            ):
                mask[r, c] = True
                rows[n] = r
                cols[n] = c
                n += 1
    return mask, rows[:n], cols[:n]


@_compile
def clusters_from_labels(
    image: np.ndarray, rows: np.ndarray, cols: np.ndarray, count: int, max_cells: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cluster index, sizes and centroids of the frontier cells (rows, cols; raster order)
    labelled 1..count in ``image``, clusters above ``max_cells`` (> 0) split."""
    label = np.empty(len(rows), dtype=np.int64)
    for i in range(len(rows)):
        label[i] = image[rows[i], cols[i]] - 1
    if max_cells > 0:
        label, count = split_and_renumber(rows, cols, label, count, max_cells)
    sizes, centroids = cluster_stats(rows, cols, label, count)
    return label, sizes, centroids


@_compile
def split_and_renumber(
    rows: np.ndarray, cols: np.ndarray, label: np.ndarray, count: int, max_cells: int
) -> tuple[np.ndarray, int]:
    """Split clusters above ``max_cells`` (as ``frontiers.split_cells``) and renumber every
    piece in raster order of its first cell. ``label`` is 0-based, cells in raster order.
    Returns the new labels and their count."""
    n = len(label)
    # Group cell indices by cluster (counting sort keeps raster order within a cluster).
    starts = np.zeros(count + 1, dtype=np.int64)
    for i in range(n):
        starts[label[i] + 1] += 1
    for k in range(count):
        starts[k + 1] += starts[k]
    order = np.empty(n, dtype=np.int64)
    fill = starts[:-1].copy()
    for i in range(n):
        order[fill[label[i]]] = i
        fill[label[i]] += 1
    piece = np.empty(n, dtype=np.int64)
    pieces = 0
    stack = np.empty((2 * n + 2, 2), dtype=np.int64)  # segments [lo, hi) of ``order``
    for k in range(count):
        stack[0, 0] = starts[k]
        stack[0, 1] = starts[k + 1]
        top = 1
        while top > 0:
            top -= 1
            lo = stack[top, 0]
            hi = stack[top, 1]
            if hi - lo <= max_cells:
                for j in range(lo, hi):
                    piece[order[j]] = pieces
                pieces += 1
                continue
            r_min = r_max = rows[order[lo]]
            c_min = c_max = cols[order[lo]]
            for j in range(lo + 1, hi):
                r = rows[order[j]]
                c = cols[order[j]]
                r_min = min(r_min, r)
                r_max = max(r_max, r)
                c_min = min(c_min, c)
                c_max = max(c_max, c)
            by_rows = r_max - r_min >= c_max - c_min
            middle = (r_min + r_max) / 2.0 if by_rows else (c_min + c_max) / 2.0
            # Partition the segment: values <= middle first (order inside a piece is
            # irrelevant, pieces are renumbered by their first cell below).
            i = lo
            j = hi - 1
            while i <= j:
                value = rows[order[i]] if by_rows else cols[order[i]]
                if value <= middle:
                    i += 1
                else:
                    order[i], order[j] = order[j], order[i]
                    j -= 1
            stack[top, 0] = lo
            stack[top, 1] = i
            stack[top + 1, 0] = i
            stack[top + 1, 1] = hi
            top += 2
    # Renumber pieces by first appearance in raster order.
    rank = np.full(pieces, -1, dtype=np.int64)
    out = np.empty(n, dtype=np.int64)
    seen = 0
    for i in range(n):
        p = piece[i]
        if rank[p] < 0:
            rank[p] = seen
            seen += 1
        out[i] = rank[p]
    return out, seen


@_compile
def cluster_stats(
    rows: np.ndarray, cols: np.ndarray, cluster: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray]:
    """Sizes (K,) and centroids (K, 2) of clusters numbered 0..count-1."""
    sizes = np.zeros(count, dtype=np.int64)
    sums = np.zeros((count, 2), dtype=np.float64)
    for i in range(len(cluster)):
        k = cluster[i]
        sizes[k] += 1
        sums[k, 0] += rows[i]
        sums[k, 1] += cols[i]
    for k in range(count):
        sums[k, 0] /= sizes[k]
        sums[k, 1] /= sizes[k]
    return sizes, sums


@_compile
def reachable_free(belief: np.ndarray, row: int, col: int) -> np.ndarray:
    """Bool grid of the known-free cells 4-connected to (row, col) (which must be free)."""
    height, width = belief.shape
    reached = np.zeros((height, width), dtype=np.bool_)
    if belief[row, col] != FREE:
        return reached
    queue = np.empty(height * width, dtype=np.int64)
    queue[0] = row * width + col
    reached[row, col] = True
    head, tail = 0, 1
    while head < tail:
        cell = queue[head]
        head += 1
        r, c = cell // width, cell % width
        for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
            nr, nc = r + dr, c + dc
            inside = 0 <= nr < height and 0 <= nc < width
            if inside and not reached[nr, nc] and belief[nr, nc] == FREE:
                reached[nr, nc] = True
                queue[tail] = nr * width + nc
                tail += 1
    return reached


@_compile
def reachable_targets(
    belief: np.ndarray,
    row: int,
    col: int,
    rows: np.ndarray,
    cols: np.ndarray,
    cluster: np.ndarray,
    centroids: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`nearest_targets` over the frontier cells reachable from (row, col)."""
    reached = reachable_free(belief, row, col)
    eligible = np.empty(len(rows), dtype=np.bool_)
    for i in range(len(rows)):
        eligible[i] = reached[rows[i], cols[i]]
    return nearest_targets(rows, cols, cluster, centroids, eligible)


@_compile
def nearest_targets(
    rows: np.ndarray,
    cols: np.ndarray,
    cluster: np.ndarray,
    centroids: np.ndarray,
    eligible: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Per cluster, its eligible cell nearest the centroid (ties: raster order)."""
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


@_compile
def slot_arrays(
    row: float,
    col: float,
    centroids: np.ndarray,
    sizes: np.ndarray,
    gains: np.ndarray,
    has_target: np.ndarray,
    targets: np.ndarray,
    n_slots: int,
    sort: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The fields of ``slots.SlotTable``, selected and padded as ``slots.build_slots`` does."""
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
    cluster = np.full(n_slots, -1, dtype=np.int64)
    valid = np.zeros(n_slots, dtype=np.bool_)
    centroid = np.zeros((n_slots, 2))
    target = np.full((n_slots, 2), -1, dtype=np.int64)
    slot_distance = np.zeros(n_slots)
    size = np.zeros(n_slots, dtype=np.int64)
    gain = np.zeros(n_slots)
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
    return cluster, valid, centroid, target, slot_distance, size, gain


@_compile
def robot_slots(
    belief: np.ndarray,
    row: int,
    col: int,
    rows: np.ndarray,
    cols: np.ndarray,
    cluster: np.ndarray,
    centroids: np.ndarray,
    sizes: np.ndarray,
    gains: np.ndarray,
    n_slots: int,
    sort: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`slot_arrays` of the robot at (row, col), targets from :func:`reachable_targets`."""
    has_target, targets = reachable_targets(belief, row, col, rows, cols, cluster, centroids)
    return slot_arrays(
        float(row), float(col), centroids, sizes, gains, has_target, targets, n_slots, sort
    )


@_compile
def _euclid(d_row: int, d_col: int) -> float:
    # sqrt of an exact integer is correctly rounded: the same value in Python and numba.
    return math.sqrt(d_row * d_row + d_col * d_col)


@_compile
def astar_path(
    grid: np.ndarray, free: Any, s_row: int, s_col: int, g_row: int, g_col: int
) -> np.ndarray:
    """As ``planning.astar`` (same expansion order, same path) on the cells where
    ``grid == free`` (a bool passable grid and True, or a belief and FREE); (0, 2) if the goal
    is unreachable."""
    height, width = grid.shape
    if not (0 <= g_row < height and 0 <= g_col < width) or grid[g_row, g_col] != free:
        return np.empty((0, 2), dtype=np.int64)
    source = s_row * width + s_col
    target = g_row * width + g_col
    if source == target:
        path = np.empty((1, 2), dtype=np.int64)
        path[0, 0] = s_row
        path[0, 1] = s_col
        return path
    cost = np.full(height * width, 1 << 60, dtype=np.int64)
    parent = np.full(height * width, -1, dtype=np.int64)
    cost[source] = 0
    heap = [(_euclid(s_row - g_row, s_col - g_col), 0, source)]
    while heap:
        _, neg_g, cell = heapq.heappop(heap)
        if cell == target:
            length = 1
            walk = target
            while walk != source:
                walk = parent[walk]
                length += 1
            path = np.empty((length, 2), dtype=np.int64)
            walk = target
            for i in range(length - 1, -1, -1):
                path[i, 0] = walk // width
                path[i, 1] = walk % width
                walk = parent[walk]
            return path
        g = -neg_g
        if g > cost[cell]:
            continue
        row, col = cell // width, cell % width
        g_next = g + 1
        for n_row, n_col in ((row - 1, col), (row + 1, col), (row, col - 1), (row, col + 1)):
            if not (0 <= n_row < height and 0 <= n_col < width) or grid[n_row, n_col] != free:
                continue
            neighbour = n_row * width + n_col
            if g_next < cost[neighbour]:
                cost[neighbour] = g_next
                parent[neighbour] = cell
                f = g_next + _euclid(n_row - g_row, n_col - g_col)
                heapq.heappush(heap, (f, -g_next, neighbour))
    return np.empty((0, 2), dtype=np.int64)


@_compile
def count_known(belief: np.ndarray, region: np.ndarray) -> int:
    """Known cells of ``belief`` inside the bool mask ``region``."""
    count = 0
    for r in range(belief.shape[0]):
        for c in range(belief.shape[1]):
            if region[r, c] and belief[r, c] != UNKNOWN:
                count += 1
    return count


@_compile
def raycast_reveal(
    true_grid: np.ndarray,
    belief: np.ndarray,
    seen: np.ndarray,
    row: int,
    col: int,
    offsets: np.ndarray,
    between: np.ndarray,
) -> int:
    """Sense from (row, col) as ``sensing.RaycastSensor`` does: every offset inside the grid
    whose in-between cells (``between``, padded with the origin) are all free is marked in
    ``seen`` and written into ``belief``; returns how many of them were unknown."""
    height, width = true_grid.shape
    count = 0
    for i in range(len(offsets)):
        r = row + offsets[i, 0]
        c = col + offsets[i, 1]
        if not (0 <= r < height and 0 <= c < width):
            continue
        blocked = False
        for k in range(between.shape[1]):
            if true_grid[row + between[i, k, 0], col + between[i, k, 1]]:
                blocked = True
                break
        if blocked:
            continue
        seen[r, c] = True
        if belief[r, c] == UNKNOWN:
            belief[r, c] = OCCUPIED if true_grid[r, c] else FREE
            count += 1
    return count


@_compile
def walk(
    true_grid: np.ndarray,
    belief: np.ndarray,
    seen: np.ndarray,
    positions: np.ndarray,
    travelled: np.ndarray,
    goals: np.ndarray,
    plans: np.ndarray,
    plan_meta: np.ndarray,
    version: int,
    cells_per_step: int,
    offsets: np.ndarray,
    between: np.ndarray,
    new_cells: np.ndarray,
    walked: np.ndarray,
    walked_len: np.ndarray,
    reached: np.ndarray,
) -> int:
    """``World.move`` in one call: plan, walk in sub-steps, sense; returns the new belief
    version.

    State (changed in place): ``belief``, ``seen`` (N, H, W), ``positions`` and ``travelled``;
    the plan cache: ``plans[a, first:end]`` is robot a's remaining path and ``plan_meta[a]`` =
    (goal row, goal col, first, end, belief version planned on; -1 when robot a has no plan).
    ``goals[a]`` is robot a's target, row -1 to stay; ``cells_per_step`` is -1 for the whole
    path. Sensing is :func:`raycast_reveal` with ``offsets``/``between``. Outputs:
    ``new_cells`` (N,), ``walked[a, :walked_len[a]]`` (the cells robot a occupied, start
    included) and ``reached`` (N,).
    """
    n = positions.shape[0]
    first = np.zeros(n, dtype=np.int64)  # index in plans[a] of the next cell to enter
    end = np.zeros(n, dtype=np.int64)  # one past the last cell this step may enter
    path_length = np.zeros(n, dtype=np.int64)  # moves left to the target
    for a in range(n):
        new_cells[a] = 0
        reached[a] = False
        walked[a, 0, 0] = positions[a, 0]
        walked[a, 0, 1] = positions[a, 1]
        walked_len[a] = 1
        goal_row = goals[a, 0]
        goal_col = goals[a, 1]
        if goal_row < 0:
            continue
        row = positions[a, 0]
        col = positions[a, 1]
        start = plan_meta[a, 2]
        cached = (
            plan_meta[a, 4] == version
            and plan_meta[a, 0] == goal_row
            and plan_meta[a, 1] == goal_col
            and plan_meta[a, 3] > start
            and plans[a, start, 0] == row
            and plans[a, start, 1] == col
        )
        if not cached:
            path = astar_path(belief, FREE, row, col, goal_row, goal_col)
            if len(path) == 0:
                plan_meta[a, 4] = -1
                continue
            plans[a, : len(path)] = path
            plan_meta[a, 0] = goal_row
            plan_meta[a, 1] = goal_col
            plan_meta[a, 2] = 0
            plan_meta[a, 3] = len(path)
            plan_meta[a, 4] = version
            start = 0
        path_length[a] = plan_meta[a, 3] - start - 1
        first[a] = start + 1
        end[a] = plan_meta[a, 3]
        if cells_per_step >= 0:
            end[a] = min(end[a], start + 1 + cells_per_step)
    progress = np.zeros(n, dtype=np.int64)
    sub_step = 0
    while cells_per_step < 0 or sub_step < cells_per_step:
        moved = False
        for a in range(n):
            index = first[a] + progress[a]
            if index >= end[a]:
                continue
            row = plans[a, index, 0]
            col = plans[a, index, 1]
            occupied = False
            for b in range(n):
                if b != a and positions[b, 0] == row and positions[b, 1] == col:
                    occupied = True
                    break
            if occupied:  # wait; the path is kept
                continue
            positions[a, 0] = row
            positions[a, 1] = col
            walked[a, walked_len[a], 0] = row
            walked[a, walked_len[a], 1] = col
            walked_len[a] += 1
            progress[a] += 1
            count = raycast_reveal(true_grid, belief, seen[a], row, col, offsets, between)
            if count:
                version += 1
            new_cells[a] += count
            moved = True
        sub_step += 1
        if not moved:
            break
    for a in range(n):
        if progress[a]:
            plan_meta[a, 2] += progress[a]
        travelled[a] += progress[a]
        reached[a] = path_length[a] > 0 and path_length[a] == progress[a]
    return version
