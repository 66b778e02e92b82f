"""Tests for frontier_marl.core.planning: A* and distance fields on hand-made maps, and both
against a plain BFS oracle on random maps."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frontier_marl.core.planning import (
    UNSEEN,
    astar,
    astar_into,
    distance_field,
    distance_fields,
    path_search_scratch,
)
from tests import oracles


def bfs_distances(passable, start):
    return distance_field(np.asarray(passable, dtype=bool), True, int(start[0]), int(start[1]))


def passable_from(text: str) -> np.ndarray:
    """Bool grid from rows of ``.`` (passable) and ``#`` (blocked)."""
    return np.array([[c == "." for c in line.split()] for line in text.strip().splitlines()])


# 4x6, non-square. The only shortest path from (0,0) to (0,4) goes down column 2, along
# row 2 and up column 4.
MAZE = passable_from(
    """
    . . . # . .
    # # . # . #
    . . . . . .
    . # # # # .
    """
)


def assert_valid_path(passable, path, start, goal):
    assert path.ndim == 2 and path.shape[1] == 2
    assert tuple(path[0]) == tuple(start)
    assert tuple(path[-1]) == tuple(goal)
    steps = np.abs(np.diff(path, axis=0)).sum(axis=1)
    np.testing.assert_array_equal(steps, np.ones(len(path) - 1))  # 4-adjacent moves
    assert passable[path[1:, 0], path[1:, 1]].all()
    assert len({tuple(cell) for cell in path.tolist()}) == len(path)  # no cell twice


def test_astar_unique_shortest_path_non_square():
    path = astar(MAZE, (0, 0), (0, 4))
    expected = [[0, 0], [0, 1], [0, 2], [1, 2], [2, 2], [2, 3], [2, 4], [1, 4], [0, 4]]
    np.testing.assert_array_equal(path, expected)
    assert path.dtype.kind == "i"


def test_astar_reverse_direction():
    path = astar(MAZE, (0, 4), (0, 0))
    expected = [[0, 4], [1, 4], [2, 4], [2, 3], [2, 2], [1, 2], [0, 2], [0, 1], [0, 0]]
    np.testing.assert_array_equal(path, expected)


@pytest.mark.parametrize(
    ("start", "goal", "length"),
    [((0, 0), (3, 0), 7), ((3, 0), (3, 5), 7), ((0, 5), (3, 5), 5), ((2, 0), (0, 5), 7)],
)
def test_astar_known_lengths(start, goal, length):
    path = astar(MAZE, start, goal)
    assert path is not None
    assert len(path) - 1 == length
    assert_valid_path(MAZE, path, start, goal)


WALLED = passable_from(
    """
    . . # . .
    . . # . .
    . . # . .
    """
)


def test_astar_unreachable_returns_none():
    assert astar(WALLED, (0, 0), (2, 4)) is None
    assert astar(WALLED, (1, 3), (1, 0)) is None


def test_astar_goal_not_passable_returns_none():
    assert astar(WALLED, (0, 0), (1, 2)) is None
    assert astar(MAZE, (0, 0), (1, 0)) is None


def test_astar_goal_out_of_bounds_returns_none():
    assert astar(WALLED, (0, 0), (3, 0)) is None
    assert astar(WALLED, (0, 0), (0, 5)) is None


def test_astar_start_equals_goal():
    np.testing.assert_array_equal(astar(MAZE, (2, 3), (2, 3)), [[2, 3]])


def test_astar_start_need_not_be_passable():
    passable = np.ones((3, 4), dtype=bool)
    passable[1, 1] = False
    path = astar(passable, (1, 1), (1, 3))
    np.testing.assert_array_equal(path, [[1, 1], [1, 2], [1, 3]])


def test_astar_open_grid_path_length_is_manhattan():
    passable = np.ones((5, 9), dtype=bool)
    path = astar(passable, (4, 0), (0, 8))
    assert len(path) - 1 == 12
    assert_valid_path(passable, path, (4, 0), (0, 8))


def test_bfs_distances_exact_non_square():
    passable = passable_from(
        """
        . # . .
        . . . #
        # # . .
        """
    )
    expected = np.array(
        [
            [0, -1, 4, 5],
            [1, 2, 3, -1],
            [-1, -1, 4, 5],
        ]
    )
    np.testing.assert_array_equal(bfs_distances(passable, (0, 0)), expected)


def test_bfs_distances_unreachable_region():
    dist = bfs_distances(WALLED, (1, 0))
    expected = np.array(
        [
            [1, 2, -1, -1, -1],
            [0, 1, -1, -1, -1],
            [1, 2, -1, -1, -1],
        ]
    )
    np.testing.assert_array_equal(dist, expected)


