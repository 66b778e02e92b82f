"""The frontier as a mask kept up to date where the belief changed, labelled by a union-find
over its cells: the rollouts' compiled equivalent of
:func:`~frontier_marl.core.frontiers.frontier_mask` and ``scipy.ndimage.label`` (the env keeps
scipy's labelling, the design card's clustering)."""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontiers import is_frontier


@compiled
def update_frontier(
    belief: np.ndarray,
    frontier: np.ndarray,
    row_count: np.ndarray,
    r0: int,
    r1: int,
    c0: int,
    c1: int,
) -> None:
    """Bring the frontier mask ``frontier`` (bool, (H, W)) and its per-row counts
    ``row_count`` (H,) up to date with ``belief`` inside rows ``r0:r1`` and columns ``c0:c1``
    (clipped to the grid). A belief change at a cell can only change the frontier at that cell
    and its 4-neighbours, so a window one cell wider than the changes keeps the whole mask
    exact; the whole grid's window makes it from scratch."""
    height, width = belief.shape
    for r in range(max(r0, 0), min(r1, height)):
        for c in range(max(c0, 0), min(c1, width)):
            # (as a branch: numba compiles ``is_frontier`` used as a value about 20x slower)
            if is_frontier(belief, r, c):
                if not frontier[r, c]:
                    frontier[r, c] = True
                    row_count[r] += 1
            elif frontier[r, c]:
                frontier[r, c] = False
                row_count[r] -= 1


@compiled
def label_frontier_cells(
    frontier: np.ndarray,
    row_count: np.ndarray,
    connectivity: int,
    rows: np.ndarray,
    cols: np.ndarray,
    label: np.ndarray,
    parent: np.ndarray,
    index: np.ndarray,
) -> tuple[int, int]:
    """The cells of the frontier mask ``frontier`` (with its per-row counts ``row_count``, as
    :func:`update_frontier` keeps them) and their contiguous groups, labelled as
    ``scipy.ndimage.label`` labels the mask (``connectivity`` 4 or 8; groups numbered from 0
    in raster order of their first cell), by a union-find over the frontier cells alone; rows
    without frontier cells are skipped.

    Fills ``rows``/``cols`` (the cells, raster order) and ``label`` (0-based group per cell);
    ``parent`` is scratch of at least as many entries, ``index`` an (H, W) int64 scratch grid
    that must hold -1 everywhere and is left so. Returns (cells, groups)."""
    height, width = frontier.shape
    n = 0
    for r in range(height):
        if row_count[r] == 0:
            continue
        for c in range(width):
            if not frontier[r, c]:
                continue
            rows[n] = r
            cols[n] = c
            index[r, c] = n
            parent[n] = n
            # Join the groups of the neighbours already scanned; a group's root is its
            # first cell (the smaller root always wins).
            for dr, dc in ((0, -1), (-1, -1), (-1, 0), (-1, 1)):
                if connectivity == 4 and dr != 0 and dc != 0:
                    continue
                nr, nc = r + dr, c + dc
                if nr >= 0 and 0 <= nc < width and index[nr, nc] >= 0:
                    a = _root(parent, n)
                    b = _root(parent, index[nr, nc])
                    if a < b:
                        parent[b] = a
                    elif b < a:
                        parent[a] = b
            n += 1
    groups = 0
    for i in range(n):
        root = _root(parent, i)
        if root == i:
            label[i] = groups
            groups += 1
        else:
            label[i] = label[root]
        index[rows[i], cols[i]] = -1
    return n, groups


@compiled
def _root(parent: np.ndarray, i: int) -> int:
    """The root of ``i`` in the union-find ``parent``, halving the path on the way."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i
