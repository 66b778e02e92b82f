"""Tests for frontier_marl.core.frontiers on hand-made maps with known answers, plus properties."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from frontier_marl.core.frontier_union import label_frontier_cells, update_frontier
from frontier_marl.core.frontiers import (
    cluster_frontiers,
    frontier_mask,
    split_cells,
    unknown_around,
)
from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN
from frontier_marl.core.slot_kernels import nearest_targets
from tests import oracles

_CODES = {"?": UNKNOWN, ".": FREE, "#": OCCUPIED}


def belief_from(text: str) -> np.ndarray:
    """Belief grid from rows of ``?`` (unknown), ``.`` (free), ``#`` (occupied)."""
    rows = [line.split() for line in text.strip().splitlines()]
    return np.array([[_CODES[c] for c in row] for row in rows], dtype=np.int8)


# A non-square 4x6 belief whose frontier is a diagonal staircase: with 8-connectivity one
# cluster, with 4-connectivity four clusters. (3,0) is unknown but touches no free cell.
STAIR = belief_from(
    """
    . . ? ? ? ?
    . . . ? ? ?
    # . . . ? ?
    ? # . . . .
    """
)
STAIR_FRONTIER = np.array(
    [
        [0, 1, 0, 0, 0, 0],
        [0, 0, 1, 0, 0, 0],
        [0, 0, 0, 1, 0, 0],
        [0, 0, 0, 0, 1, 1],
    ],
    dtype=bool,
)


# ----------------------------------------------------------------------------- frontier_mask
def test_frontier_mask_non_square_exact():
    assert STAIR.shape == (4, 6)
    np.testing.assert_array_equal(frontier_mask(STAIR), STAIR_FRONTIER)


def test_frontier_mask_transpose_is_transposed_mask():
    np.testing.assert_array_equal(frontier_mask(STAIR.T.copy()), STAIR_FRONTIER.T)


def test_frontier_mask_ignores_diagonal_unknown_and_occupied_cells():
    # (1,1) is free with only a *diagonal* unknown neighbour -> not a frontier.
    # (0,2) is occupied next to unknown -> not a frontier. (2,2) is free next to unknown (2,3).
    belief = belief_from(
        """
        ? . # ?
        . . . .
        . . . ?
        """
    )
    expected = np.array(
        [
            [0, 1, 0, 0],
            [1, 0, 0, 1],
            [0, 0, 1, 0],
        ],
        dtype=bool,
    )
    np.testing.assert_array_equal(frontier_mask(belief), expected)


def test_frontier_mask_all_known_or_all_unknown_is_empty():
    assert not frontier_mask(np.full((3, 5), FREE, dtype=np.int8)).any()
    assert not frontier_mask(np.full((3, 5), UNKNOWN, dtype=np.int8)).any()


# ----------------------------------------------------------------------------- clustering
def test_cluster_8_connectivity_joins_the_diagonal_staircase():
    clusters = cluster_frontiers(STAIR, connectivity=8)
    assert clusters.count == 1
    np.testing.assert_array_equal(clusters.sizes, [5])
    np.testing.assert_allclose(clusters.centroids, [[9 / 5, 3.0]])
    np.testing.assert_array_equal(clusters.cell_rows, [0, 1, 2, 3, 3])
    np.testing.assert_array_equal(clusters.cell_cols, [1, 2, 3, 4, 5])
    np.testing.assert_array_equal(clusters.cell_cluster, [0, 0, 0, 0, 0])
    np.testing.assert_array_equal(clusters.labels(), STAIR_FRONTIER.astype(np.int32))


