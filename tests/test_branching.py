"""Branching (sim/branching.py) and batched rollouts (sim/rollouts.py): a clone steps exactly as
its original; the rollouts end where they should and give the per-clone route's costs."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frontier_marl.core.frontiers import cluster_frontiers
from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN
from frontier_marl.core.slots import robot_slots
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.evaluation.benchmark.families import family, variant_configs
from frontier_marl.evaluation.benchmark.run import oracle, run_family
from frontier_marl.policies import lookahead
from frontier_marl.sim.batch_engine import BatchMDP
from frontier_marl.sim.branching import branch, branch_mdp, clone_mdp
from frontier_marl.sim.engine import ExplorationMDP
from frontier_marl.sim.nearest_path import DecisionScratch, nearest_path_goal, start_frontier
from frontier_marl.sim.rollouts import NearestPathBase, rollout_costs

DOCS = Path(__file__).resolve().parent.parent / "docs" / "environment.md"


def _env(seed: int, prefix: list[int], **kwargs: object) -> FrontierParallelEnv:
    """An env reset with ``seed`` after playing the valid slots ``prefix`` (modulo the live
    ones)."""
    env = FrontierParallelEnv(preset="thesis-20x20", **kwargs)
    env.reset(seed=seed)
    for choice in prefix:
        masks = env.mdp.action_masks()
        env.mdp.step([_valid(mask, choice + a) for a, mask in enumerate(masks)])
    return env


def _valid(mask: np.ndarray, choice: int) -> int:
    valid = np.flatnonzero(mask)
    return int(valid[choice % len(valid)])


def _assert_same(single: ExplorationMDP, batch: BatchMDP, row: int) -> None:
    world, clone = single.world, batch.worlds
    assert world is not None
    assert np.array_equal(world.belief, clone.belief[row])
    assert np.array_equal(world.positions, clone.positions[row])
    assert np.array_equal(world.travelled, clone.travelled[row])
    slots = single.slot_arrays()
    for name in ("target", "valid", "mask", "path_length", "distance", "size", "gain"):
        assert np.array_equal(getattr(slots, name), getattr(batch.slots, name)[row]), name
    assert single.steps == batch.steps[row]
    assert single.last is not None
    observed = batch.observations(np.array([row]))
    for agent, obs in enumerate(single.last.observations):
        if isinstance(obs, dict):
            for key, value in obs.items():
                assert np.array_equal(value, observed[key][0, agent]), key
        else:
            assert np.array_equal(obs, observed[0, agent])


@pytest.mark.parametrize("kwargs", [{}, {"n_agents": 2}, {"commit": "until-reached"}])
def test_a_clone_steps_exactly_as_its_original(kwargs: dict[str, object]) -> None:
    prefix = [1, 0, 2]
    source = _env(3, prefix, **kwargs)
    futures = [[0, 1, 0, 2, 1], [1, 1, 0, 0, 3]]
    batch = branch_mdp(source.mdp, len(futures))
    originals = [_env(3, prefix, **kwargs) for _ in futures]
    for row, original in enumerate(originals):
        _assert_same(original.mdp, batch, row)
    agents = originals[0].config.n_agents
    for step in range(len(futures[0])):
        active = ~batch.done
        if not active.any():
            break
        actions = np.zeros((len(futures), agents), dtype=np.int64)
        for row, original in enumerate(originals):
            if not active[row]:
                continue
            masks = original.mdp.action_masks()
            chosen = [_valid(masks[a], futures[row][step] + a) for a in range(agents)]
            actions[row] = chosen
            original.mdp.step(chosen)
        batch.step(actions, active)
        for row, original in enumerate(originals):
            if not active[row]:
                continue
            _assert_same(original.mdp, batch, row)
            outcome = original.mdp.last.outcome
            assert np.array_equal(outcome.rewards, batch.outcome.rewards[row])
            assert outcome.terminated == batch.outcome.terminated[row]
            assert outcome.truncated == batch.outcome.truncated[row]


def test_a_clone_of_any_world_of_a_batch_steps_as_that_world() -> None:
    """clone_mdp copies world 1 of three mid-episode; each copy then plays world 1's steps."""
    from frontier_marl.config import make_config

    cfg = make_config("thesis-20x20", n_agents=2, features="explorer", teammates="positions")
    source = BatchMDP(cfg, 3)
    source.rngs = [np.random.default_rng(seed) for seed in (5, 6, 7)]
    source.reset_worlds(np.arange(3))
    rng = np.random.default_rng(0)

    def play(batch: BatchMDP, active: np.ndarray) -> np.ndarray:
        masks = batch.slots.mask
        actions = (rng.random(masks.shape) * masks).argmax(axis=2)
        batch.step(actions, active)
        return actions

    for _ in range(3):
        play(source, ~source.done)
    assert not source.done[1]
    clones = clone_mdp(source, 1, 2)
    assert np.array_equal(clones.explored, np.repeat(source.explored[1], 2))
    only_one = np.array([False, True, False])
    for _ in range(4):
        if source.done[1]:
            break
        actions = play(source, only_one)
        clones.step(np.repeat(actions[1:2], 2, axis=0), np.ones(2, dtype=bool))
        mine, theirs = source.observations(np.array([1])), clones.observations()
        for row in range(2):
            assert np.array_equal(clones.worlds.belief[row], source.worlds.belief[1])
            assert np.array_equal(clones.worlds.positions[row], source.worlds.positions[1])
            assert np.array_equal(clones.slots.mask[row], source.slots.mask[1])
            assert np.array_equal(clones.outcome.rewards[row], source.outcome.rewards[1])
            assert clones.done[row] == source.done[1]
            for key, value in mine.items():
                assert np.array_equal(theirs[key][row], value[0]), key


