"""Team rollouts (sim/team_rollouts.py) and the team lookahead oracle (policies/team_lookahead.py):
the batched rollouts cost what the team pays playing the base policy step by step, one robot
costs what the single-robot rollouts say, and the oracle plays benchmark episodes."""

from __future__ import annotations

import numpy as np
import pytest

from frontier_marl.core.frontiers import cluster_frontiers
from frontier_marl.core.grid import FREE, UNKNOWN
from frontier_marl.core.sensing import make_sensor
from frontier_marl.core.slots import SlotArrays, robot_slots
from frontier_marl.core.world import World, WorldParams
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.policies.team_lookahead import TeamLookaheadOracle, team_lookahead_costs
from frontier_marl.sim.branching import branch
from frontier_marl.sim.rollouts import NearestPathBase, rollout_costs
from frontier_marl.sim.team_rollouts import ClaimingNearestBase, team_rollout_costs


def _env(preset: str, agents: int, seed: int, steps: int) -> FrontierParallelEnv:
    """An env after ``steps`` steps of every robot taking its first valid slot."""
    env = FrontierParallelEnv(preset=preset, n_agents=agents)
    env.reset(seed=seed)
    for _ in range(steps):
        env.mdp.step([int(np.flatnonzero(mask)[0]) for mask in env.mdp.action_masks()])
    return env


def _is_frontier(belief: np.ndarray, row: int, col: int) -> bool:
    if belief[row, col] != FREE:
        return False
    near = [(row + dr, col + dc) for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1))]
    inside = [(r, c) for r, c in near if 0 <= r < belief.shape[0] and 0 <= c < belief.shape[1]]
    return any(belief[r, c] == UNKNOWN for r, c in inside)


def _claimed_nearest(
    world: World, robot: int, goals: np.ndarray, previous: np.ndarray, reach: float
) -> np.ndarray:
    """The base's rule from scipy's clusters and one robot's slot table."""
    params = world.batch.params
    clusters = cluster_frontiers(world.belief, params.connectivity, params.max_cluster_cells)
    table = robot_slots(
        world.belief, tuple(world.positions[robot]), clusters, clusters.sizes.astype(float), 256,
        False,
    )  # fmt: skip
    others = [goals[a] for a in range(len(goals)) if a != robot and goals[a, 0] >= 0]
    slots = [s for s in range(table.live) if tuple(table.target[s]) != tuple(previous)]
    keys = []
    for s in slots or range(table.live):
        near = any(np.hypot(*(table.target[s] - other)) <= reach for other in others)
        keys.append((near, table.path_length[s], table.distance[s], s))
    if not keys:
        return np.array([-1, -1])
    if all(key[0] for key in keys):  # every slot claimed: the nearest of all
        keys = [(False, *key[1:]) for key in keys]
    return table.target[min(keys)[3]].copy()


def _next_cell(world: World, robot: int, goals: np.ndarray) -> tuple[int, int] | None:
    """The next cell of ``robot``'s planned path to its goal (None: no such plan)."""
    meta = world.batch.plan_meta[world.index, robot]
    plan = world.batch.plan_cells[world.index, robot]
    if tuple(meta[:2]) != tuple(goals[robot]) or meta[3] <= meta[2] + 1:
        return None
    return tuple(plan[meta[2] + 1])


def _played(world: World, coverage: float, max_steps: int, reach: float) -> int:
    """The makespan to go of the team of ``world`` (a clone, its robots' first goals set in
    its batch) playing the base step by step: the reference for team_rollout_costs."""
    k = world.n_agents
    goals = world.batch.goals[world.index].copy()
    region = world.start_region
    start = int(world.travelled.max())
    waits = np.zeros(k, dtype=int)
    idle = np.zeros(k, dtype=bool)
    for step in range(max_steps + 1):
        known = np.count_nonzero((world.belief != UNKNOWN) & region)
        if known / np.count_nonzero(region) >= coverage:
            return int(world.travelled.max()) - start
        if step == max_steps:
            return max_steps
        deciding = [
            a
            for a in range(k)
            if (goals[a, 0] < 0 and not idle[a])
            or (goals[a, 0] >= 0 and not _is_frontier(world.belief, *goals[a]))
            or (goals[a, 0] >= 0 and tuple(world.positions[a]) == tuple(goals[a]))
            or waits[a] >= 2
        ]
        previous = goals.copy()
        for a in deciding:
            goals[a] = -1
        for a in deciding:
            goals[a] = _claimed_nearest(world, a, goals, previous[a], reach)
            idle[a] = goals[a, 0] < 0
            waits[a] = 0
        if (goals[:, 0] < 0).all():
            return max_steps
        before = world.positions.copy()
        moved = world.move(goals)
        if int(np.sum(moved.new_cells)):
            idle[:] = False
        for a in range(k):
            stuck = goals[a, 0] >= 0 and (world.positions[a] == before[a]).all()
            waits[a] = waits[a] + 1 if stuck and tuple(before[a]) != tuple(goals[a]) else 0
        for a in range(k):  # a blocked robot and one it meets head-on swap their targets
            for b in range(k):
                head_on = _next_cell(world, a, goals) == tuple(world.positions[b]) and (
                    _next_cell(world, b, goals) == tuple(world.positions[a])
                )
                if b != a and waits[a] >= 2 and head_on:
                    goals[[a, b]] = goals[[b, a]]
                    waits[a] = waits[b] = 0
                    break
    raise AssertionError("unreachable")


