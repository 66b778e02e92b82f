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

import heapq
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
    path = astar_path(passable, True, int(start[0]), int(start[1]), int(goal[0]), int(goal[1]))
    return path if len(path) else None


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
    dist = np.full((height, width), -1, dtype=np.int64)
    queue = np.empty(height * width, dtype=np.int64)
    queue[0] = row * width + col
    dist[row, col] = 0
    head, tail = 0, 1
    while head < tail:
        cell = queue[head]
        head += 1
        r, c = cell // width, cell % width
        d = dist[r, c] + 1
        for nr, nc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
            if 0 <= nr < height and 0 <= nc < width and dist[nr, nc] < 0 and grid[nr, nc] == free:
                dist[nr, nc] = d
                queue[tail] = nr * width + nc
                tail += 1
    return dist


@compiled
def _euclid(d_row: int, d_col: int) -> float:
    # sqrt of an exact integer is correctly rounded: the same value in Python and numba.
    return math.sqrt(d_row * d_row + d_col * d_col)


@compiled
def astar_path(
    grid: np.ndarray, free: Any, s_row: int, s_col: int, g_row: int, g_col: int
) -> np.ndarray:
    """:func:`astar` on the cells where ``grid == free``; (0, 2) if the goal is unreachable.

    Among equal f the deeper node is expanded first (fewer expansions); ties keep push order.
    """
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
