"""Tests for frontier_marl.core.world: movement, sensing credit, multi-robot rules, invariants."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from frontier_marl.core.frontiers import frontier_mask
from frontier_marl.core.grid import FREE, UNKNOWN
from frontier_marl.core.maps import random_obstacle_map, sample_start_cells
from frontier_marl.core.sensing import RaycastSensor, SquareSensor
from frontier_marl.core.world import FULL_PATH, World, WorldParams
from tests import oracles


def grid_from(text: str) -> np.ndarray:
    """True grid (bool, True = occupied) from rows of ``.`` and ``#``."""
    return np.array([[c == "#" for c in line.split()] for line in text.strip().splitlines()])


# A 1-wide corridor of 8 cells (3x8 map).
CORRIDOR = grid_from(
    """
    # # # # # # # #
    . . . . . . . .
    # # # # # # # #
    """
)


def make_world(true_grid, starts, radius=10, cells_per_step=1, sensor=SquareSensor, **kw):
    params = WorldParams(sensor(radius), cells_per_step, **kw)
    return World(np.array(true_grid, dtype=bool), np.array(starts), params)


# ----------------------------------------------------------------------------- single robot
def test_one_cell_per_step_moves_one_cell():
    world = make_world(CORRIDOR, [[1, 0]], cells_per_step=1)
    result = world.move([(1, 7)])
    np.testing.assert_array_equal(result.paths[0], [[1, 0], [1, 1]])
    np.testing.assert_array_equal(world.positions, [[1, 1]])
    np.testing.assert_array_equal(result.reached, [False])
    np.testing.assert_array_equal(world.travelled, [1])
    np.testing.assert_array_equal(result.new_cells, [0])  # radius 10: all known from the start
    # The plan is kept: the next steps continue along the corridor.
    world.move([(1, 7)])
    world.move([(1, 7)])
    np.testing.assert_array_equal(world.positions, [[1, 3]])
    np.testing.assert_array_equal(world.travelled, [3])


def test_full_path_walks_all_the_way():
    world = make_world(CORRIDOR, [[1, 0]], cells_per_step=FULL_PATH)
    result = world.move([(1, 7)])
    np.testing.assert_array_equal(result.paths[0], [[1, c] for c in range(8)])
    np.testing.assert_array_equal(world.positions, [[1, 7]])
    np.testing.assert_array_equal(result.reached, [True])
    np.testing.assert_array_equal(world.travelled, [7])


def test_cells_per_step_three_and_stopping_at_the_target():
    world = make_world(CORRIDOR, [[1, 0]], cells_per_step=3)
    result = world.move([(1, 4)])
    np.testing.assert_array_equal(result.paths[0], [[1, 0], [1, 1], [1, 2], [1, 3]])
    result = world.move([(1, 4)])  # one cell left: stops at the target
    np.testing.assert_array_equal(result.paths[0], [[1, 3], [1, 4]])
    np.testing.assert_array_equal(result.reached, [True])
    np.testing.assert_array_equal(world.travelled, [4])


def test_stay_and_unreachable_targets_keep_the_robot_in_place():
    world = make_world(CORRIDOR, [[1, 3]], radius=2)
    for target in (None, (1, 3), (0, 3), (1, 7)):  # stay, here, a wall, an unknown cell
        result = world.move([target])
        np.testing.assert_array_equal(result.paths[0], [[1, 3]])
        np.testing.assert_array_equal(result.new_cells, [0])
        np.testing.assert_array_equal(result.reached, [False])
    np.testing.assert_array_equal(world.positions, [[1, 3]])
    np.testing.assert_array_equal(world.travelled, [0])


def test_new_cells_credit_single_robot():
    world = make_world(CORRIDOR, [[1, 0]], radius=1)
    # Initially known: rows 0-2, columns 0-1.
    assert np.count_nonzero(world.belief != UNKNOWN) == 6
    result = world.move([(1, 1)])
    np.testing.assert_array_equal(result.new_cells, [3])  # column 2
    result = world.move([(1, 2)])
    np.testing.assert_array_equal(result.new_cells, [3])  # column 3
    result = world.move([(1, 1)])  # back: nothing new
    np.testing.assert_array_equal(result.new_cells, [0])
    assert np.count_nonzero(world.belief != UNKNOWN) == 12


