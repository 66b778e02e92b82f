"""Frontier detection, clustering with ``scipy.ndimage.label``, splitting, cluster statistics.

A *frontier cell* is a known-free cell with at least one unknown 4-neighbour. Frontier cells
are grouped into clusters of contiguous cells (4- or 8-connectivity) by ``scipy.ndimage.label``,
called once for a batch of worlds (:func:`pack_frontier_masks`, :func:`label_packed`: each
world's mask, cropped to the box around its frontier cells, ends in a blank row, and the crops
are labelled as one image, so no component crosses worlds);
a cluster with more than ``max_cells`` cells is split recursively in two across the longer side
of its bounding box (rows on a tie), at the box's midpoint, until every piece is small enough.
Clusters are numbered in raster order of their first cell, the convention of
``scipy.ndimage.label``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from frontier_marl.core.compiled import compiled
from frontier_marl.core.grid import FREE, UNKNOWN

_STRUCTURES = {
    4: ndimage.generate_binary_structure(2, 1),
    8: ndimage.generate_binary_structure(2, 2),
}


@dataclass(slots=True)
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


def frontier_mask(belief: np.ndarray) -> np.ndarray:
    """Bool mask of frontier cells: known-free cells with an unknown 4-neighbour."""
    return frontier_cells(belief)[0]


def cluster_frontiers(belief: np.ndarray, connectivity: int = 8, max_cells: int = 0) -> Clusters:
    """Find, label and split the frontier clusters of ``belief`` (one world of
    :func:`cluster_worlds`).

    Args:
        belief: int8 belief grid.
        connectivity: 4 or 8, the neighbourhood that joins frontier cells into one cluster.
        max_cells: split clusters larger than this; 0 disables splitting.
    """
    if connectivity not in _STRUCTURES:
        raise ValueError(f"connectivity must be 4 or 8, got {connectivity!r}")
    worlds = np.zeros(1, dtype=np.int64)
    image = np.empty((belief.shape[0] + 1) * belief.shape[1], dtype=np.bool_)
    labels = np.empty(image.shape, dtype=np.int32)
    boxes = np.empty((1, 4), dtype=np.int64)
    frontier = np.empty((1, *belief.shape), dtype=np.bool_)
    height, width = pack_frontier_masks(belief[None], worlds, frontier, image, boxes)
    label_packed(image, labels, height, width, connectivity)
    cells = belief.size
    rows, cols, cluster = (np.zeros((1, cells), dtype=np.int64) for _ in range(3))
    sizes, centroids = np.zeros((1, cells), dtype=np.int64), np.zeros((1, cells, 2))
    n_cells, n_clusters = np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64)
    cluster_worlds(
        labels, boxes, width, worlds, max_cells, rows, cols, cluster, n_cells, sizes, centroids,
        n_clusters,
    )  # fmt: skip
    n, k = int(n_cells[0]), int(n_clusters[0])
    return Clusters(
        belief.shape, rows[0, :n], cols[0, :n], cluster[0, :n], sizes[0, :k], centroids[0, :k]
    )


def label_packed(
    image: np.ndarray, labels: np.ndarray, height: int, width: int, connectivity: int
) -> None:
    """Label the packed frontier masks of :func:`pack_frontier_masks` (the first ``height``
    ``width`` cells of ``image``, flat) into ``labels`` (int32, as long) with one
    ``scipy.ndimage.label`` call. Its components are numbered crop after crop in raster order,
    exactly as one call per world on its whole map would number them: a crop holds all of its
    world's frontier cells and keeps their raster order, and the blank rows keep every
    component inside its world."""
    cells = height * width
    ndimage.label(
        image[:cells].reshape(height, width),
        structure=_STRUCTURES[connectivity],
        output=labels[:cells].reshape(height, width),
    )


def split_cells(rows: np.ndarray, cols: np.ndarray, max_cells: int) -> list[np.ndarray]:
    """Split one set of cells as :func:`cluster_frontiers` splits a cluster.

    Returns index arrays into ``rows``/``cols``, one per piece, ordered by their first index.
    """
    if max_cells < 1:
        raise ValueError(f"max_cells must be >= 1, got {max_cells}")
    rows = np.asarray(rows, dtype=np.int64)
    cols = np.asarray(cols, dtype=np.int64)
    piece, count = split_and_renumber(rows, cols, np.zeros(len(rows), np.int64), 1, max_cells)
    return [np.flatnonzero(piece == k) for k in range(count)]


def unknown_around(belief: np.ndarray, clusters: Clusters) -> np.ndarray:
    """Per cluster, the number of distinct unknown cells 8-adjacent to any of its cells."""
    out = np.zeros(clusters.count, dtype=np.int64)
    count_unknown_around(belief, clusters.cell_rows, clusters.cell_cols, clusters.cell_cluster, out)
    return out


@compiled
def count_unknown_around(
    belief: np.ndarray, rows: np.ndarray, cols: np.ndarray, cluster: np.ndarray, out: np.ndarray
) -> None:
    """:func:`unknown_around` of the clusters numbered 0..len(out)-1 whose cells are
    (``rows``, ``cols``) with cluster ids ``cluster``, into ``out`` (added to its values)."""
    height, width = belief.shape
    stamp = np.full((height, width), -1, dtype=np.int64)  # the last cluster that counted a cell
    for i in np.argsort(cluster, kind="mergesort"):  # each cluster's cells one after another
        k = cluster[i]
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                r, c = rows[i] + dr, cols[i] + dc
                inside = (dr or dc) and 0 <= r < height and 0 <= c < width
                if inside and belief[r, c] == UNKNOWN and stamp[r, c] != k:
                    stamp[r, c] = k
                    out[k] += 1


@compiled
def is_frontier(belief: np.ndarray, r: int, c: int) -> bool:
    """Cell (r, c) is free with an unknown 4-neighbour."""
    height, width = belief.shape
    return belief[r, c] == FREE and (
        (r > 0 and belief[r - 1, c] == UNKNOWN)
        or (r + 1 < height and belief[r + 1, c] == UNKNOWN)
        or (c > 0 and belief[r, c - 1] == UNKNOWN)
        or (c + 1 < width and belief[r, c + 1] == UNKNOWN)
    )


@compiled
def frontier_cells(belief: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mask, rows, cols) of the frontier cells, cells in raster order."""
    height, width = belief.shape
    mask = np.zeros((height, width), dtype=np.bool_)
    rows = np.empty(height * width, dtype=np.int64)
    cols = np.empty(height * width, dtype=np.int64)
    n = 0
    for r in range(height):
        for c in range(width):
            if is_frontier(belief, r, c):
                mask[r, c] = True
                rows[n] = r
                cols[n] = c
                n += 1
    return mask, rows[:n], cols[:n]


