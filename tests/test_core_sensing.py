"""Tests for frontier_marl.core.sensing: square window and ray casting on hand-made maps."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN, new_belief
from frontier_marl.core.sensing import RaycastSensor, SquareSensor, make_sensor
from tests import oracles


def grid_from(text: str) -> np.ndarray:
    """True grid (bool, True = occupied) from rows of ``.`` and ``#``."""
    return np.array([[c == "#" for c in line.split()] for line in text.strip().splitlines()])


# 4x6 non-square true grid.
TRUE_4x6 = grid_from(
    """
    . # . . . #
    . . # . . .
    # . . . # .
    . . . # . .
    """
)


def expected_belief(true_grid: np.ndarray, known: np.ndarray) -> np.ndarray:
    out = np.full(true_grid.shape, UNKNOWN, dtype=np.int8)
    out[known] = np.where(true_grid[known], OCCUPIED, FREE)
    return out


# ----------------------------------------------------------------------------- square
@pytest.mark.parametrize(
    ("cell", "radius", "rows", "cols"),
    [
        ((0, 0), 2, slice(0, 3), slice(0, 3)),  # top-left corner
        ((3, 5), 2, slice(1, 4), slice(3, 6)),  # bottom-right corner
        ((0, 5), 1, slice(0, 2), slice(4, 6)),  # top-right corner
        ((3, 0), 1, slice(2, 4), slice(0, 2)),  # bottom-left corner
        ((1, 2), 3, slice(0, 4), slice(0, 6)),  # window larger than the map in rows
    ],
)
def test_square_sensor_clipped_window_non_square(cell, radius, rows, cols):
    sensor = SquareSensor(radius)
    belief = new_belief(TRUE_4x6.shape)
    seen = np.zeros(TRUE_4x6.shape, dtype=bool)
    known = np.zeros(TRUE_4x6.shape, dtype=bool)
    known[rows, cols] = True
    count = sensor.sense(TRUE_4x6, belief, cell, seen)
    assert count == known.sum()
    np.testing.assert_array_equal(belief, expected_belief(TRUE_4x6, known))
    np.testing.assert_array_equal(seen, known)
    assert belief.dtype == np.int8
    # Sensing again reveals nothing new and changes nothing.
    before = belief.copy()
    assert sensor.sense(TRUE_4x6, belief, cell, seen) == 0
    np.testing.assert_array_equal(belief, before)


def test_square_sensor_exact_corner_belief():
    belief = new_belief(TRUE_4x6.shape)
    assert SquareSensor(2).sense(TRUE_4x6, belief, (3, 5)) == 9
    U, F, X = UNKNOWN, FREE, OCCUPIED
    expected = np.array(
        [
            [U, U, U, U, U, U],
            [U, U, U, F, F, F],
            [U, U, U, F, X, F],
            [U, U, U, X, F, F],
        ],
        dtype=np.int8,
    )
    np.testing.assert_array_equal(belief, expected)


def test_square_sensor_counts_only_new_cells_and_sees_through_walls():
    sensor = SquareSensor(1)
    belief = new_belief(TRUE_4x6.shape)
    assert sensor.sense(TRUE_4x6, belief, (1, 1)) == 9  # rows 0-2, cols 0-2
    # Moving one cell right overlaps 6 known cells: 3 new (column 3).
    seen = np.zeros(TRUE_4x6.shape, dtype=bool)
    assert sensor.sense(TRUE_4x6, belief, (1, 2), seen) == 3
    expected_seen = np.zeros(TRUE_4x6.shape, dtype=bool)
    expected_seen[0:3, 1:4] = True
    np.testing.assert_array_equal(seen, expected_seen)  # seen marks overlaps too
    known = np.zeros(TRUE_4x6.shape, dtype=bool)
    known[0:3, 0:4] = True
    np.testing.assert_array_equal(belief, expected_belief(TRUE_4x6, known))


def test_square_sensor_without_seen_argument():
    belief = new_belief((3, 5))
    assert SquareSensor(1).sense(np.zeros((3, 5), dtype=bool), belief, (2, 4)) == 4


# ----------------------------------------------------------------------------- raycast
# 5x7 map, robot at (2,0), a wall in column 2 (rows 1-3).
WALL = grid_from(
    """
    . . . . . . .
    . . # . . . .
    . . # . . . .
    . . # . . . .
    . . . . . . .
    """
)


def test_raycast_wall_blocks_cells_behind_it():
    sensor = RaycastSensor(4)
    belief = new_belief(WALL.shape)
    seen = np.zeros(WALL.shape, dtype=bool)
    count = sensor.sense(WALL, belief, (2, 0), seen)
    # Disc of radius 4 clipped to the map: columns 0-2 in full, (0..4, 3) and (2, 4).
    # Columns 0-2 are all visible (the wall cells included); every disc cell of columns 3-4
    # lies behind the wall.
    expected_seen = np.zeros(WALL.shape, dtype=bool)
    expected_seen[:, 0:3] = True
    np.testing.assert_array_equal(seen, expected_seen)
    assert count == 15
    np.testing.assert_array_equal(belief, expected_belief(WALL, expected_seen))
    assert belief[2, 2] == OCCUPIED  # the blocking wall cell is itself seen
    assert belief[2, 3] == UNKNOWN and belief[2, 4] == UNKNOWN