def test_new_cells_credit_full_path_senses_every_cell_entered():
    world = make_world(CORRIDOR, [[1, 0]], radius=1, cells_per_step=FULL_PATH)
    world.move([(1, 1)])
    world.move([(1, 2)])
    result = world.move([(1, 1)])
    np.testing.assert_array_equal(result.new_cells, [0])
    # (1,3) is known now; walking (1,1) -> (1,3) reveals column 4 only.
    result = world.move([(1, 3)])
    np.testing.assert_array_equal(result.new_cells, [3])
    np.testing.assert_array_equal(world.seen[0][:, :5], np.ones((3, 5), dtype=bool))
    assert not world.seen[0][:, 5:].any()


def test_start_cells_are_sensed_and_seen():
    world = make_world(CORRIDOR, [[1, 6]], radius=1)
    expected = np.zeros(CORRIDOR.shape, dtype=bool)
    expected[:, 5:8] = True
    np.testing.assert_array_equal(world.seen[0], expected)
    np.testing.assert_array_equal(world.belief != UNKNOWN, expected)


# ----------------------------------------------------------------------------- multi robot
def test_shared_new_cells_credited_to_first_robot_in_agent_order():
    open_map = np.zeros((3, 7), dtype=bool)
    # Robot 0 knows columns 0-2, robot 1 knows columns 4-6; column 3 is unknown.
    world = make_world(open_map, [[1, 1], [1, 5]], radius=1)
    assert (world.belief[:, 3] == UNKNOWN).all()
    result = world.move([(1, 2), (1, 4)])
    np.testing.assert_array_equal(result.new_cells, [3, 0])
    assert (world.belief != UNKNOWN).all()
    assert world.seen[0][:, 3].all() and world.seen[1][:, 3].all()


def test_robots_reveal_their_own_cells():
    world = make_world(CORRIDOR, [[1, 2], [1, 5]], radius=1)
    result = world.move([(1, 1), (1, 6)])
    np.testing.assert_array_equal(result.new_cells, [3, 3])


CORRIDOR_6 = grid_from(
    """
    # # # # # #
    . . . . . .
    # # # # # #
    """
)


@pytest.mark.parametrize("cells_per_step", [1, 2, FULL_PATH])
@pytest.mark.parametrize("targets", [[(1, 3), (1, 2)], [(1, 5), (1, 0)]])
def test_robots_in_one_wide_corridor_never_swap(cells_per_step, targets):
    world = make_world(CORRIDOR_6, [[1, 2], [1, 3]], cells_per_step=cells_per_step)
    for _ in range(3):
        result = world.move(targets)
        np.testing.assert_array_equal(world.positions, [[1, 2], [1, 3]])
        np.testing.assert_array_equal(result.paths[0], [[1, 2]])
        np.testing.assert_array_equal(result.paths[1], [[1, 3]])
    np.testing.assert_array_equal(world.travelled, [0, 0])


def test_robot_behind_waits_for_the_robot_ahead_one_cell_per_step():
    world = make_world(CORRIDOR_6, [[1, 2], [1, 3]], cells_per_step=1)
    result = world.move([(1, 4), (1, 5)])
    # Robot 0 acts first and finds (1,3) occupied: it waits; robot 1 moves on.
    np.testing.assert_array_equal(world.positions, [[1, 2], [1, 4]])
    np.testing.assert_array_equal(result.paths[0], [[1, 2]])
    np.testing.assert_array_equal(result.paths[1], [[1, 3], [1, 4]])
    # Next step robot 0 acts first again and (1,3) is free now: both advance.
    world.move([(1, 4), (1, 5)])
    np.testing.assert_array_equal(world.positions, [[1, 3], [1, 5]])
    result = world.move([(1, 4), (1, 5)])
    np.testing.assert_array_equal(world.positions, [[1, 4], [1, 5]])
    np.testing.assert_array_equal(result.paths[1], [[1, 5]])  # already there: stays
    np.testing.assert_array_equal(result.reached, [True, False])
    np.testing.assert_array_equal(world.travelled, [2, 2])


def test_robot_behind_follows_in_the_same_sub_step_when_ahead_acts_first():
    world = make_world(CORRIDOR_6, [[1, 3], [1, 2]], cells_per_step=1)
    world.move([(1, 5), (1, 4)])
    np.testing.assert_array_equal(world.positions, [[1, 4], [1, 3]])


