"""Sensor models: which cells a robot at a cell perceives, written into the belief grid.

Both models are idealised (no noise): a perceived cell's belief becomes its true state.

* :class:`SquareSensor` — every cell within Chebyshev distance ``r`` (a (2r+1)^2 window),
  seen through walls.
* :class:`RaycastSensor` — every cell within Euclidean distance ``r`` whose straight line of
  sight from the robot's cell crosses no occupied cell (the occupied cell that blocks a ray is
  itself seen). The visible set of a cell is cached while the grid is one read-only array.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from frontier_marl.core import kernels
from frontier_marl.core.grid import UNKNOWN


class Sensor(Protocol):
    range: int
    #: The sensor as rays for the compiled kernels (:func:`kernels.raycast_reveal`): cell
    #: offsets (K, 2) and, per offset, the offsets that must be free to see it (K, L, 2).
    rays: tuple[np.ndarray, np.ndarray]

    def sense(
        self,
        true_grid: np.ndarray,
        belief: np.ndarray,
        cell: tuple[int, int],
        seen: np.ndarray | None = None,
    ) -> int:
        """Write perceived cells into ``belief``; return how many were unknown before.

        If ``seen`` (bool, grid-shaped) is given, every perceived cell is set True in it.
        """
        ...


class SquareSensor:
    """Chebyshev window of radius ``r``, no occlusion."""

    def __init__(self, perception_range: int) -> None:
        self.range = int(perception_range)
        span = np.arange(-self.range, self.range + 1, dtype=np.int64)
        offsets = np.stack(np.meshgrid(span, span, indexing="ij"), axis=-1).reshape(-1, 2)
        # Nothing occludes: the only cell "between" is the origin, the robot's free cell.
        self.rays = (offsets, np.zeros((len(offsets), 1, 2), dtype=np.int64))

    def window(self, shape: tuple[int, int], cell: tuple[int, int]) -> tuple[slice, slice]:
        row, col = cell
        r = self.range
        return (
            slice(max(0, row - r), min(shape[0], row + r + 1)),
            slice(max(0, col - r), min(shape[1], col + r + 1)),
        )

    def sense(
        self,
        true_grid: np.ndarray,
        belief: np.ndarray,
        cell: tuple[int, int],
        seen: np.ndarray | None = None,
    ) -> int:
        rows, cols = self.window(belief.shape, cell)
        window = belief[rows, cols]
        unknown = window == UNKNOWN
        if seen is not None:
            seen[rows, cols] = True
        count = int(np.count_nonzero(unknown))
        if count:
            window[unknown] = true_grid[rows, cols][unknown]
        return count


class RaycastSensor:
    """Euclidean disc of radius ``r`` with line-of-sight occlusion by occupied cells."""

    #: Visible sets are cached per cell while the true grid stays the same read-only array
    #: (a static map), as long as the cache would hold at most this many cell indices.
    CACHE_LIMIT = 4_000_000

    def __init__(self, perception_range: int) -> None:
        self.range = int(perception_range)
        self._offsets, self._between = _rays(self.range)
        self.rays = (self._offsets, self._between)
        self._cache_grid: np.ndarray | None = None
        self._cache: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}

    def visible_cells(
        self, true_grid: np.ndarray, cell: tuple[int, int]
    ) -> tuple[np.ndarray, np.ndarray]:
        """Row and column indices of the cells perceived from ``cell``."""
        if true_grid.flags.writeable:
            return self._cast(true_grid, cell)
        if true_grid is not self._cache_grid:
            self._cache_grid = true_grid
            self._cache = {}
            if len(self._offsets) * true_grid.size > self.CACHE_LIMIT:
                self._cache_grid = None
        if self._cache_grid is None:
            return self._cast(true_grid, cell)
        found = self._cache.get(cell)
        if found is None:
            found = self._cache[cell] = self._cast(true_grid, cell)
        return found

    def _cast(self, true_grid: np.ndarray, cell: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        height, width = true_grid.shape
        rows = self._offsets[:, 0] + cell[0]
        cols = self._offsets[:, 1] + cell[1]
        inside = (rows >= 0) & (rows < height) & (cols >= 0) & (cols < width)
        rows, cols = rows[inside], cols[inside]
        between = self._between[inside]
        # Cells strictly between the robot and a target lie inside the grid whenever the
        # target does, because they lie inside the bounding box of the two.
        blocked = true_grid[between[..., 0] + cell[0], between[..., 1] + cell[1]].any(axis=1)
        return rows[~blocked], cols[~blocked]

    def sense(
        self,
        true_grid: np.ndarray,
        belief: np.ndarray,
        cell: tuple[int, int],
        seen: np.ndarray | None = None,
    ) -> int:
        if kernels.ENABLED and seen is not None:  # casts the rays itself, no cache needed
            return int(
                kernels.raycast_reveal(
                    true_grid,
                    belief,
                    seen,
                    int(cell[0]),
                    int(cell[1]),
                    self._offsets,
                    self._between,
                )
            )
        rows, cols = self.visible_cells(true_grid, cell)
        if seen is not None:
            seen[rows, cols] = True
        unknown = belief[rows, cols] == UNKNOWN
        count = int(np.count_nonzero(unknown))
        if count:
            rows, cols = rows[unknown], cols[unknown]
            belief[rows, cols] = true_grid[rows, cols]
        return count


def _rays(radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Offsets in the disc, and for each the offsets strictly between it and the origin.

    The in-between lists are padded with the origin (0, 0), which is the robot's own free cell
    and so never blocks.
    """
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