@pytest.mark.parametrize(
    ("preset", "agents", "seed", "steps"),
    [
        ("thesis-20x20", 2, 3, 2),
        ("thesis-20x20", 3, 8, 4),
        ("thesis-20x20", 4, 2, 0),
        ("rooms-32", 4, 5, 6),
        ("rooms-32", 4, 7, 0),
    ],
)
def test_team_rollouts_cost_what_the_team_pays_playing_the_base(preset, agents, seed, steps):
    env = _env(preset, agents, seed, steps)
    world = env.world
    reach = float(env.config.perception_range)
    slots = env.mdp.slot_arrays()
    targets = slots.target[0, : int(slots.live[0])]
    goals = np.full((agents, 2), -1, dtype=np.int64)
    goals[1] = slots.target[1, 0]  # robot 1 keeps a target, the others are decided at once
    cap = 4 * world.belief.size
    costs = team_lookahead_costs(
        world.batch, world.index, 0, targets, goals, 0.99, cap, ClaimingNearestBase(reach)
    )
    expected = []
    for target in targets:
        sims = branch(world.batch, world.index, 1)
        sims.goals[0] = goals
        sims.goals[0, 0] = target
        expected.append(_played(World.of(sims, 0), 0.99, cap, reach))
    assert costs.tolist() == expected
    assert (costs < cap).all()  # every candidate reached the coverage
    pruned = team_lookahead_costs(
        world.batch, world.index, 0, targets, goals, 0.99, cap, ClaimingNearestBase(reach), True
    )
    cheapest = costs == costs.min()
    assert np.array_equal(pruned[cheapest], costs[cheapest])
    assert ((pruned == costs) | (pruned == cap)).all()


@pytest.mark.parametrize("seed", [1, 4, 9])
def test_one_robot_team_rollouts_cost_what_the_single_robot_rollouts_do(seed: int) -> None:
    env = _env("rooms-32", 1, seed, 3)
    world = env.world
    slots = env.mdp.slot_arrays()
    targets = slots.target[0, : int(slots.live[0])]
    cap = 4 * world.belief.size
    single = branch(world.batch, world.index, len(targets))
    single.goals[:, 0] = targets
    expected = rollout_costs(single, int(world.travelled[0]), 0.99, cap, NearestPathBase())
    team = branch(world.batch, world.index, len(targets))
    team.goals[:, 0] = targets
    costs = team_rollout_costs(team, 0.99, cap, ClaimingNearestBase(3.0))
    assert costs.tolist() == expected.tolist()
    assert np.array_equal(team.belief, single.belief)


def test_the_base_skips_targets_a_teammate_has_claimed_unless_all_are() -> None:
    grid = np.zeros((5, 9), dtype=bool)
    world = World(grid, np.array([[2, 4], [0, 0]]), WorldParams(make_sensor("square", 1), 1))
    sims = branch(world.batch, world.index, 1)
    slots = SlotArrays.empty(1, 2, 3)
    slots.valid[:] = [[True, True, False], [True, False, False]]
    slots.target[0, 0] = [[2, 6], [2, 1], [0, 0]]
    slots.target[0, 1] = [[2, 6], [0, 0], [0, 0]]
    slots.path_length[:] = [[2, 3, 0], [5, 0, 0]]
    slots.distance[:] = [[2.0, 3.0, 0.0], [5.0, 0.0, 0.0]]
    sims.goals[0, 1] = [2, 7]  # robot 1 heads one cell from robot 0's nearest target
    deciding = np.array([[True, False]])
    base = ClaimingNearestBase(reach=1.0)
    assert base.goals(sims, slots, np.array([0]), deciding)[0].tolist() == [[2, 1], [2, 7]]
    far = ClaimingNearestBase(reach=0.5)  # now (2, 6) is unclaimed: the nearest
    assert far.goals(sims, slots, np.array([0]), deciding)[0, 0].tolist() == [2, 6]
    sims.goals[0, 0] = [2, 6]  # ... unless it was the robot's own target: blocked, it turns
    assert far.goals(sims, slots, np.array([0]), deciding)[0, 0].tolist() == [2, 1]
    sims.goals[0, 0] = -1
    both = np.array([[True, True]])  # robot 0 decides first; robot 1, with one slot, claims
    # the same cluster target all the same: its only slot is claimed, so it takes the nearest
    assert base.goals(sims, slots, np.array([0]), both)[0].tolist() == [[2, 6], [2, 6]]
    with pytest.raises(ValueError, match="reach"):
        ClaimingNearestBase(0)