def test_full_path_follow_the_leader():
    world = make_world(CORRIDOR_6, [[1, 2], [1, 3]], cells_per_step=FULL_PATH)
    result = world.move([(1, 4), (1, 5)])
    np.testing.assert_array_equal(world.positions, [[1, 4], [1, 5]])
    np.testing.assert_array_equal(result.paths[0], [[1, 2], [1, 3], [1, 4]])
    np.testing.assert_array_equal(result.paths[1], [[1, 3], [1, 4], [1, 5]])
    np.testing.assert_array_equal(result.reached, [True, True])


def test_two_robots_same_target_never_share_it():
    world = make_world(CORRIDOR_6, [[1, 0], [1, 4]], cells_per_step=FULL_PATH)
    result = world.move([(1, 2), (1, 2)])
    np.testing.assert_array_equal(world.positions, [[1, 2], [1, 3]])
    np.testing.assert_array_equal(result.reached, [True, False])
    np.testing.assert_array_equal(world.travelled, [2, 1])


def test_move_needs_one_target_per_robot():
    world = make_world(CORRIDOR_6, [[1, 0], [1, 4]])
    with pytest.raises(ValueError):
        world.move([(1, 2)])


# ----------------------------------------------------------------------------- construction
def test_bad_start_cells_raise():
    with pytest.raises(ValueError, match="free"):
        make_world(CORRIDOR, [[0, 0]])
    with pytest.raises(ValueError, match="distinct"):
        make_world(CORRIDOR, [[1, 1], [1, 1]])


def test_state_arrays_are_read_only():
    world = make_world(CORRIDOR, [[1, 0], [1, 5]], radius=1)
    for name in ("belief", "positions", "seen", "travelled", "true_grid", "start_region"):
        array = getattr(world, name)
        with pytest.raises(ValueError):
            array[(0,) * array.ndim] = 1
    # The world itself still changes.
    world.move([(1, 1), None])
    np.testing.assert_array_equal(world.positions, [[1, 1], [1, 5]])


def test_explored_fraction_and_start_region():
    true_grid = grid_from(
        """
        . . # . .
        . . # . .
        . . # # #
        """
    )
    world = make_world(true_grid, [[0, 0]], radius=1, cells_per_step=FULL_PATH)
    expected_region = np.zeros(true_grid.shape, dtype=bool)
    expected_region[:, 0:2] = True
    np.testing.assert_array_equal(world.start_region, expected_region)
    # Known: rows 0-1, columns 0-1 (4 free cells).
    assert world.explored_fraction("all") == pytest.approx(4 / 15)
    assert world.explored_fraction("free") == pytest.approx(4 / 10)
    assert world.explored_fraction("reachable") == pytest.approx(4 / 6)
    with pytest.raises(ValueError, match="threshold_basis"):
        world.explored_fraction("visible")
    world.move([(1, 1)])  # sees rows 0-2, columns 0-2
    assert world.explored_fraction("all") == pytest.approx(9 / 15)
    assert world.explored_fraction("free") == pytest.approx(6 / 10)
    assert world.explored_fraction("reachable") == pytest.approx(1.0)
    assert world.n_agents == 1 and world.shape == (3, 5)


def test_slots_of_a_corridor_robot():
    world = make_world(CORRIDOR, [[1, 3]], radius=1)
    # Known columns 2-4: frontier cells (1,2) and (1,4), two single-cell clusters.
    slots = world.slots(0, n_slots=3, sort_by_distance=False)
    np.testing.assert_array_equal(slots.cluster, [0, 1, -1])
    np.testing.assert_array_equal(slots.valid, [True, True, False])
    np.testing.assert_array_equal(slots.target, [[1, 2], [1, 4], [-1, -1]])
    np.testing.assert_allclose(slots.distance, [1.0, 1.0, 0.0])
    np.testing.assert_array_equal(slots.size, [1, 1, 0])
    np.testing.assert_array_equal(slots.path_length, [1, 1, -1])
    np.testing.assert_array_equal(slots.mask, [1, 1, 0])
    assert slots.live == 2


