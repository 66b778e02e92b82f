"""Cell codes of the belief grid and small grid helpers shared by the core.

The *true grid* is a boolean array, ``True`` where a cell is occupied.
The *belief grid* is an ``int8`` array holding one of the codes below.
Coordinates are always ``(row, col)``; arrays are indexed ``grid[row, col]``.
"""

from __future__ import annotations

import numpy as np

UNKNOWN: int = -1
FREE: int = 0
OCCUPIED: int = 1

BELIEF_DTYPE = np.int8


def new_belief(shape: tuple[int, int]) -> np.ndarray:
    """An all-unknown belief grid of ``shape``."""
    return np.full(shape, UNKNOWN, dtype=BELIEF_DTYPE)