def test_cluster_4_connectivity_splits_the_diagonal_staircase():
    clusters = cluster_frontiers(STAIR, connectivity=4)
    assert clusters.count == 4
    np.testing.assert_array_equal(clusters.sizes, [1, 1, 1, 2])
    np.testing.assert_allclose(clusters.centroids, [[0, 1], [1, 2], [2, 3], [3, 4.5]])
    np.testing.assert_array_equal(clusters.cell_cluster, [0, 1, 2, 3, 3])
    expected_labels = np.array(
        [
            [0, 1, 0, 0, 0, 0],
            [0, 0, 2, 0, 0, 0],
            [0, 0, 0, 3, 0, 0],
            [0, 0, 0, 0, 4, 4],
        ]
    )
    np.testing.assert_array_equal(clusters.labels(), expected_labels)
    np.testing.assert_array_equal(clusters.cells_of(3), [[3, 4], [3, 5]])
    np.testing.assert_array_equal(clusters.cells_of(1), [[1, 2]])


def test_clusters_are_numbered_in_raster_order():
    # Cluster at (0,3) comes first in raster (row-major) order although (1,0) comes first in
    # column-major order.
    belief = belief_from(
        """
        # # # . ?
        . # # # #
        ? # # # #
        """
    )
    clusters = cluster_frontiers(belief, connectivity=8)
    assert clusters.count == 2
    np.testing.assert_array_equal(clusters.cells_of(0), [[0, 3]])
    np.testing.assert_array_equal(clusters.cells_of(1), [[1, 0]])
    np.testing.assert_allclose(clusters.centroids, [[0, 3], [1, 0]])
    expected = np.array([[0, 0, 0, 1, 0], [2, 0, 0, 0, 0], [0, 0, 0, 0, 0]])
    np.testing.assert_array_equal(clusters.labels(), expected)


def test_cluster_empty_belief_gives_no_clusters():
    for belief in (np.full((3, 5), UNKNOWN, np.int8), np.full((3, 5), FREE, np.int8)):
        clusters = cluster_frontiers(belief, connectivity=8, max_cells=4)
        assert clusters.count == 0
        assert clusters.centroids.shape == (0, 2)
        assert clusters.cell_rows.size == 0
        np.testing.assert_array_equal(clusters.labels(), np.zeros((3, 5)))
        assert unknown_around(belief, clusters).shape == (0,)


@pytest.mark.parametrize("connectivity", [0, 6, 3])
def test_cluster_bad_connectivity_raises(connectivity):
    with pytest.raises(ValueError, match="connectivity"):
        cluster_frontiers(STAIR, connectivity=connectivity)


# A 3x10 belief: top row unknown, the whole middle row is one straight frontier of 10 cells.
LINE = belief_from(
    """
    ? ? ? ? ? ? ? ? ? ?
    . . . . . . . . . .
    . . . . . . . . . .
    """
)


@pytest.mark.parametrize("connectivity", [4, 8])
def test_cluster_line_of_ten_split_with_max_four(connectivity):
    clusters = cluster_frontiers(LINE, connectivity=connectivity, max_cells=4)
    assert clusters.count == 4
    np.testing.assert_array_equal(clusters.sizes, [3, 2, 3, 2])
    np.testing.assert_allclose(clusters.centroids, [[1, 1], [1, 3.5], [1, 6], [1, 8.5]])
    expected = np.zeros((3, 10), dtype=np.int32)
    expected[1] = [1, 1, 1, 2, 2, 3, 3, 3, 4, 4]
    np.testing.assert_array_equal(clusters.labels(), expected)


def test_cluster_line_of_ten_unsplit_when_disabled_or_large_enough():
    for max_cells in (0, 10, 11):
        clusters = cluster_frontiers(LINE, connectivity=8, max_cells=max_cells)
        np.testing.assert_array_equal(clusters.sizes, [10])
        np.testing.assert_allclose(clusters.centroids, [[1, 4.5]])


def test_cluster_vertical_line_split_on_non_square_map():
    belief = LINE.T.copy()  # 10x3: column 0 unknown, column 1 a vertical frontier of 10
    clusters = cluster_frontiers(belief, connectivity=8, max_cells=4)
    np.testing.assert_array_equal(clusters.sizes, [3, 2, 3, 2])
    np.testing.assert_allclose(clusters.centroids, [[1, 1], [3.5, 1], [6, 1], [8.5, 1]])
    expected = np.zeros((10, 3), dtype=np.int32)
    expected[:, 1] = [1, 1, 1, 2, 2, 3, 3, 3, 4, 4]
    np.testing.assert_array_equal(clusters.labels(), expected)