@pytest.mark.parametrize("basis", ["all", "free", "reachable"])
def test_a_step_counts_the_explored_fraction_of_every_world_on_its_basis(basis: str) -> None:
    """The step's compiled count (only worlds whose belief changed are recounted) equals a
    count with numpy, world by world, also in worlds that wait or whose episode ended."""
    from frontier_marl.config import make_config

    cfg = make_config("thesis-20x20", threshold_basis=basis, gain="unknown")
    batch = BatchMDP(cfg, 3)
    batch.rngs = [np.random.default_rng(seed) for seed in (1, 2, 3)]
    batch.reset_worlds(np.arange(3))
    rng = np.random.default_rng(0)
    w = batch.worlds
    for step in range(40):
        active = ~batch.done & (np.arange(3) != step % 3)  # one world waits each step
        masks = batch.slots.mask
        batch.step((rng.random(masks.shape) * masks).argmax(axis=2), active)
        known = w.belief != UNKNOWN
        counts = {
            "all": known.sum(axis=(1, 2)) / known[0].size,
            "free": (w.belief == FREE).sum(axis=(1, 2)) / (~w.true).sum(axis=(1, 2)),
            "reachable": (known & w.start_region).sum(axis=(1, 2)) / w.start_region_size,
        }
        assert np.array_equal(batch.explored, counts[basis])
        assert np.array_equal(w.explored_fraction(basis), counts[basis])


def test_branch_mdp_needs_an_episode_in_progress() -> None:
    env = FrontierParallelEnv(preset="thesis-20x20")
    with pytest.raises(RuntimeError, match="episode in progress"):
        branch_mdp(env.mdp, 2)