def test_raycast_same_cells_visible_without_the_wall():
    open_grid = np.zeros(WALL.shape, dtype=bool)
    visible = RaycastSensor(4).visible(open_grid, (2, 0))
    expected = np.zeros(WALL.shape, dtype=bool)
    for r in range(5):
        for c in range(7):
            expected[r, c] = (r - 2) ** 2 + c**2 <= 16
    np.testing.assert_array_equal(visible, expected)
    assert visible[:, 3].all() and visible[2, 4]


def test_raycast_disc_only_at_corner_of_non_square_map():
    true_grid = np.zeros((3, 5), dtype=bool)
    belief = new_belief(true_grid.shape)
    seen = np.zeros(true_grid.shape, dtype=bool)
    assert RaycastSensor(2).sense(true_grid, belief, (0, 0), seen) == 6
    expected = np.array(
        [
            [1, 1, 1, 0, 0],
            [1, 1, 0, 0, 0],
            [1, 0, 0, 0, 0],
        ],
        dtype=bool,
    )
    np.testing.assert_array_equal(seen, expected)
    np.testing.assert_array_equal(belief, np.where(expected, FREE, UNKNOWN))
    assert RaycastSensor(2).sense(true_grid, belief, (0, 0), seen) == 0


def test_raycast_disc_in_open_field():
    true_grid = np.zeros((7, 9), dtype=bool)
    visible = RaycastSensor(2).visible(true_grid, (3, 4))
    expected = np.zeros(true_grid.shape, dtype=bool)
    expected[2:5, 3:6] = True  # the 3x3 block (|dr|, |dc| <= 1)
    expected[[1, 5, 3, 3], [4, 4, 2, 6]] = True  # (+-2, 0) and (0, +-2); (1, 2) is outside
    np.testing.assert_array_equal(visible, expected)
    assert visible.sum() == 13


def test_raycast_walled_cell_sees_only_its_ring():
    true_grid = grid_from(
        """
        . . . . . . .
        . # # # . . .
        . # . # . . .
        . # # # . . .
        . . . . . . .
        """
    )
    belief = new_belief(true_grid.shape)
    seen = np.zeros(true_grid.shape, dtype=bool)
    assert RaycastSensor(3).sense(true_grid, belief, (2, 2), seen) == 9
    expected = np.zeros(true_grid.shape, dtype=bool)
    expected[1:4, 1:4] = True
    np.testing.assert_array_equal(seen, expected)
    np.testing.assert_array_equal(belief, expected_belief(true_grid, expected))


def test_raycast_four_neighbours_always_seen_behind_diagonal_walls():
    # Diagonal walls all around: the 4-neighbours are free and must be seen.
    true_grid = grid_from(
        """
        # . #
        . . .
        # . #
        """
    )
    rows, cols = np.nonzero(RaycastSensor(1).visible(true_grid, (1, 1)))
    assert {(int(r), int(c)) for r, c in zip(rows, cols, strict=True)} == {
        (0, 1),
        (1, 0),
        (1, 1),
        (1, 2),
        (2, 1),
    }


# ----------------------------------------------------------------------------- properties
@settings(max_examples=80)
@given(
    height=st.integers(1, 12),
    width=st.integers(1, 12),
    density=st.floats(0.0, 0.6),
    radius=st.integers(1, 5),
    seed=st.integers(0, 2**32 - 1),
)
def test_sensor_properties(height, width, density, radius, seed):
    rng = np.random.default_rng(seed)
    true_grid = rng.random((height, width)) < density
    row, col = int(rng.integers(height)), int(rng.integers(width))
    true_grid[row, col] = False
    square, ray = SquareSensor(radius), RaycastSensor(radius)
    visible = ray.visible(true_grid, (row, col))
    for model, sensor in (("square", square), ("raycast", ray)):
        expected = oracles.visible(true_grid, (row, col), radius, model)
        assert set(zip(*np.nonzero(sensor.visible(true_grid, (row, col))), strict=True)) == expected
    r_idx, c_idx = np.indices(true_grid.shape)
    disc = (r_idx - row) ** 2 + (c_idx - col) ** 2 <= radius * radius
    chebyshev = np.maximum(abs(r_idx - row), abs(c_idx - col))
    assert not (visible & ~disc).any()  # only the Euclidean disc
    manhattan = abs(r_idx - row) + abs(c_idx - col)
    assert visible[manhattan <= 1].all()  # the robot's cell and its 4-neighbours
    assert visible[(chebyshev <= 1) & disc].all()  # and its diagonals once inside the disc
    # With no obstacle the whole clipped disc is visible.
    assert ray.visible(np.zeros_like(true_grid), (row, col)).sum() == disc.sum()
    # Both sensors write the truth, count the new cells, and fill ``seen``.
    for sensor, expected_seen in ((square, chebyshev <= radius), (ray, visible)):
        belief = new_belief(true_grid.shape)
        seen = np.zeros(true_grid.shape, dtype=bool)
        assert sensor.sense(true_grid, belief, (row, col), seen) == expected_seen.sum()
        np.testing.assert_array_equal(seen, expected_seen)
        np.testing.assert_array_equal(belief, expected_belief(true_grid, expected_seen))
        assert sensor.sense(true_grid, belief, (row, col), seen) == 0


# ----------------------------------------------------------------------------- factory
def test_make_sensor():
    assert isinstance(make_sensor("square", 3), SquareSensor)
    ray = make_sensor("raycast", 2)
    assert isinstance(ray, RaycastSensor) and ray.range == 2
    with pytest.raises(ValueError, match="sensor"):
        make_sensor("lidar", 3)
