"""Sensor models: which cells a robot at a cell perceives, written into the belief grid.

Both models are idealised (no noise): a perceived cell's belief becomes its true state. Both are
a set of *rays*: cell offsets, each with the offsets that must be free to see it, cast by one
compiled function, :func:`reveal`.

* :class:`SquareSensor` — every cell within Chebyshev distance ``r`` (a (2r+1)^2 window),
  seen through walls.
* :class:`RaycastSensor` — every cell within Euclidean distance ``r`` whose straight line of
  sight from the robot's cell crosses no occupied cell (the occupied cell that blocks a ray is
  itself seen).
"""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN, new_belief


class Sensor:
    """Rays from the robot's cell: ``offsets`` (K, 2) and, per offset, the offsets that must be
    free to see it, ``between`` (K, L, 2), padded with the origin (the robot's own cell)."""

    range: int
    rays: tuple[np.ndarray, np.ndarray]  # (offsets, between)

    def sense(
        self,
        true_grid: np.ndarray,
        belief: np.ndarray,
        cell: tuple[int, int],
        seen: np.ndarray | None = None,
    ) -> int:
        """Write the cells perceived from ``cell`` into ``belief``; return how many were unknown
        before. If ``seen`` (bool, grid-shaped) is given, every perceived cell is set True."""
        if seen is None:
            seen = np.zeros(true_grid.shape, dtype=bool)
        offsets, between = self.rays
        return int(reveal(true_grid, belief, seen, int(cell[0]), int(cell[1]), offsets, between))

    def visible(self, true_grid: np.ndarray, cell: tuple[int, int]) -> np.ndarray:
        """Bool mask of the cells perceived from ``cell``."""
        seen = np.zeros(true_grid.shape, dtype=bool)
        self.sense(true_grid, new_belief(true_grid.shape), cell, seen)
        return seen


class SquareSensor(Sensor):
    """Chebyshev window of radius ``r``, no occlusion."""

    def __init__(self, perception_range: int) -> None:
        self.range = int(perception_range)
        span = np.arange(-self.range, self.range + 1, dtype=np.int64)
        offsets = np.stack(np.meshgrid(span, span, indexing="ij"), axis=-1).reshape(-1, 2)
        # Nothing occludes: no cell lies "between".
        self.rays = (offsets, np.zeros((len(offsets), 0, 2), dtype=np.int64))


class RaycastSensor(Sensor):
    """Euclidean disc of radius ``r`` with line-of-sight occlusion by occupied cells."""

    def __init__(self, perception_range: int) -> None:
        self.range = int(perception_range)
        self.rays = _rays(self.range)


def _rays(radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Offsets in the disc, and for each the offsets strictly between it and the origin
    (rounded to the nearest cell along the straight line), padded with the origin (0, 0)."""
    span = np.arange(-radius, radius + 1)
    drow, dcol = np.meshgrid(span, span, indexing="ij")
    inside = drow**2 + dcol**2 <= radius * radius
    offsets = np.stack([drow[inside], dcol[inside]], axis=1)
    longest = max(radius - 1, 1)
    between = np.zeros((len(offsets), longest, 2), dtype=np.int64)
    for i, (dr, dc) in enumerate(offsets):
        steps = max(abs(int(dr)), abs(int(dc)))
        for k in range(1, steps):
            t = k / steps
            between[i, k - 1] = (int(np.floor(dr * t + 0.5)), int(np.floor(dc * t + 0.5)))
    return offsets.astype(np.int64), between


def make_sensor(model: str, perception_range: int) -> Sensor:
    """The sensor named ``model`` (``square`` or ``raycast``)."""
    if model == "square":
        return SquareSensor(perception_range)
    if model == "raycast":
        return RaycastSensor(perception_range)
    raise ValueError(f"sensor must be 'square' or 'raycast', got {model!r}")


@compiled
def reveal(
    true_grid: np.ndarray,
    belief: np.ndarray,
    seen: np.ndarray,
    row: int,
    col: int,
    offsets: np.ndarray,
    between: np.ndarray,
) -> int:
    """Sense from (row, col): every offset inside the grid whose in-between cells are all free
    is marked in ``seen`` and written into ``belief``; returns how many of them were unknown.

    Cells between the robot and a target inside the grid lie inside the grid too (inside the
    bounding box of the two)."""
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