# ----------------------------------------------------------------------------- split_cells
def _as_lists(pieces: list[np.ndarray]) -> list[list[int]]:
    return [sorted(int(i) for i in piece) for piece in pieces]


def test_split_cells_horizontal_line_of_ten():
    rows, cols = np.zeros(10, dtype=np.int64), np.arange(10)
    pieces = split_cells(rows, cols, 4)
    assert _as_lists(pieces) == [[0, 1, 2], [3, 4], [5, 6, 7], [8, 9]]


def test_split_cells_vertical_line_of_ten():
    rows, cols = np.arange(10), np.full(10, 7)
    assert _as_lists(split_cells(rows, cols, 4)) == [[0, 1, 2], [3, 4], [5, 6, 7], [8, 9]]


def test_split_cells_small_set_is_one_piece():
    rows, cols = np.array([2, 2, 3]), np.array([0, 1, 1])
    assert _as_lists(split_cells(rows, cols, 3)) == [[0, 1, 2]]


def test_split_cells_square_box_splits_rows_on_a_tie():
    # 2x2 block in raster order: (0,0),(0,1),(1,0),(1,1). A tie splits across rows.
    rows, cols = np.array([0, 0, 1, 1]), np.array([5, 6, 5, 6])
    assert _as_lists(split_cells(rows, cols, 2)) == [[0, 1], [2, 3]]


def test_split_cells_splits_across_longer_side():
    # 2 rows x 4 cols block: columns are the longer side.
    rows = np.array([0, 0, 0, 0, 1, 1, 1, 1])
    cols = np.array([0, 1, 2, 3, 0, 1, 2, 3])
    assert _as_lists(split_cells(rows, cols, 4)) == [[0, 1, 4, 5], [2, 3, 6, 7]]


def test_split_cells_to_singletons():
    rows, cols = np.zeros(5, dtype=np.int64), np.arange(5)
    assert _as_lists(split_cells(rows, cols, 1)) == [[0], [1], [2], [3], [4]]


@pytest.mark.parametrize("max_cells", [0, -1])
def test_split_cells_bad_max_raises(max_cells):
    with pytest.raises(ValueError, match="max_cells"):
        split_cells(np.array([0]), np.array([0]), max_cells)


# ----------------------------------------------------------------------------- unknown_around
def test_unknown_around_counts_distinct_cells_4_connectivity():
    clusters = cluster_frontiers(STAIR, connectivity=4)
    # (0,1): {(0,2)}; (1,2): {(0,2),(0,3),(1,3)}; (2,3): {(1,3),(1,4),(2,4)};
    # (3,4),(3,5): {(2,4),(2,5)} counted once each.
    np.testing.assert_array_equal(unknown_around(STAIR, clusters), [1, 3, 3, 2])


def test_unknown_around_counts_distinct_cells_8_connectivity():
    clusters = cluster_frontiers(STAIR, connectivity=8)
    # Union {(0,2),(0,3),(1,3),(1,4),(2,4),(2,5)}: 6, not the per-cell sum 9.
    np.testing.assert_array_equal(unknown_around(STAIR, clusters), [6])


def test_unknown_around_at_grid_border():
    # Frontier row along the bottom border; unknown row above; clipping must not wrap around.
    belief = belief_from(
        """
        ? ? ? ? ?
        . . . . .
        """
    )
    clusters = cluster_frontiers(belief, connectivity=8, max_cells=2)
    # pieces: cols {0,1}, {2}, {3,4}; 8-neighbourhood unknowns: {0,1,2}, {1,2,3}, {2,3,4}
    np.testing.assert_array_equal(clusters.sizes, [2, 1, 2])
    np.testing.assert_array_equal(unknown_around(belief, clusters), [3, 3, 3])