@settings(max_examples=300, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 14), st.integers(1, 14)),
    seed=st.integers(0, 2**32 - 1),
    unknown=st.floats(0.1, 0.6),
    occupied=st.floats(0.0, 0.3),
    connectivity=st.sampled_from([4, 8]),
    max_cells=st.integers(0, 5),
    n_slots=st.sampled_from([1, 2, 256]),
)
def test_the_rollouts_nearest_path_goal_is_the_slots_nearest_path(
    shape, seed, unknown, occupied, connectivity, max_cells, n_slots
) -> None:
    """The compiled decision (union-find labelling, bounded search) against the slots built
    from scipy's clusters: the live slot of shortest path, ties by centroid distance, then
    slot; (-1, -1) when none is live."""
    rng = np.random.default_rng(seed)
    codes = np.array([UNKNOWN, FREE, OCCUPIED], dtype=np.int8)
    belief = rng.choice(codes, size=shape, p=[unknown, 1 - unknown - occupied, occupied])
    row, col = int(rng.integers(shape[0])), int(rng.integers(shape[1]))
    belief[row, col] = FREE
    clusters = cluster_frontiers(belief, connectivity, max_cells)
    table = robot_slots(belief, (row, col), clusters, clusters.sizes.astype(float), n_slots, False)
    expected = [-1, -1]
    if table.live:
        key = [(table.path_length[s], table.distance[s], s) for s in range(table.live)]
        expected = table.target[min(key)[2]].tolist()
    scratch = DecisionScratch(shape)
    start_frontier(belief, scratch.arrays())
    goal = nearest_path_goal(belief, row, col, connectivity, max_cells, n_slots, scratch.arrays())
    assert goal.tolist() == expected
    assert (scratch.owner == -1).all() and (scratch.distance == -1).all()  # left as found


class _SlotRoute:
    """Nearest-path through the generic route: decision rounds, clusters labelled by
    scipy.ndimage.label, the slots built by ``Worlds.slots``."""

    n_slots = NearestPathBase.n_slots
    gain = NearestPathBase.gain

    def goals(self, sims, slots, deciding):  # type: ignore[no-untyped-def]
        return NearestPathBase().goals(sims, slots, deciding)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"preset": "thesis-20x20"},
        {"preset": "rooms-32", "connectivity": 4, "max_cluster_cells": 5},
        {"preset": "rooms-32", "max_cluster_cells": 64, "sensor": "square"},
    ],
)
@pytest.mark.parametrize("seed", [3, 11])
def test_the_compiled_nearest_path_rollouts_walk_as_the_generic_route(kwargs, seed) -> None:
    env = FrontierParallelEnv(**kwargs)
    env.reset(seed=seed)
    for choice in range(4):
        (mask,) = env.mdp.action_masks()
        env.mdp.step([_valid(mask, choice)])
    world = env.world
    slots = env.mdp.slot_arrays()
    targets = slots.target[0, : int(slots.live[0])]
    start = int(world.travelled[0])
    runs = []
    for base in (NearestPathBase(), _SlotRoute()):
        sims = branch(world.batch, world.index, len(targets))
        sims.goals[:, 0] = targets
        cost = rollout_costs(sims, start, 0.99, 4 * world.belief.size, base)  # type: ignore[arg-type]
        runs.append((cost, sims.belief.copy(), sims.positions.copy(), sims.travelled.copy()))
    for fused, generic in zip(*runs, strict=True):
        assert np.array_equal(fused, generic)
    assert (runs[0][0] < 4 * world.belief.size).all()  # every rollout reached the coverage


@pytest.mark.parametrize("route", [NearestPathBase, _SlotRoute])
@pytest.mark.parametrize("seed", [3, 11, 19])
def test_pruned_rollouts_keep_the_cheapest_costs_and_only_raise_the_others(route, seed) -> None:
    env = FrontierParallelEnv(preset="rooms-32")
    env.reset(seed=seed)
    while env.mdp.slot_arrays().live[0] < 4:  # a decision with a few candidates
        (mask,) = env.mdp.action_masks()
        env.mdp.step([_valid(mask, 0)])
    world = env.world
    slots = env.mdp.slot_arrays()
    targets = slots.target[0, : int(slots.live[0])]
    start, cap = int(world.travelled[0]), 4 * world.belief.size
    runs = []
    for prune in (False, True):
        sims = branch(world.batch, world.index, len(targets))
        sims.goals[:, 0] = targets
        runs.append(rollout_costs(sims, start, 0.99, cap, route(), prune))  # type: ignore[arg-type]
    exact, pruned = runs
    cheapest = exact == exact.min()
    assert np.array_equal(pruned[cheapest], exact[cheapest])
    assert ((pruned[~cheapest] == exact[~cheapest]) | (pruned[~cheapest] == cap)).all()
    if route is NearestPathBase:  # world after world: each is pruned by those before it
        before = np.minimum.accumulate(np.concatenate([[cap], exact[:-1]]))
        assert np.array_equal(pruned, np.where(exact <= before, exact, cap))


