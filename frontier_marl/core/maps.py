"""True-grid generators: pure functions of their arguments and a ``numpy.random.Generator``."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

FOUR_CONNECTED = ndimage.generate_binary_structure(2, 1)


def random_obstacle_map(
    height: int, width: int, obstacle_prob: float, rng: np.random.Generator
) -> np.ndarray:
    """Obstacles drawn independently per cell with probability ``obstacle_prob``.

    Returns a bool array ``(height, width)``, ``True`` = occupied. At least one cell is free.
    """
    grid = rng.random((height, width)) < obstacle_prob
    if grid.all():
        grid[rng.integers(height), rng.integers(width)] = False
    return grid


def largest_free_component(true_grid: np.ndarray) -> np.ndarray:
    """Bool mask of the largest 4-connected component of free cells (ties: lowest label)."""
    labels, count = ndimage.label(~true_grid, structure=FOUR_CONNECTED)
    if count == 0:
        raise ValueError("the map has no free cell")
    sizes = np.bincount(labels.ravel())[1:]
    return labels == (int(np.argmax(sizes)) + 1)


def free_component_of(true_grid: np.ndarray, cell: tuple[int, int]) -> np.ndarray:
    """Bool mask of the 4-connected free component that contains ``cell``."""
    labels, _ = ndimage.label(~true_grid, structure=FOUR_CONNECTED)
    label = labels[cell]
    if label == 0:
        raise ValueError(f"cell {cell} is occupied")
    return labels == label


def sample_start_cells(
    region: np.ndarray, count: int, rng: np.random.Generator
) -> np.ndarray:
    """``count`` distinct cells drawn uniformly from the True cells of ``region``, as (count, 2)."""
    cells = np.argwhere(region)
    if len(cells) < count:
        raise ValueError(
            f"the start region has {len(cells)} free cells, fewer than n_agents={count}"
        )
    chosen = rng.choice(len(cells), size=count, replace=False)
    return cells[chosen].astype(np.int64)