def test_slots_when_the_map_is_fully_explored():
    world = make_world(CORRIDOR, [[1, 3]], radius=10)
    assert world.clusters().count == 0
    slots = world.slots(0, n_slots=3, sort_by_distance=True)
    assert slots.live == 0
    np.testing.assert_array_equal(slots.cluster, [-1, -1, -1])
    np.testing.assert_array_equal(slots.mask, [1, 0, 0])  # slot 0 is the idle action


# ----------------------------------------------------------------------------- properties
def _check_frontiers(world: World, max_cluster_cells: int, connectivity: int) -> None:
    belief = world.belief
    height, width = belief.shape
    unknown = np.pad(belief == UNKNOWN, 1, constant_values=False)
    near_unknown = unknown[:-2, 1:-1] | unknown[2:, 1:-1] | unknown[1:-1, :-2] | unknown[1:-1, 2:]
    definition = (belief == FREE) & near_unknown
    np.testing.assert_array_equal(frontier_mask(belief), definition)
    assert set(zip(*np.nonzero(definition), strict=True)) == oracles.frontier_set(belief)
    clusters = world.clusters()
    labels = clusters.labels()
    np.testing.assert_array_equal(labels > 0, definition)  # clusters cover exactly the frontier
    assert len(clusters.cell_rows) == definition.sum()  # each frontier cell exactly once
    np.testing.assert_array_equal(
        np.bincount(clusters.cell_cluster, minlength=clusters.count), clusters.sizes
    )
    assert (clusters.sizes >= 1).all()
    if max_cluster_cells > 0:
        assert (clusters.sizes <= max_cluster_cells).all()
    structure = ndimage.generate_binary_structure(2, 1 if connectivity == 4 else 2)
    components, _ = ndimage.label(definition, structure=structure)
    for k in range(clusters.count):
        cells = clusters.cells_of(k)
        assert len(np.unique(components[cells[:, 0], cells[:, 1]])) == 1
        np.testing.assert_allclose(clusters.centroids[k], cells.mean(axis=0))
    gains = world.cluster_gains()
    assert gains.shape == (clusters.count,)


def _check_state(world: World, previous_known: np.ndarray) -> np.ndarray:
    true_grid, belief = world.true_grid, world.belief
    known = belief != UNKNOWN
    # The belief never contradicts the truth.
    np.testing.assert_array_equal(belief[known], true_grid[known].astype(np.int8))
    assert not (previous_known & ~known).any()  # known cells only grow
    positions = world.positions
    assert not true_grid[positions[:, 0], positions[:, 1]].any()  # robots on free cells
    assert (belief[positions[:, 0], positions[:, 1]] == FREE).all()
    assert len({tuple(p) for p in positions.tolist()}) == len(positions)  # never shared
    seen = world.seen
    assert not (seen.any(axis=0) & ~known).any()
    for agent, (row, col) in enumerate(positions.tolist()):
        assert seen[agent, row, col]
    return known


def _check_slots(world: World, slots, clusters, agent: int, n_slots: int) -> None:
    """The slot rules of frontier_marl.core.slots, checked with a BFS oracle."""
    position = tuple(int(v) for v in world.positions[agent])
    dist = oracles.bfs(world.belief == FREE, position)
    reachable = []  # (distance to centroid, cluster, target) of every reachable cluster
    for k in range(clusters.count):
        cells = [tuple(c) for c in clusters.cells_of(k).tolist() if dist[tuple(c)] >= 0]
        if cells:
            centroid = clusters.centroids[k]
            target = min(cells, key=lambda c: (c[0] - centroid[0]) ** 2 + (c[1] - centroid[1]) ** 2)
            reachable.append((float(np.hypot(*(centroid - position))), k, target))
    chosen = sorted(sorted(reachable)[:n_slots], key=lambda entry: entry[1])
    live = slots.live
    assert live == slots.valid.sum() == len(chosen) <= n_slots
    shown = {int(slots.cluster[i]): i for i in range(live)}
    assert sorted(shown) == [k for _, k, _ in chosen]
    for distance, k, target in chosen:
        slot = shown[k]
        assert tuple(slots.target[slot]) == target
        assert slots.path_length[slot] == dist[target]
        assert slots.distance[slot] == pytest.approx(distance)
    assert (slots.cluster[live:] == -1).all() and (slots.path_length[live:] == -1).all()