@settings(max_examples=60, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 9), st.integers(1, 9)),
    max_cells=st.integers(0, 4),
    seed=st.integers(0, 2**32 - 1),
)
def test_unknown_around_is_the_distinct_unknown_neighbours_of_each_cluster(shape, max_cells, seed):
    belief = np.random.default_rng(seed).integers(-1, 2, shape).astype(np.int8)
    clusters = cluster_frontiers(belief, connectivity=8, max_cells=max_cells)
    expected = []
    for k in range(clusters.count):
        around = {
            (r + dr, c + dc)
            for r, c in clusters.cells_of(k).tolist()
            for dr in (-1, 0, 1)
            for dc in (-1, 0, 1)
            if (dr, dc) != (0, 0)
            and 0 <= r + dr < shape[0]
            and 0 <= c + dc < shape[1]
            and belief[r + dr, c + dc] == UNKNOWN
        }
        expected.append(len(around))
    assert unknown_around(belief, clusters).tolist() == expected


# ----------------------------------------------------------------------------- targets
def nearest_cells_to_centroids(clusters, eligible):
    return nearest_targets(
        clusters.cell_rows,
        clusters.cell_cols,
        clusters.cell_cluster,
        clusters.centroids,
        np.asarray(eligible, dtype=bool),
    )


def test_nearest_cell_to_centroid_8_connectivity():
    clusters = cluster_frontiers(STAIR, connectivity=8)  # centroid (1.8, 3.0)
    eligible = np.ones(5, dtype=bool)
    has, targets = nearest_cells_to_centroids(clusters, eligible)
    np.testing.assert_array_equal(has, [True])
    np.testing.assert_array_equal(targets, [[2, 3]])
    # Without (2,3), the next nearest is (1,2) (d2 1.64) ahead of (3,4) (d2 2.44).
    eligible[2] = False
    has, targets = nearest_cells_to_centroids(clusters, eligible)
    np.testing.assert_array_equal(targets, [[1, 2]])
    eligible[1] = False
    _, targets = nearest_cells_to_centroids(clusters, eligible)
    np.testing.assert_array_equal(targets, [[3, 4]])


def test_nearest_cell_ties_break_in_raster_order_and_respect_eligible():
    clusters = cluster_frontiers(STAIR, connectivity=4)
    has, targets = nearest_cells_to_centroids(clusters, np.ones(5, dtype=bool))
    np.testing.assert_array_equal(has, [True, True, True, True])
    # Cluster 3 = (3,4),(3,5) with centroid (3, 4.5): a tie, raster order picks (3,4).
    np.testing.assert_array_equal(targets, [[0, 1], [1, 2], [2, 3], [3, 4]])
    eligible = np.array([True, False, True, False, True])
    has, targets = nearest_cells_to_centroids(clusters, eligible)
    np.testing.assert_array_equal(has, [True, False, True, True])
    np.testing.assert_array_equal(targets, [[0, 1], [-1, -1], [2, 3], [3, 5]])


def test_nearest_cell_with_no_clusters():
    clusters = cluster_frontiers(np.full((3, 5), FREE, dtype=np.int8))
    has, targets = nearest_cells_to_centroids(clusters, np.zeros(0, dtype=bool))
    assert has.shape == (0,)
    assert targets.shape == (0, 2)


def test_nearest_cell_none_eligible():
    clusters = cluster_frontiers(STAIR, connectivity=4)
    has, targets = nearest_cells_to_centroids(clusters, np.zeros(5, dtype=bool))
    np.testing.assert_array_equal(has, [False] * 4)
    np.testing.assert_array_equal(targets, np.full((4, 2), -1))


# ----------------------------------------------------------------------------- properties
def _naive_unknown_around(belief: np.ndarray, cells: np.ndarray) -> int:
    height, width = belief.shape
    found = set()
    for r, c in cells:
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                rr, cc = r + dr, c + dc
                if 0 <= rr < height and 0 <= cc < width and belief[rr, cc] == UNKNOWN:
                    found.add((rr, cc))
    return len(found)


