"""The compiled kernels give exactly the results of the numpy/Python reference code.

Every dispatching core function is run twice on the same input, once with the kernels and once
with ``kernels.ENABLED`` patched off, and the results must be identical (not just close): a
seed must give the same episode with and without numba.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import frontier_marl
from frontier_marl.core import kernels
from frontier_marl.core.frontiers import (
    cluster_frontiers,
    free_components,
    nearest_cells_to_centroids,
)
from frontier_marl.core.grid import FREE, UNKNOWN
from frontier_marl.core.planning import astar
from frontier_marl.core.sensing import RaycastSensor, make_sensor
from frontier_marl.core.slots import build_slots
from frontier_marl.core.world import FULL_PATH, World, WorldParams

pytestmark = pytest.mark.skipif(not kernels.NUMBA_AVAILABLE, reason="numba is not installed")


def both(function, *args):
    """``function(*args)`` with the kernels, then with the reference code."""
    saved = kernels.ENABLED
    try:
        kernels.ENABLED = True
        compiled = function(*args)
        kernels.ENABLED = False
        reference = function(*args)
    finally:
        kernels.ENABLED = saved
    return compiled, reference


def random_belief(seed: int, height: int, width: int) -> np.ndarray:
    """A belief with free, occupied and unknown cells in random patches."""
    rng = np.random.default_rng(seed)
    belief = rng.choice(np.array([UNKNOWN, FREE, FREE, 1], dtype=np.int8), size=(height, width))
    belief[rng.random((height, width)) < 0.3] = UNKNOWN
    return belief


def assert_same(a, b) -> None:
    if isinstance(a, tuple | list):
        assert len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            assert_same(x, y)
    elif a is None or b is None:
        assert a is b
    else:
        a, b = np.asarray(a), np.asarray(b)
        assert a.dtype.kind == b.dtype.kind and a.shape == b.shape
        np.testing.assert_array_equal(a, b)


dims = st.integers(min_value=1, max_value=24)


@settings(max_examples=150)
@given(seed=st.integers(0, 10**6), height=dims, width=dims, max_cells=st.integers(0, 10))
def test_clusters_match(seed, height, width, max_cells):
    belief = random_belief(seed, height, width)
    for connectivity in (4, 8):
        compiled, reference = both(cluster_frontiers, belief, connectivity, max_cells)
        for field in ("cell_rows", "cell_cols", "cell_cluster", "sizes", "centroids"):
            assert_same(getattr(compiled, field), getattr(reference, field))


@settings(max_examples=150)
@given(seed=st.integers(0, 10**6), height=dims, width=dims, sort=st.booleans())
def test_targets_and_slots_match(seed, height, width, sort):
    belief = random_belief(seed, height, width)
    clusters = cluster_frontiers(belief, 8, 4)
    rng = np.random.default_rng(seed)
    eligible = rng.random(len(clusters.cell_rows)) < 0.7
    has_target, targets = nearest_cells_to_centroids(clusters, eligible)
    assert_same(*both(nearest_cells_to_centroids, clusters, eligible))
    position = np.array([rng.integers(height), rng.integers(width)])
    gains = clusters.sizes.astype(float)
    args = (position, clusters.centroids, clusters.sizes, gains, has_target, targets, 3, sort)
    compiled, reference = both(build_slots, *args)
    for field in ("cluster", "valid", "centroid", "target", "distance", "size", "gain", "live"):
        assert_same(getattr(compiled, field), getattr(reference, field))


@settings(max_examples=200)
@given(seed=st.integers(0, 10**6), height=dims, width=dims)
def test_astar_matches(seed, height, width):
    rng = np.random.default_rng(seed)
    passable = rng.random((height, width)) < 0.75
    start = (int(rng.integers(height)), int(rng.integers(width)))
    goal = (int(rng.integers(height)), int(rng.integers(width)))
    assert_same(*both(astar, passable, start, goal))


def test_reachable_targets_match_the_component_rule():
    belief = random_belief(3, 15, 17)
    clusters = cluster_frontiers(belief, 8, 4)
    free = np.argwhere(belief == FREE)
    components = free_components(belief)
    for row, col in free[:: max(1, len(free) // 10)]:
        reachable = components[clusters.cell_rows, clusters.cell_cols] == components[row, col]
        expected = nearest_cells_to_centroids(clusters, reachable)
        got = kernels.reachable_targets(
            belief,
            int(row),
            int(col),
            clusters.cell_rows,
            clusters.cell_cols,
            clusters.cell_cluster,
            clusters.centroids,
        )
        assert_same(got, expected)


def test_sensing_matches():
    rng = np.random.default_rng(0)
    true_grid = rng.random((12, 9)) < 0.25
    sensor = RaycastSensor(3)

    def sense_everywhere() -> tuple[np.ndarray, np.ndarray, list[int]]:
        belief = np.full(true_grid.shape, UNKNOWN, dtype=np.int8)
        seen = np.zeros(true_grid.shape, dtype=bool)
        counts = [sensor.sense(true_grid, belief, (r, c), seen) for r, c in np.argwhere(~true_grid)]
        return belief, seen, counts

    assert_same(*both(sense_everywhere))


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 10**6),
    n_robots=st.integers(1, 5),
    cells_per_step=st.sampled_from([1, 2, 3, FULL_PATH]),
    sensor=st.sampled_from(["square", "raycast"]),
)
def test_moves_match(seed, n_robots, cells_per_step, sensor):
    """The compiled ``World.move`` (plan cache, robots waiting for each other, sensing)."""
    rng = np.random.default_rng(seed)
    true_grid = rng.random((9, 11)) < 0.2
    free = np.argwhere(~true_grid)
    if len(free) < n_robots:
        return
    starts = free[rng.choice(len(free), n_robots, replace=False)]
    params = WorldParams(make_sensor(sensor, 2), cells_per_step)
    # Targets: known-free cells (often the same for several robots, so they block each
    # other), sometimes an unreachable cell or none; some repeated to reuse the plans.
    choices = [rng.integers(1 << 30) for _ in range(12)]

    def play() -> list:
        world = World(true_grid, starts, params)
        trace = []
        for choice in choices:
            known = np.argwhere(world.belief == FREE)
            pick = np.random.default_rng(choice)
            targets = [
                None if pick.random() < 0.1 else tuple(int(v) for v in known[pick.integers(3)])
                for _ in range(n_robots)
            ]
            moved = world.move(targets)
            trace.append((moved.new_cells, moved.paths, moved.reached, world.belief.copy()))
            trace.append((world.positions.copy(), world.seen.copy(), world.travelled.copy()))
        return trace

    assert_same(*both(play))


@pytest.mark.parametrize(
    "kwargs",
    [
        {"preset": "thesis-20x20"},
        {"preset": "thesis-30x30", "map_mode": "dynamic", "sort_by_distance": True},
        {"preset": "thesis-20x20", "n_agents": 3, "cells_per_step": 2, "sensor": "square"},
        {"preset": "thesis-20x20", "gain": "unknown", "connectivity": 4, "cells_per_step": "full"},
    ],
)
def test_episodes_identical_with_and_without_kernels(kwargs):
    def episodes() -> list:
        env = frontier_marl.parallel_env(**kwargs)
        trace = []
        for seed in range(3):
            _, infos = env.reset(seed=seed)
            rng = np.random.default_rng(seed)
            while env.agents:
                actions = {
                    agent: int(rng.choice(np.flatnonzero(infos[agent]["action_mask"])))
                    for agent in env.agents
                }
                obs, rewards, _, _, infos = env.step(actions)
                for agent in sorted(obs):
                    observation = obs[agent]
                    flat = (
                        np.concatenate([np.ravel(v) for v in observation.values()])
                        if isinstance(observation, dict)
                        else observation
                    )
                    trace.append((agent, rewards[agent], infos[agent]["position"], flat.tobytes()))
        return trace

    compiled, reference = both(episodes)
    assert compiled == reference
    assert len(compiled) > 20


def test_compiles_without_a_writable_cache():
    namespace: dict = {}
    exec("def add_one(x):\n    return x + 1\n", namespace)  # no source file: numba cannot cache
    compiled = kernels._compile(namespace["add_one"])
    assert compiled(41) == 42
    assert compiled is not namespace["add_one"]  # compiled, not the plain function