def test_clones_do_not_touch_their_source() -> None:
    env = _env(5, [0, 1])
    world = env.world
    belief, positions = world.belief.copy(), world.positions.copy()
    sims = branch(world.batch, world.index, 3)
    assert np.array_equal(sims.belief[2], belief)
    sims.goals[:, 0] = env.mdp.slot_arrays().target[0, 0]
    rollout_costs(sims, int(world.travelled[0]), 0.99, 1600, NearestPathBase())
    assert np.array_equal(world.belief, belief)
    assert np.array_equal(world.positions, positions)


def test_rollouts_end_at_coverage_at_the_cap_or_when_stuck() -> None:
    env = _env(5, [0])
    world = env.world
    start = int(world.travelled[0])
    targets = env.mdp.slot_arrays().target[0, : int(env.mdp.slot_arrays().live[0])]
    sims = branch(world.batch, world.index, len(targets))
    sims.goals[:, 0] = targets
    assert rollout_costs(sims, start, 0.0, 1600, NearestPathBase()).tolist() == [0] * len(targets)
    sims = branch(world.batch, world.index, len(targets))
    sims.goals[:, 0] = targets
    capped = rollout_costs(sims, start, 0.99, 3, NearestPathBase())
    assert capped.tolist() == [3] * len(targets)
    assert (sims.travelled[:, 0] - start).tolist() == [3] * len(targets)
    sims = branch(world.batch, world.index, len(targets))
    sims.goals[:, 0] = targets
    stuck = rollout_costs(sims, start, 2.0, 1600, NearestPathBase())  # never covered: stuck
    assert stuck.tolist() == [1600] * len(targets)


def test_oracle_gives_the_per_clone_routes_costs_and_t99() -> None:
    """Recorded with the per-clone route (lookahead_costs stepping one Worlds batch in
    lockstep, main at 1fa19b7): random-20, validation episodes 0 and 1. The oracle prunes
    its rollouts and orders its candidates by path; the unpruned costs are the recorded ones
    (sorted: the recording was in slot order), and pruning keeps their argmin."""
    costs: list[list[int]] = []
    original = lookahead.lookahead_costs

    def recording(*args: object, **kwargs: object) -> np.ndarray:
        out = original(*args, **kwargs)  # type: ignore[arg-type]
        exact = original(*args, **{**kwargs, "prune": False})  # type: ignore[arg-type]
        assert out.argmin() == exact.argmin() and out.min() == exact.min()
        costs.append(sorted(exact.tolist()))
        return out

    fam = family("random-20")
    lookahead.lookahead_costs = recording  # type: ignore[assignment]
    try:
        result = run_family(fam, oracle(), variant_configs(fam), 2, split="validation")
    finally:
        lookahead.lookahead_costs = original  # type: ignore[assignment]
    assert [e.cells_to_coverage["0.99"] for e in result.episodes] == [88.0, 112.0]
    assert costs[:3] == [[93, 107], [92, 104], [89, 91]]


def test_the_documented_example_runs() -> None:
    section = DOCS.read_text().split("## Branching")[1].split("\n## ")[0]
    (snippet,) = re.findall(r"```python\n(.*?)```", section, flags=re.DOTALL)
    exec(compile(snippet, str(DOCS), "exec"), {"__name__": "snippet"})