def test_astar_and_distance_fields_equal_the_bfs_oracle_on_random_maps():
    """On 300 random maps A*'s path length and the distance field both equal a plain BFS."""
    rng = np.random.default_rng(20240607)
    reachable_pairs = 0
    for trial in range(300):
        height, width = int(rng.integers(1, 21)), int(rng.integers(1, 21))
        density = float(rng.uniform(0.0, 0.55))
        passable = rng.random((height, width)) >= density
        free = np.argwhere(passable)
        if len(free) == 0:
            continue
        start = tuple(int(v) for v in free[rng.integers(len(free))])
        dist = oracles.bfs(passable, start)
        np.testing.assert_array_equal(bfs_distances(passable, start), dist)
        for _ in range(3):
            # Goals mostly on free cells, sometimes anywhere (blocked goals must give None).
            if rng.random() < 0.8:
                goal = tuple(int(v) for v in free[rng.integers(len(free))])
            else:
                goal = (int(rng.integers(height)), int(rng.integers(width)))
            path = astar(passable, start, goal)
            context = f"trial {trial}: {height}x{width}, start {start}, goal {goal}"
            if dist[goal] < 0:
                assert path is None, context
                continue
            reachable_pairs += 1
            assert path is not None, context
            assert len(path) - 1 == dist[goal], context
            assert_valid_path(passable, path, start, goal)
    assert reachable_pairs > 300  # the loop really exercised reachable pairs


def test_bfs_distances_match_astar_from_every_cell_small_map():
    passable = MAZE
    for start in map(tuple, np.argwhere(passable).tolist()):
        dist = bfs_distances(passable, start)
        assert dist[start] == 0
        assert (dist[~passable] == -1).all()
        for goal in map(tuple, np.argwhere(passable).tolist()):
            path = astar(passable, start, goal)
            assert (path is None) == (dist[goal] < 0)
            if path is not None:
                assert len(path) - 1 == dist[goal]


def test_distance_fields_stack_one_field_per_source():
    sources = [(0, 0), (2, 5), (3, 0)]
    fields = distance_fields(MAZE, sources)
    assert fields.shape == (3, *MAZE.shape)
    for field, source in zip(fields, sources, strict=True):
        np.testing.assert_array_equal(field, oracles.bfs(MAZE, source))
    assert distance_fields(MAZE, []).shape == (0, *MAZE.shape)


def test_distance_field_on_a_belief_uses_free_cells_only():
    belief = np.array([[0, 0, -1, 0], [1, 0, 0, 0]], dtype=np.int8)
    np.testing.assert_array_equal(distance_field(belief, 0, 0, 0), [[0, 1, -1, 5], [-1, 2, 3, 4]])


def _heapq_astar(passable, start, goal):
    """The planner's search written with Python's heapq: nodes leave in order of
    (f, -g, cell), f = g + the Euclidean distance to the goal."""
    height, width = passable.shape
    (s_row, s_col), (g_row, g_col) = start, goal
    if not passable[g_row, g_col]:
        return None
    source, target = s_row * width + s_col, g_row * width + g_col
    cost, parent = {source: 0}, {}
    heap = [(math.hypot(s_row - g_row, s_col - g_col), 0, source)]
    while heap:
        _, neg_g, cell = heapq.heappop(heap)
        if cell == target:
            path = [cell]
            while path[-1] != source:
                path.append(parent[path[-1]])
            return np.array([divmod(c, width) for c in reversed(path)])
        g = -neg_g
        if g > cost[cell]:
            continue
        row, col = divmod(cell, width)
        for n_row, n_col in ((row - 1, col), (row + 1, col), (row, col - 1), (row, col + 1)):
            if 0 <= n_row < height and 0 <= n_col < width and passable[n_row, n_col]:
                neighbour = n_row * width + n_col
                if g + 1 < cost.get(neighbour, 1 << 60):
                    cost[neighbour], parent[neighbour] = g + 1, cell
                    f = g + 1 + math.sqrt((n_row - g_row) ** 2 + (n_col - g_col) ** 2)
                    heapq.heappush(heap, (f, -(g + 1), neighbour))
    return None


@settings(max_examples=150, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    shape=st.tuples(st.integers(1, 14), st.integers(1, 14)),
    density=st.floats(0.0, 0.45),
)
def test_astar_takes_the_same_path_as_a_heapq_search(seed, shape, density):
    """Same cells, not only the same length: the walk and the plan cache depend on which
    shortest path is taken. The compiled search keeps its buffers between calls."""
    rng = np.random.default_rng(seed)
    passable = rng.random(shape) >= density
    scratch, out = path_search_scratch(shape), np.empty((passable.size, 2), dtype=np.int64)
    cells = [tuple(int(x) for x in rng.integers(0, shape)) for _ in range(6)]
    for start, goal in zip(cells[:-1], cells[1:], strict=True):
        expected = _heapq_astar(passable, start, goal)
        length = astar_into(passable, True, *start, *goal, out, scratch)
        if expected is None:
            assert length == 0
        else:
            np.testing.assert_array_equal(out[:length], expected)
        assert (scratch[0] == UNSEEN).all()  # left as found