def test_the_team_oracle_plays_benchmark_episodes_below_the_team_heuristics() -> None:
    from frontier_marl.evaluation.benchmark.families import family
    from frontier_marl.evaluation.benchmark.run import contenders, run_benchmark

    names = ["coordinated-assignment", "team-lookahead-oracle"]
    rows = run_benchmark([family("random-20")], contenders(names, "none"), 4, agents=2)
    by_name = {row["policy"]: row for row in rows}
    assert by_name["team-lookahead-oracle"]["success"] == 4
    assert all(row["best_heuristic"] == "coordinated-assignment" for row in rows)
    oracle, best = (by_name[name]["makespan99_mean"] for name in names[::-1])
    assert oracle < best


def test_the_team_oracle_needs_an_env_and_runs_from_the_cli(capsys) -> None:
    from frontier_marl.cli.main import main

    with pytest.raises(RuntimeError, match="attach"):
        TeamLookaheadOracle().act_team({}, {})
    argv = ["benchmark", "--agents", "2", "--families", "random-20", "--episodes", "1"]
    assert main([*argv, "--policies", "utility-discount,team-lookahead-oracle"]) == 0
    assert "team-lookahead-oracle" in capsys.readouterr().out


def test_the_decider_counts_the_steps_a_robot_stands_short_of_its_target() -> None:
    decider = TeamLookaheadOracle()
    robots = ["robot_0", "robot_1", "robot_2"]
    infos = {
        "robot_0": {"target": np.array([3, 3])},  # heading somewhere else
        "robot_1": {"target": np.array([-1, -1])},  # no target: idle, not blocked
        "robot_2": {"target": np.array([5, 5])},  # standing on its target: reached
    }
    still = np.array([[1, 1], [2, 2], [5, 5]])
    for steps, expected in ((0, [0, 0, 0]), (1, [1, 0, 0]), (2, [2, 0, 0])):
        decider._count_waits(still, steps, infos, robots)
        assert decider._waits.tolist() == expected
    decider._count_waits(still + [[0, 1], [0, 0], [0, 0]], 3, infos, robots)  # robot 0 moved
    assert decider._waits.tolist() == [0, 0, 0]
    decider._count_waits(still, 0, infos, robots)  # a new episode starts counting afresh
    assert decider._waits.tolist() == [0, 0, 0]


def test_team_costs_over_the_true_map_as_its_completion_are_the_true_maps() -> None:
    env = _env("rooms-32", 3, 4, 3)
    world = env.world
    slots = env.mdp.slot_arrays()
    targets = slots.target[0, : int(slots.live[0])]
    goals = np.full((3, 2), -1, dtype=np.int64)
    base, cap = ClaimingNearestBase(float(env.config.perception_range)), 4 * world.belief.size

    def costs(maps: list[np.ndarray] | None) -> np.ndarray:
        return team_lookahead_costs(
            world.batch, world.index, 0, targets, goals, 0.99, cap, base, maps=maps
        )

    exact = costs(None)
    true = world.batch.true[world.index].copy()
    assert costs([true]).tolist() == exact.tolist()
    # the mean over maps: the true map twice and a map with every unknown cell an obstacle
    walled = true | (world.belief == UNKNOWN)
    np.testing.assert_allclose(costs([true, walled, true]), (2 * exact + costs([walled])) / 3)
    with pytest.raises(ValueError, match="prune"):
        team_lookahead_costs(
            world.batch, world.index, 0, targets, goals, 0.99, cap, base, True, [true]
        )


def test_with_one_robot_the_team_oracle_plays_the_single_robot_oracles_episodes() -> None:
    from frontier_marl.evaluation.benchmark.families import family, variant_configs
    from frontier_marl.evaluation.benchmark.run import contenders, run_family

    fam = family("random-20")
    worlds = variant_configs(fam)
    runs = [
        [e.cells_to_coverage for e in run_family(fam, c, worlds, 3, split="validation").episodes]
        for c in contenders(["lookahead-oracle", "team-lookahead-oracle"])
    ]
    assert runs[0] == runs[1]
