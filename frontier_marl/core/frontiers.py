"""Frontier detection, clustering with ``scipy.ndimage.label``, splitting, and cluster statistics.

A *frontier cell* is a known-free cell with at least one unknown 4-neighbour. Frontier cells
are grouped into clusters of contiguous cells (4- or 8-connectivity); a cluster with more than
``max_cells`` cells is split recursively in two across the longer side of its bounding box
(at the box's midpoint) until every piece is small enough. Clusters are numbered in raster
order of their first cell, the same convention as ``scipy.ndimage.label``.

With numba (see :mod:`frontier_marl.core.kernels`) the loops around the labelling run compiled,
with identical results; the labelling is ``scipy.ndimage.label`` in both modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from frontier_marl.core import kernels
from frontier_marl.core.grid import FREE, UNKNOWN

_STRUCTURES = {
    4: ndimage.generate_binary_structure(2, 1),
    8: ndimage.generate_binary_structure(2, 2),
}
_EIGHT_OFFSETS = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if (dr, dc) != (0, 0)]


def frontier_mask(belief: np.ndarray) -> np.ndarray:
    """Bool mask of frontier cells: known-free cells with an unknown 4-neighbour."""
    unknown = belief == UNKNOWN
    near_unknown = np.zeros_like(unknown)
    near_unknown[1:, :] |= unknown[:-1, :]
    near_unknown[:-1, :] |= unknown[1:, :]
    near_unknown[:, 1:] |= unknown[:, :-1]
    near_unknown[:, :-1] |= unknown[:, 1:]
    return (belief == FREE) & near_unknown


@dataclass(frozen=True)
class Clusters:
    """Frontier clusters of one belief grid.

    Attributes:
        shape: the grid shape.
        cell_rows, cell_cols: coordinates of every frontier cell, in raster order.
        cell_cluster: the 0-based cluster index of each frontier cell.
        sizes: cells per cluster, shape (K,).
        centroids: mean (row, col) of each cluster, shape (K, 2), float.
    """

    shape: tuple[int, int]
    cell_rows: np.ndarray
    cell_cols: np.ndarray
    cell_cluster: np.ndarray
    sizes: np.ndarray
    centroids: np.ndarray

    @property
    def count(self) -> int:
        return len(self.sizes)

    def labels(self) -> np.ndarray:
        """Label image: 0 off the frontier, k for a cell of cluster k-1 (i.e. 1-based)."""
        image = np.zeros(self.shape, dtype=np.int32)
        image[self.cell_rows, self.cell_cols] = self.cell_cluster + 1
        return image

    def cells_of(self, cluster: int) -> np.ndarray:
        """(n, 2) cells of cluster ``cluster`` (0-based)."""
        pick = self.cell_cluster == cluster
        return np.stack([self.cell_rows[pick], self.cell_cols[pick]], axis=1)


def cluster_frontiers(belief: np.ndarray, connectivity: int = 8, max_cells: int = 0) -> Clusters:
    """Find, label and split the frontier clusters of ``belief``.

    Args:
        belief: int8 belief grid.
        connectivity: 4 or 8, the neighbourhood that joins frontier cells into one cluster.
        max_cells: split clusters larger than this; 0 disables splitting.
    """
    if connectivity not in _STRUCTURES:
        raise ValueError(f"connectivity must be 4 or 8, got {connectivity!r}")
    if kernels.ENABLED:
        mask, rows, cols = kernels.frontier_cells(belief)
    else:
        mask = frontier_mask(belief)
        rows, cols = np.divmod(np.flatnonzero(mask), belief.shape[1])
    if rows.size == 0:
        empty = np.zeros(0, dtype=np.int64)
        return Clusters(belief.shape, empty, empty, empty, empty, np.zeros((0, 2)))
    image, count = ndimage.label(mask, structure=_STRUCTURES[connectivity])
    if kernels.ENABLED:
        cluster, sizes, centroids = kernels.clusters_from_labels(
            image, rows, cols, count, max_cells
        )
        return Clusters(belief.shape, rows, cols, cluster, sizes, centroids)
    # ndimage numbers features in raster order of their first cell, so label - 1 is already
    # the cluster index unless splitting adds pieces.
    cluster = image[rows, cols].astype(np.int64) - 1
    if max_cells > 0:
        cluster = _split_oversized(rows, cols, cluster, count, max_cells)
    sizes = np.bincount(cluster)
    centroids = np.empty((len(sizes), 2))
    centroids[:, 0] = np.bincount(cluster, weights=rows) / sizes
    centroids[:, 1] = np.bincount(cluster, weights=cols) / sizes
    return Clusters(belief.shape, rows, cols, cluster, sizes, centroids)


def _split_oversized(
    rows: np.ndarray, cols: np.ndarray, label: np.ndarray, count: int, max_cells: int
) -> np.ndarray:
    """Split clusters above ``max_cells`` and renumber all pieces in raster order."""
    sizes = np.bincount(label, minlength=count)
    oversized = np.flatnonzero(sizes > max_cells)
    if oversized.size == 0:
        return label
    label = label.copy()
    next_label = count
    for cluster in oversized.tolist():
        members = np.flatnonzero(label == cluster)
        for piece in split_cells(rows[members], cols[members], max_cells)[1:]:
            label[members[piece]] = next_label
            next_label += 1
    # Cells are in raster order, so a piece's first cell is its smallest position.
    first = np.full(next_label, len(label), dtype=np.int64)
    np.minimum.at(first, label, np.arange(len(label)))
    rank = np.empty(next_label, dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(next_label)
    return rank[label]


def split_cells(rows: np.ndarray, cols: np.ndarray, max_cells: int) -> list[np.ndarray]:
    """Split a set of cells recursively until every piece has at most ``max_cells`` cells.

    Each split halves the bounding box across its longer side (rows on a tie) at the box's
    midpoint, so both halves are non-empty. Returns index arrays into ``rows``/``cols``.
    """
    if max_cells < 1:
        raise ValueError(f"max_cells must be >= 1, got {max_cells}")
    row_list, col_list = rows.tolist(), cols.tolist()
    pieces: list[list[int]] = []
    stack = [list(range(len(row_list)))]
    while stack:
        index = stack.pop()
        if len(index) <= max_cells:
            pieces.append(index)
            continue
        r = [row_list[i] for i in index]
        c = [col_list[i] for i in index]
        values = r if max(r) - min(r) >= max(c) - min(c) else c
        middle = (min(values) + max(values)) / 2.0
        low = [i for i, v in zip(index, values, strict=True) if v <= middle]
        high = [i for i, v in zip(index, values, strict=True) if v > middle]
        stack.append(high)
        stack.append(low)
    pieces.sort(key=min)
    return [np.array(piece, dtype=np.int64) for piece in pieces]


def unknown_around(belief: np.ndarray, clusters: Clusters) -> np.ndarray:
    """Per cluster, the number of distinct unknown cells 8-adjacent to any of its cells."""
    height, width = belief.shape
    if clusters.count == 0:
        return np.zeros(0, dtype=np.int64)
    keys = []
    unknown = belief == UNKNOWN
    for dr, dc in _EIGHT_OFFSETS:
        r = clusters.cell_rows + dr
        c = clusters.cell_cols + dc
        inside = (r >= 0) & (r < height) & (c >= 0) & (c < width)
        hit = np.zeros_like(inside)
        hit[inside] = unknown[r[inside], c[inside]]
        keys.append(clusters.cell_cluster[hit] * (height * width) + r[hit] * width + c[hit])
    distinct = np.unique(np.concatenate(keys))
    return np.bincount(distinct // (height * width), minlength=clusters.count)


def nearest_cells_to_centroids(
    clusters: Clusters, eligible: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """For each cluster, its eligible cell nearest its centroid (ties: raster order).

    Args:
        clusters: the clusters.
        eligible: bool per frontier cell (aligned with ``clusters.cell_rows``), e.g. reachable.

    Returns:
        ``(has_target, targets)``: bool (K,), and int (K, 2) cells (rows of -1 where none).
    """
    if kernels.ENABLED:
        return kernels.nearest_targets(
            clusters.cell_rows,
            clusters.cell_cols,
            clusters.cell_cluster,
            clusters.centroids,
            np.asarray(eligible, dtype=bool),
        )
    return _nearest_cells_numpy(clusters, eligible)


def _nearest_cells_numpy(clusters: Clusters, eligible: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    count = clusters.count
    targets = np.full((count, 2), -1, dtype=np.int64)
    has_target = np.zeros(count, dtype=bool)
    if count == 0:
        return has_target, targets
    if eligible.all():
        cluster, rows, cols = clusters.cell_cluster, clusters.cell_rows, clusters.cell_cols
    else:
        pick = np.flatnonzero(eligible)
        if pick.size == 0:
            return has_target, targets
        cluster = clusters.cell_cluster[pick]
        rows, cols = clusters.cell_rows[pick], clusters.cell_cols[pick]
    centroid = clusters.centroids[cluster]
    dist2 = (rows - centroid[:, 0]) ** 2 + (cols - centroid[:, 1]) ** 2
    # Stable sort by (cluster, distance): cells are in raster order, so ties keep raster order.
    order = np.lexsort((dist2, cluster))
    sorted_cluster = cluster[order]
    starts = np.empty(len(order), dtype=bool)
    starts[0] = True
    np.not_equal(sorted_cluster[1:], sorted_cluster[:-1], out=starts[1:])
    first = order[starts]
    chosen = cluster[first]
    has_target[chosen] = True
    targets[chosen, 0] = rows[first]
    targets[chosen, 1] = cols[first]
    return has_target, targets


def free_components(belief: np.ndarray) -> np.ndarray:
    """Labels of 4-connected components of known-free cells (0 elsewhere)."""
    labels, _ = ndimage.label(belief == FREE, structure=_STRUCTURES[4])
    return labels