beliefs = st.tuples(
    st.integers(1, 12), st.integers(1, 12), st.integers(0, 2**32 - 1), st.floats(0.0, 1.0)
).map(
    lambda t: np.random.default_rng(t[2]).choice(
        np.array([UNKNOWN, FREE, OCCUPIED], dtype=np.int8),
        size=(t[0], t[1]),
        p=[t[3] * 0.6, 1 - t[3] * 0.6 - 0.1, 0.1],
    )
)


@settings(max_examples=150)
@given(belief=beliefs, connectivity=st.sampled_from([4, 8]), max_cells=st.integers(0, 6))
def test_cluster_properties_on_random_beliefs(belief, connectivity, max_cells):
    mask = frontier_mask(belief)
    assert set(zip(*np.nonzero(mask), strict=True)) == oracles.frontier_set(belief)
    clusters = cluster_frontiers(belief, connectivity=connectivity, max_cells=max_cells)
    # Every frontier cell appears exactly once, in raster order.
    flat = clusters.cell_rows * belief.shape[1] + clusters.cell_cols
    np.testing.assert_array_equal(flat, np.flatnonzero(mask))
    # Clusters partition the frontier cells; labels() is consistent with cell_cluster.
    labels = clusters.labels()
    np.testing.assert_array_equal(labels > 0, mask)
    np.testing.assert_array_equal(labels[mask] - 1, clusters.cell_cluster)
    np.testing.assert_array_equal(
        np.bincount(clusters.cell_cluster, minlength=clusters.count), clusters.sizes
    )
    assert (clusters.sizes >= 1).all()
    if max_cells > 0:
        assert (clusters.sizes <= max_cells).all()
    # Raster numbering: first cells of clusters 0..K-1 are increasing.
    firsts = [int(np.flatnonzero(clusters.cell_cluster == k)[0]) for k in range(clusters.count)]
    assert firsts == sorted(firsts)
    # Each cluster lies inside one connected component; unsplit clusters are the components.
    structure = ndimage.generate_binary_structure(2, 1 if connectivity == 4 else 2)
    components, n_components = ndimage.label(mask, structure=structure)
    comp_of_cell = components[clusters.cell_rows, clusters.cell_cols]
    for k in range(clusters.count):
        assert len(np.unique(comp_of_cell[clusters.cell_cluster == k])) == 1
    if max_cells == 0:
        assert clusters.count == n_components
    for k in range(clusters.count):
        cells = clusters.cells_of(k)
        np.testing.assert_allclose(clusters.centroids[k], cells.mean(axis=0))
    # Information gain by unknown neighbours matches a direct count.
    gains = unknown_around(belief, clusters)
    expected = [_naive_unknown_around(belief, clusters.cells_of(k)) for k in range(clusters.count)]
    np.testing.assert_array_equal(gains, expected)
    # The nearest eligible cell belongs to its cluster and is at minimal distance.
    if clusters.count == 0:
        return  # covered by test_nearest_cell_with_no_clusters
    has, targets = nearest_cells_to_centroids(clusters, np.ones(len(flat), dtype=bool))
    assert has.all()
    for k in range(clusters.count):
        cells = clusters.cells_of(k)
        assert any((cells == targets[k]).all(axis=1))
        d2 = ((cells - clusters.centroids[k]) ** 2).sum(axis=1)
        assert ((targets[k] - clusters.centroids[k]) ** 2).sum() == pytest.approx(d2.min())


@settings(max_examples=200)
@given(belief=beliefs, connectivity=st.sampled_from([4, 8]))
def test_union_find_labelling_is_scipy_labelling(belief, connectivity):
    """The rollouts' compiled labelling numbers the frontier exactly as scipy.ndimage.label
    does (the design card's clustering), and leaves its scratch grid as it found it."""
    structure = ndimage.generate_binary_structure(2, 1 if connectivity == 4 else 2)
    expected, count = ndimage.label(frontier_mask(belief), structure=structure)
    rows, cols, label, parent = (np.empty(belief.size, dtype=np.int64) for _ in range(4))
    index = np.full(belief.shape, -1, dtype=np.int64)
    mask = frontier_mask(belief)
    cells, groups = label_frontier_cells(
        mask, mask.sum(axis=1), connectivity, rows, cols, label, parent, index
    )
    assert groups == count
    assert cells == np.count_nonzero(expected)
    np.testing.assert_array_equal(rows[:cells] * belief.shape[1] + cols[:cells],
                                  np.flatnonzero(expected))  # fmt: skip
    np.testing.assert_array_equal(label[:cells], expected[rows[:cells], cols[:cells]] - 1)
    assert (index == -1).all()


