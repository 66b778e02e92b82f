"""Small, obviously correct reference implementations that the compiled core is tested against.

Each one is the definition of its operation written as plainly as possible (sets, deques,
Python loops), with no attempt at speed.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from frontier_marl.core.grid import FREE, UNKNOWN

STEPS = ((-1, 0), (1, 0), (0, -1), (0, 1))


def bfs(passable: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """4-connected shortest path lengths from ``start`` over passable cells (-1: unreachable);
    the start counts as reached."""
    height, width = passable.shape
    dist = np.full((height, width), -1, dtype=np.int64)
    dist[start] = 0
    queue = deque([tuple(start)])
    while queue:
        r, c = queue.popleft()
        for dr, dc in STEPS:
            n = (r + dr, c + dc)
            if 0 <= n[0] < height and 0 <= n[1] < width and passable[n] and dist[n] < 0:
                dist[n] = dist[r, c] + 1
                queue.append(n)
    return dist


def frontier_set(belief: np.ndarray) -> set[tuple[int, int]]:
    """The frontier by definition: known-free cells with an unknown 4-neighbour."""
    height, width = belief.shape
    free = {(r, c) for r in range(height) for c in range(width) if belief[r, c] == FREE}
    unknown = {(r, c) for r in range(height) for c in range(width) if belief[r, c] == UNKNOWN}
    return {(r, c) for r, c in free if any((r + dr, c + dc) in unknown for dr, dc in STEPS)}


def split(cells: list[tuple[int, int]], max_cells: int) -> list[list[int]]:
    """Recursive halving across the longer side of the bounding box (rows on a tie), at its
    midpoint; pieces as sorted index lists, ordered by their first index."""

    def halve(index: list[int]) -> list[list[int]]:
        if len(index) <= max_cells:
            return [index]
        rows = [cells[i][0] for i in index]
        cols = [cells[i][1] for i in index]
        values = rows if max(rows) - min(rows) >= max(cols) - min(cols) else cols
        middle = (min(values) + max(values)) / 2
        low = [i for i, v in zip(index, values, strict=True) if v <= middle]
        high = [i for i, v in zip(index, values, strict=True) if v > middle]
        return halve(low) + halve(high)

    return sorted((sorted(piece) for piece in halve(list(range(len(cells))))), key=min)


def visible(true_grid: np.ndarray, cell: tuple[int, int], radius: int, model: str) -> set:
    """Cells a sensor perceives: the Chebyshev window (``square``), or the Euclidean disc whose
    straight lines of sight (rounded to cells) cross no occupied cell (``raycast``)."""
    height, width = true_grid.shape
    out = set()
    for dr in range(-radius, radius + 1):
        for dc in range(-radius, radius + 1):
            r, c = cell[0] + dr, cell[1] + dc
            if not (0 <= r < height and 0 <= c < width):
                continue
            if model == "square":
                out.add((r, c))
                continue
            if dr * dr + dc * dc > radius * radius:
                continue
            steps = max(abs(dr), abs(dc))
            line = [
                (
                    cell[0] + int(np.floor(dr * k / steps + 0.5)),
                    cell[1] + int(np.floor(dc * k / steps + 0.5)),
                )
                for k in range(1, steps)
            ]
            if not any(true_grid[p] for p in line):
                out.add((r, c))
    return out
