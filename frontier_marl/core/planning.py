"""Shortest paths on the grid: A* paths and BFS distance fields (4-connected, unit cost).

The one family of shortest-path routines of the project: the world plans with :func:`astar`
and finds reachable targets with :func:`distance_field`; the heuristics and metrics measure path
lengths with :func:`distance_field` / :func:`distance_fields`. A* uses the Euclidean heuristic,
which never overestimates the 4-connected path length and is consistent, so it returns a
shortest path whenever one exists; the paths and distances of both routines agree.

Both run on the cells where ``grid == free``: a bool passable grid with ``free=True``, or a belief
grid with ``free=FREE``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from frontier_marl.core.compiled import compiled


def astar(passable: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> np.ndarray | None:
    """A shortest 4-connected path from ``start`` to ``goal`` through passable cells.

    Args:
        passable: bool grid, True where the robot may stand. ``start`` need not be passable.
        start, goal: (row, col) cells.

    Returns:
        int array (L, 2) of cells from ``start`` to ``goal`` inclusive, or ``None`` if the goal
        is unreachable (or not passable).
    """
    passable = np.asarray(passable, dtype=bool)
    out = np.empty((passable.size, 2), dtype=np.int64)
    length = astar_into(
        passable, True, int(start[0]), int(start[1]), int(goal[0]), int(goal[1]), out,
        path_search_scratch(passable.shape),
    )  # fmt: skip
    return out[:length].copy() if length else None


def distance_fields(passable: np.ndarray, sources: Sequence[tuple[int, int]]) -> np.ndarray:
    """(len(sources), H, W) :func:`distance_field` of each source over the ``passable`` cells."""
    passable = np.asarray(passable, dtype=bool)
    fields = np.empty((len(sources), *passable.shape), dtype=np.int64)
    for i, (row, col) in enumerate(sources):
        fields[i] = distance_field(passable, True, int(row), int(col))
    return fields


@compiled
def distance_field(grid: np.ndarray, free: Any, row: int, col: int) -> np.ndarray:
    """Shortest 4-connected path length from (row, col) to every cell where ``grid == free``
    (int64, -1 where unreachable); the source counts as reached even where it is not free."""
    height, width = grid.shape
    dist = np.empty((height, width), dtype=np.int64)
    fill_distance_field(grid, free, row, col, dist, np.empty(height * width, dtype=np.int64))
    return dist


@compiled
def fill_distance_field(
    grid: np.ndarray, free: Any, row: int, col: int, dist: np.ndarray, queue: np.ndarray
) -> None:
    """:func:`distance_field` into ``dist`` (H, W), with ``queue`` (H W,) as scratch."""
    height, width = grid.shape
    dist[:] = -1
    queue[0] = row * width + col
    dist[row, col] = 0
    head, tail = 0, 1
    while head < tail:  # the neighbours written out: faster than a loop over a tuple of them
        cell = queue[head]
        head += 1
        r, c = cell // width, cell % width
        d = dist[r, c] + 1
        if r > 0 and dist[r - 1, c] < 0 and grid[r - 1, c] == free:
            dist[r - 1, c] = d
            queue[tail] = cell - width
            tail += 1
        if r + 1 < height and dist[r + 1, c] < 0 and grid[r + 1, c] == free:
            dist[r + 1, c] = d
            queue[tail] = cell + width
            tail += 1
        if c > 0 and dist[r, c - 1] < 0 and grid[r, c - 1] == free:
            dist[r, c - 1] = d
            queue[tail] = cell - 1
            tail += 1
        if c + 1 < width and dist[r, c + 1] < 0 and grid[r, c + 1] == free:
            dist[r, c + 1] = d
            queue[tail] = cell + 1
            tail += 1


@compiled
def _euclid(d_row: int, d_col: int) -> float:
    # sqrt of an exact integer is correctly rounded: the same value in Python and numba.
    return math.sqrt(d_row * d_row + d_col * d_col)


UNSEEN = 1 << 60  # the cost of a cell the search has not reached


def path_search_scratch(shape: tuple[int, int]) -> tuple[np.ndarray, ...]:
    """The reusable buffers of :func:`astar_into` for grids of ``shape``: per cell its cost
    (all :data:`UNSEEN` between searches), parent and the list of cells a search touched, and
    a binary heap (f, -g, cell) with room for every push a search can make."""
    cells = shape[0] * shape[1]
    pushes = 4 * cells + 1  # a push per relaxed edge, and the source
    return (
        np.full(cells, UNSEEN, dtype=np.int64),
        np.empty(cells, dtype=np.int64),
        np.empty(cells, dtype=np.int64),
        np.empty(pushes, dtype=np.float64),
        np.empty(pushes, dtype=np.int64),
        np.empty(pushes, dtype=np.int64),
    )


@compiled
def astar_into(
    grid: np.ndarray,
    free: Any,
    s_row: int,
    s_col: int,
    g_row: int,
    g_col: int,
    out: np.ndarray,
    scratch: tuple,
) -> int:
    """:func:`astar` on the cells where ``grid == free``, written to ``out[:length]`` (the
    cells from start to goal); returns ``length``, 0 if the goal is unreachable. ``scratch``:
    :func:`path_search_scratch` of the grid's shape, left as found.

    Nodes leave the heap in order of (f, -g, cell): among equal f the deeper node first (fewer
    expansions), then the lower cell index.
    """
    height, width = grid.shape
    if not (0 <= g_row < height and 0 <= g_col < width) or grid[g_row, g_col] != free:
        return 0
    source = s_row * width + s_col
    target = g_row * width + g_col
    if source == target:
        out[0, 0] = s_row
        out[0, 1] = s_col
        return 1
    cost, parent, touched, heap_f, heap_g, heap_cell = scratch
    cost[source] = 0
    touched[0] = source
    n_touched = 1
    heap_f[0] = _euclid(s_row - g_row, s_col - g_col)
    heap_g[0] = 0
    heap_cell[0] = source
    size = 1
    length = 0
    while size > 0:
        neg_g, cell = heap_g[0], heap_cell[0]
        size -= 1
        _sift_down(heap_f, heap_g, heap_cell, size)
        if cell == target:
            length = 1
            walk = target
            while walk != source:
                walk = parent[walk]
                length += 1
            walk = target
            for i in range(length - 1, -1, -1):
                out[i, 0] = walk // width
                out[i, 1] = walk % width
                walk = parent[walk]
            break
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
                if cost[neighbour] == UNSEEN:
                    touched[n_touched] = neighbour
                    n_touched += 1
                cost[neighbour] = g_next
                parent[neighbour] = cell
                f = g_next + _euclid(n_row - g_row, n_col - g_col)
                _push(heap_f, heap_g, heap_cell, size, f, -g_next, neighbour)
                size += 1
    for i in range(n_touched):
        cost[touched[i]] = UNSEEN
    return length


@compiled
def _before(f: float, g: int, cell: int, f2: float, g2: int, cell2: int) -> bool:
    """(f, g, cell) < (f2, g2, cell2), as tuples compare."""
    if f != f2:
        return f < f2
    if g != g2:
        return g < g2
    return cell < cell2


@compiled
def _push(
    heap_f: np.ndarray, heap_g: np.ndarray, heap_cell: np.ndarray, size: int,
    f: float, g: int, cell: int,
) -> None:  # fmt: skip
    """Add (f, g, cell) to the heap of ``size`` entries."""
    i = size
    while i > 0:
        up = (i - 1) >> 1
        if not _before(f, g, cell, heap_f[up], heap_g[up], heap_cell[up]):
            break
        heap_f[i], heap_g[i], heap_cell[i] = heap_f[up], heap_g[up], heap_cell[up]
        i = up
    heap_f[i], heap_g[i], heap_cell[i] = f, g, cell


@compiled
def _sift_down(heap_f: np.ndarray, heap_g: np.ndarray, heap_cell: np.ndarray, size: int) -> None:
    """After the top was taken: move the last entry (now at ``size``) down from the top of the
    heap of ``size`` entries."""
    if size == 0:
        return
    f, g, cell = heap_f[size], heap_g[size], heap_cell[size]
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        right = child + 1
        if right < size and _before(
            heap_f[right], heap_g[right], heap_cell[right],
            heap_f[child], heap_g[child], heap_cell[child],
        ):  # fmt: skip
            child = right
        if not _before(heap_f[child], heap_g[child], heap_cell[child], f, g, cell):
            break
        heap_f[i], heap_g[i], heap_cell[i] = heap_f[child], heap_g[child], heap_cell[child]
        i = child
    heap_f[i], heap_g[i], heap_cell[i] = f, g, cell