@settings(max_examples=200)
@given(
    belief=beliefs,
    seed=st.integers(0, 2**32 - 1),
    changes=st.integers(1, 6),
)
def test_a_frontier_mask_updated_around_the_changes_is_the_mask_made_afresh(belief, seed, changes):
    """Unknown cells become known (as sensing does) inside a box; updating the mask one cell
    beyond the box gives the mask and row counts made from the whole grid."""
    rng = np.random.default_rng(seed)
    height, width = belief.shape
    frontier = np.zeros(belief.shape, dtype=bool)
    row_count = np.zeros(height, dtype=np.int64)
    update_frontier(belief, frontier, row_count, 0, height, 0, width)
    np.testing.assert_array_equal(frontier, frontier_mask(belief))
    for _ in range(changes):
        r0, c0 = int(rng.integers(height)), int(rng.integers(width))
        r1, c1 = r0 + int(rng.integers(1, 4)), c0 + int(rng.integers(1, 4))
        box = belief[r0:r1, c0:c1]
        box[box == UNKNOWN] = rng.choice([FREE, OCCUPIED], size=int((box == UNKNOWN).sum()))
        update_frontier(belief, frontier, row_count, r0 - 1, r1 + 1, c0 - 1, c1 + 1)
        np.testing.assert_array_equal(frontier, frontier_mask(belief))
        np.testing.assert_array_equal(row_count, frontier_mask(belief).sum(axis=1))


def test_union_find_labelling_joins_a_u_shape_in_raster_order():
    """Two arms met only at the bottom: one group, whose cells all get the first arm's label,
    then a later group numbered 1."""
    belief = belief_from(
        """
        ? ? ? ? ? ?
        . ? . ? . ?
        . ? . ? . ?
        . . . ? . ?
        ? ? ? ? ? ?
        """
    )
    n = belief.size
    rows, cols, label, parent = (np.empty(n, dtype=np.int64) for _ in range(4))
    index = np.full(belief.shape, -1, dtype=np.int64)
    mask = frontier_mask(belief)
    cells, groups = label_frontier_cells(
        mask, mask.sum(axis=1), 4, rows, cols, label, parent, index
    )
    assert groups == 2
    cells_at = zip(rows[:cells].tolist(), cols[:cells].tolist(), strict=True)
    by_cell = dict(zip(cells_at, label[:cells].tolist(), strict=True))
    assert by_cell[(1, 0)] == by_cell[(1, 2)] == by_cell[(3, 1)] == 0
    assert by_cell[(1, 4)] == by_cell[(3, 4)] == 1


@settings(max_examples=100)
@given(
    n=st.integers(1, 40),
    max_cells=st.integers(1, 8),
    seed=st.integers(0, 2**32 - 1),
)
def test_split_cells_properties(n, max_cells, seed):
    rng = np.random.default_rng(seed)
    flat = np.sort(rng.choice(15 * 15, size=n, replace=False))
    rows, cols = np.divmod(flat, 15)
    pieces = split_cells(rows, cols, max_cells)
    cells = list(zip(rows.tolist(), cols.tolist(), strict=True))
    assert [p.tolist() for p in pieces] == oracles.split(cells, max_cells)
    joined = np.sort(np.concatenate(pieces))
    np.testing.assert_array_equal(joined, np.arange(n))  # a partition of the indices
    assert all(1 <= len(p) <= max_cells for p in pieces)
    mins = [int(p.min()) for p in pieces]
    assert mins == sorted(mins)