@compiled
def split_and_renumber(
    rows: np.ndarray, cols: np.ndarray, label: np.ndarray, count: int, max_cells: int
) -> tuple[np.ndarray, int]:
    """Split clusters above ``max_cells`` (see the module docstring) and renumber every
    piece in raster order of its first cell. ``label`` is 0-based, cells in raster order.
    Returns the new labels and their count."""
    n = len(label)
    # Group cell indices by cluster (counting sort keeps raster order within a cluster).
    starts = np.zeros(count + 1, dtype=np.int64)
    for i in range(n):
        starts[label[i] + 1] += 1
    for k in range(count):
        starts[k + 1] += starts[k]
    order = np.empty(n, dtype=np.int64)
    fill = starts[:-1].copy()
    for i in range(n):
        order[fill[label[i]]] = i
        fill[label[i]] += 1
    piece = np.empty(n, dtype=np.int64)
    pieces = 0
    stack = np.empty((2 * n + 2, 2), dtype=np.int64)  # segments [lo, hi) of ``order``
    for k in range(count):
        stack[0, 0] = starts[k]
        stack[0, 1] = starts[k + 1]
        top = 1
        while top > 0:
            top -= 1
            lo = stack[top, 0]
            hi = stack[top, 1]
            if hi - lo <= max_cells:
                for j in range(lo, hi):
                    piece[order[j]] = pieces
                pieces += 1
                continue
            r_min = r_max = rows[order[lo]]
            c_min = c_max = cols[order[lo]]
            for j in range(lo + 1, hi):
                r = rows[order[j]]
                c = cols[order[j]]
                r_min = min(r_min, r)
                r_max = max(r_max, r)
                c_min = min(c_min, c)
                c_max = max(c_max, c)
            by_rows = r_max - r_min >= c_max - c_min
            middle = (r_min + r_max) / 2.0 if by_rows else (c_min + c_max) / 2.0
            # Partition the segment: values <= middle first (order inside a piece is
            # irrelevant, pieces are renumbered by their first cell below).
            i = lo
            j = hi - 1
            while i <= j:
                value = rows[order[i]] if by_rows else cols[order[i]]
                if value <= middle:
                    i += 1
                else:
                    order[i], order[j] = order[j], order[i]
                    j -= 1
            stack[top, 0] = lo
            stack[top, 1] = i
            stack[top + 1, 0] = i
            stack[top + 1, 1] = hi
            top += 2
    # Renumber pieces by first appearance in raster order.
    rank = np.full(pieces, -1, dtype=np.int64)
    out = np.empty(n, dtype=np.int64)
    seen = 0
    for i in range(n):
        p = piece[i]
        if rank[p] < 0:
            rank[p] = seen
            seen += 1
        out[i] = rank[p]
    return out, seen