@settings(max_examples=60)
@given(
    height=st.integers(5, 15),
    width=st.integers(5, 15),
    obstacle_prob=st.floats(0.0, 0.4),
    n_agents=st.integers(1, 3),
    sensor=st.sampled_from(["square", "raycast"]),
    radius=st.integers(1, 3),
    cells_per_step=st.sampled_from([1, 2, 3, FULL_PATH]),
    connectivity=st.sampled_from([4, 8]),
    max_cluster_cells=st.sampled_from([0, 1, 3, 8]),
    gain=st.sampled_from(["size", "unknown"]),
    seed=st.integers(0, 2**32 - 1),
)
def test_world_invariants_under_random_play(
    height,
    width,
    obstacle_prob,
    n_agents,
    sensor,
    radius,
    cells_per_step,
    connectivity,
    max_cluster_cells,
    gain,
    seed,
):
    rng = np.random.default_rng(seed)
    true_grid = random_obstacle_map(height, width, obstacle_prob, rng)
    n_agents = min(n_agents, int(np.count_nonzero(~true_grid)))
    starts = sample_start_cells(~true_grid, n_agents, rng)
    sensor_model = SquareSensor(radius) if sensor == "square" else RaycastSensor(radius)
    params = WorldParams(sensor_model, cells_per_step, connectivity, max_cluster_cells, gain)
    world = World(true_grid, starts, params)
    known = _check_state(world, np.zeros(true_grid.shape, dtype=bool))
    travelled = world.travelled.copy()
    for _ in range(25):
        _check_frontiers(world, max_cluster_cells, connectivity)
        clusters = world.clusters()
        passable = world.belief == FREE
        targets: list[tuple[int, int] | None] = []
        for agent in range(n_agents):
            slots = world.slots(agent, n_slots=4, sort_by_distance=bool(rng.integers(2)))
            _check_slots(world, slots, clusters, agent, n_slots=4)
            live = np.flatnonzero(slots.valid)
            if len(live) and rng.random() < 0.9:
                targets.append(tuple(int(v) for v in slots.target[rng.choice(live)]))
            else:
                targets.append(None)
        before = world.positions.copy()
        to_target = [None if t is None else oracles.bfs(passable, t) for t in targets]
        known_before = int(np.count_nonzero(world.belief != UNKNOWN))
        result = world.move(targets)
        # Paths start where the robot stood, move between 4-adjacent cells, end where it stands.
        for agent, path in enumerate(result.paths):
            np.testing.assert_array_equal(path[0], before[agent])
            np.testing.assert_array_equal(path[-1], world.positions[agent])
            if len(path) > 1:
                np.testing.assert_array_equal(np.abs(np.diff(path, axis=0)).sum(axis=1), 1)
            if cells_per_step != FULL_PATH:
                assert len(path) - 1 <= cells_per_step
            if targets[agent] is None:
                assert len(path) == 1
            assert result.reached[agent] == (len(path) > 1 and tuple(path[-1]) == targets[agent])
            if to_target[agent] is not None:  # every move follows a shortest known-free path
                remaining = to_target[agent][path[:, 0], path[:, 1]]
                np.testing.assert_array_equal(remaining, remaining[0] - np.arange(len(path)))
        np.testing.assert_array_equal(
            world.travelled - travelled, [len(p) - 1 for p in result.paths]
        )
        travelled = world.travelled.copy()
        # The robots' credits add up to what the team revealed.
        known_after = int(np.count_nonzero(world.belief != UNKNOWN))
        assert result.new_cells.sum() == known_after - known_before
        assert (result.new_cells >= 0).all()
        known = _check_state(world, known)


@settings(max_examples=50, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 4), st.integers(1, 9), st.integers(1, 9)),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_explored_cell_counts_are_numpys(shape, seed) -> None:
    from frontier_marl.core.world_kernels import basis_code, count_cells

    rng = np.random.default_rng(seed)
    belief = rng.integers(-1, 2, shape).astype(np.int8)
    region = rng.random(shape) < 0.5
    expected = {
        "all": np.count_nonzero(belief != UNKNOWN, axis=(1, 2)),
        "free": np.count_nonzero(belief == FREE, axis=(1, 2)),
        "reachable": np.count_nonzero(region & (belief != UNKNOWN), axis=(1, 2)),
    }
    for basis, counts in expected.items():
        code = basis_code(basis)
        assert [count_cells(code, belief[n], region[n]) for n in range(len(belief))] == list(counts)
