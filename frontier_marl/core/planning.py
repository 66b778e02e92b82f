"""Grid path planning: A* (4-connected, unit cost, Euclidean heuristic) and BFS distance fields.

The Euclidean heuristic never overestimates the 4-connected path length and is consistent,
so A* returns a shortest path whenever one exists. With numba, :func:`astar` runs the compiled
``kernels.astar_path``, which expands the same cells in the same order.
"""

from __future__ import annotations

import heapq
import math
from collections import deque

import numpy as np

from frontier_marl.core import kernels


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
    if kernels.ENABLED:
        path = kernels.astar_path(
            passable, True, int(start[0]), int(start[1]), int(goal[0]), int(goal[1])
        )
        return path if len(path) else None
    return astar_python(passable, start, goal)


def astar_python(
    passable: np.ndarray, start: tuple[int, int], goal: tuple[int, int]
) -> np.ndarray | None:
    """The pure-Python :func:`astar` (the reference of ``kernels.astar_path``)."""
    passable = np.asarray(passable, dtype=bool)
    height, width = passable.shape
    s_row, s_col = int(start[0]), int(start[1])
    g_row, g_col = int(goal[0]), int(goal[1])
    if not (0 <= g_row < height and 0 <= g_col < width) or not passable[g_row, g_col]:
        return None
    source, target = s_row * width + s_col, g_row * width + g_col
    if source == target:
        return np.array([[s_row, s_col]], dtype=np.int64)
    free = passable.tobytes()
    sqrt = math.sqrt  # of an exact integer: the same heuristic value as the kernel's
    cost = {source: 0}
    parent = {source: -1}
    # Entries are (f, -g, cell): among equal f, deeper nodes first (fewer expansions).
    heap = [(sqrt((s_row - g_row) ** 2 + (s_col - g_col) ** 2), 0, source)]
    pop, push = heapq.heappop, heapq.heappush
    while heap:
        _, neg_g, cell = pop(heap)
        if cell == target:
            return _trace(parent, target, width)
        g = -neg_g
        if g > cost[cell]:
            continue
        row, col = divmod(cell, width)
        g_next = g + 1
        for n_row, n_col, neighbour in (
            (row - 1, col, cell - width),
            (row + 1, col, cell + width),
            (row, col - 1, cell - 1),
            (row, col + 1, cell + 1),
        ):
            if not (0 <= n_row < height and 0 <= n_col < width) or not free[neighbour]:
                continue
            if g_next < cost.get(neighbour, 1 << 60):
                cost[neighbour] = g_next
                parent[neighbour] = cell
                h = sqrt((n_row - g_row) ** 2 + (n_col - g_col) ** 2)
                push(heap, (g_next + h, -g_next, neighbour))
    return None


def _trace(parent: dict[int, int], target: int, width: int) -> np.ndarray:
    cells = []
    cell = target
    while cell != -1:
        cells.append(divmod(cell, width))
        cell = parent[cell]
    cells.reverse()
    return np.array(cells, dtype=np.int64)


def bfs_distances(passable: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """Shortest 4-connected path length from ``start`` to every cell; -1 where unreachable."""
    passable = np.asarray(passable, dtype=bool)
    height, width = passable.shape
    dist = np.full(height * width, -1, dtype=np.int64)
    free = passable.tobytes()
    source = int(start[0]) * width + int(start[1])
    dist[source] = 0
    queue = deque([source])
    seen = dist.tolist()
    while queue:
        cell = queue.popleft()
        row, col = divmod(cell, width)
        d = seen[cell] + 1
        for n_row, n_col, neighbour in (
            (row - 1, col, cell - width),
            (row + 1, col, cell + width),
            (row, col - 1, cell - 1),
            (row, col + 1, cell + 1),
        ):
            inside = 0 <= n_row < height and 0 <= n_col < width
            if inside and free[neighbour] and seen[neighbour] < 0:
                seen[neighbour] = d
                queue.append(neighbour)
    return np.array(seen, dtype=np.int64).reshape(height, width)