@compiled
def cluster_stats(
    rows: np.ndarray, cols: np.ndarray, cluster: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray]:
    """Sizes (K,) and centroids (K, 2) of clusters numbered 0..count-1."""
    sizes = np.zeros(count, dtype=np.int64)
    sums = np.zeros((count, 2), dtype=np.float64)
    for i in range(len(cluster)):
        k = cluster[i]
        sizes[k] += 1
        sums[k, 0] += rows[i]
        sums[k, 1] += cols[i]
    for k in range(count):
        sums[k, 0] /= sizes[k]
        sums[k, 1] /= sizes[k]
    return sizes, sums


@compiled
def pack_frontier_masks(
    belief: np.ndarray,
    worlds: np.ndarray,
    frontier: np.ndarray,
    image: np.ndarray,
    boxes: np.ndarray,
) -> tuple[int, int]:
    """The frontier masks of ``worlds`` (into the first planes of ``frontier``, (M, H, W)),
    each cropped to the box around its frontier cells and packed into ``image`` (flat bool,
    ``M (H + 1) W`` long at least) as one image of the widest crop's width: crop after crop,
    each at the left and with a blank row below it (:func:`label_packed`). ``boxes`` gets each
    crop's top row, left column, height and width (height 0 where a world has no frontier).
    Returns the image's (height, width)."""
    height, map_width = belief.shape[1], belief.shape[2]
    width = 1
    for m in range(len(worlds)):
        world, mask = belief[worlds[m]], frontier[m]
        top, bottom, left, right = -1, -1, map_width, -1
        for r in range(height):
            first, last = -1, -1
            for c in range(map_width):
                # (as a branch: numba compiles ``is_frontier`` used as a value about 20x slower)
                if is_frontier(world, r, c):
                    mask[r, c] = True
                    last = c
                    if first < 0:
                        first = c
                else:
                    mask[r, c] = False
            if first >= 0:
                if top < 0:
                    top = r
                bottom = r
                left, right = min(left, first), max(right, last)
        if top < 0:
            boxes[m, 0], boxes[m, 1], boxes[m, 2], boxes[m, 3] = 0, 0, 0, 0
        else:
            boxes[m, 0], boxes[m, 1] = top, left
            boxes[m, 2], boxes[m, 3] = bottom - top + 1, right - left + 1
            width = max(width, right - left + 1)
    row = 0
    for m in range(len(worlds)):
        top, left, crop_height, crop_width = boxes[m, 0], boxes[m, 1], boxes[m, 2], boxes[m, 3]
        for r in range(crop_height):
            start = (row + r) * width
            for c in range(crop_width):
                image[start + c] = frontier[m, top + r, left + c]
            image[start + crop_width : start + width] = False
        start = (row + crop_height) * width
        image[start : start + width] = False
        row += crop_height + 1
    return row, width


@compiled
def cluster_worlds(
    labels: np.ndarray,
    boxes: np.ndarray,
    width: int,
    worlds: np.ndarray,
    max_cells: int,
    cell_rows: np.ndarray,
    cell_cols: np.ndarray,
    cell_cluster: np.ndarray,
    n_cells: np.ndarray,
    sizes: np.ndarray,
    centroids: np.ndarray,
    n_clusters: np.ndarray,
) -> None:
    """Clusters of each world from a packed labelling (flat ``labels`` of ``width`` columns
    and the crops' ``boxes``, as :func:`pack_frontier_masks` and :func:`label_packed` make
    them: numbered world after world), split above ``max_cells`` (> 0) and renumbered in raster
    order, into the world's rows of the cluster buffers."""
    below = 0  # labels used by the worlds before this one
    row = 0  # the crop's first row in the packed image
    for m in range(len(worlds)):
        n = worlds[m]
        count = 0
        top = below
        for r in range(boxes[m, 2]):
            start = (row + r) * width
            for c in range(boxes[m, 3]):
                label = labels[start + c]
                if label > 0:
                    cell_rows[n, count] = boxes[m, 0] + r
                    cell_cols[n, count] = boxes[m, 1] + c
                    cell_cluster[n, count] = label - 1 - below
                    top = max(top, label)
                    count += 1
        row += boxes[m, 2] + 1
        n_cells[n] = count
        clusters = top - below
        below = top
        rows = cell_rows[n, :count]
        cols = cell_cols[n, :count]
        cluster = cell_cluster[n, :count]
        if max_cells > 0 and count > 0:
            split, clusters = split_and_renumber(rows, cols, cluster.copy(), clusters, max_cells)
            cluster[:] = split
        world_sizes, world_centroids = cluster_stats(rows, cols, cluster, clusters)
        sizes[n, :clusters] = world_sizes
        centroids[n, :clusters] = world_centroids
        n_clusters[n] = clusters
