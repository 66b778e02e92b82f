"""Teams: team rewards, the teammates observation, the joint heuristics, the team metrics, the
team options of the commands, and the PettingZoo suites with 2 and 8 robots on loaded and
generated maps."""

from __future__ import annotations

import itertools
import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pettingzoo.test import parallel_api_test, parallel_seed_test

import frontier_marl
from frontier_marl import slot_table
from frontier_marl.cli.main import main
from frontier_marl.config import make_config
from frontier_marl.core.example_maps import example_map_path
from frontier_marl.core.grid import FREE, OCCUPIED
from frontier_marl.evaluation import evaluate
from frontier_marl.evaluation.metrics import makespan_curve, overlap_ratio
from frontier_marl.experiments import multi_robot, multi_robot_tables
from frontier_marl.policies import (
    TEAM_POLICIES,
    CoordinatedAssignment,
    UtilityDiscount,
    make_policy,
)
from frontier_marl.sim.rewards import StepEvents, step_outcome
from tests.helpers import info_with, live_slot
from tests.oracles import bfs as bfs_distances

# A 1 x 11 corridor inside walls: with range 1 each robot senses its 3 x 3 window.
CORRIDOR = "#" * 13 + "\n#" + "." * 11 + "#\n" + "#" * 13 + "\n"


@pytest.fixture
def corridor(tmp_path: Path) -> str:
    path = tmp_path / "corridor.txt"
    path.write_text(CORRIDOR)
    return str(path)


def corridor_env(path: str, **kwargs: Any) -> tuple[Any, dict, dict]:
    """A 2-robot corridor env reset so that the robots stand at (1, 4) and (1, 8)."""
    env = frontier_marl.parallel_env(
        preset=None, map_path=path, n_agents=2, perception_range=1, sensor="square", **kwargs
    )
    for seed in range(200):
        obs, infos = env.reset(seed=seed)
        if env.world.positions.tolist() == [[1, 4], [1, 8]]:
            return env, obs, infos
    raise AssertionError("no seed puts the robots at (1, 4) and (1, 8)")


def slot_of(info: dict, target: tuple[int, int]) -> int:
    return next(c["slot"] for c in slot_table(info).rows() if c["target"] == target)


def padding_slot(info: dict) -> int:
    return int(np.flatnonzero(np.asarray(info["action_mask"]) == 0)[0])


# ----------------------------------------------------------------- team rewards


@pytest.mark.parametrize(
    "weight, expected",
    [(0.0, [0.15, -0.05]), (1.0, [0.15, 0.10]), (0.5, [0.15, 0.025])],
)
def test_team_weight_on_a_hand_made_two_robot_step(corridor, weight, expected):
    # Known: columns 3-5 (robot 0) and 7-9 (robot 1); column 6 is unknown between them.
    # Both step toward it; robot 0 moves first in the sub-step and senses column 6 (3 cells:
    # wall, free, wall), so it is credited with all 3 and robot 1, which senses the same
    # column after it, with none. Cell term: 0.05 * ((1 - w) * own + w * team), team = 3;
    # robot 1 also pays the no-new-cell penalty (-0.05), whatever w.
    env, _, infos = corridor_env(corridor, team_weight=weight)
    actions = {
        "robot_0": slot_of(infos["robot_0"], (1, 5)),
        "robot_1": slot_of(infos["robot_1"], (1, 7)),
    }
    _, rewards, terminations, truncations, infos = env.step(actions)
    assert [infos[a]["new_cells"] for a in ("robot_0", "robot_1")] == [3, 0]
    assert env.world.positions.tolist() == [[1, 5], [1, 7]]
    assert not any(terminations.values()) and not any(truncations.values())
    assert [rewards["robot_0"], rewards["robot_1"]] == pytest.approx(expected)


def test_team_weight_step_outcome_exact_values():
    events = StepEvents(
        new_cells=np.array([4, 0, 2]),
        padding=np.array([False, True, False]),
        oscillation=np.array([False, False, True]),
        threshold_reached=False,
        no_frontier_left=False,
        steps_taken=1,
        steps_without_progress=0,
    )
    cfg = make_config(team_weight=0.25).reward  # Reward 2: padding -0.1, oscillation -0.05
    rewards = step_outcome(cfg, events).rewards
    team = 6
    assert rewards == pytest.approx(
        [
            0.05 * (0.75 * 4 + 0.25 * team),
            0.05 * (0.25 * team) - 0.05 - 0.1,
            0.05 * (0.75 * 2 + 0.25 * team) - 0.05,
        ]
    )


@pytest.mark.parametrize("weight", [0.0, 0.3, 1.0])
def test_team_rewards_follow_the_rule_through_an_episode(weight):
    env = frontier_marl.parallel_env(
        map_path=str(example_map_path("rooms-32")), n_agents=3, team_weight=weight
    )
    policy = make_policy("greedy-distance")
    obs, infos = env.reset(seed=4)
    checked = 0
    while env.agents:
        obs, rewards, terms, truncs, infos = env.step(policy.act_team(obs, infos))
        if any(terms.values()) or any(truncs.values()):
            break
        own = np.array([infos[a]["new_cells"] for a in rewards])
        for agent, cells in zip(rewards, own, strict=True):
            expected = 0.05 * ((1 - weight) * cells + weight * own.sum())
            expected -= 0.05 if cells == 0 else 0.0
            expected -= 0.05 if infos[agent]["oscillation"] else 0.0
            assert rewards[agent] == pytest.approx(expected)
            checked += 1
    assert checked > 30


# ----------------------------------------------------------------- teammates observation


def test_teammates_positions_and_targets(corridor):
    env, obs, infos = corridor_env(corridor, teammates="positions+targets")
    # at reset: positions, and zero targets (no decision yet)
    assert obs["robot_0"]["teammates"].tolist() == [1, 8, 0, 0]
    assert obs["robot_1"]["teammates"].tolist() == [1, 4, 0, 0]
    # step 1: both reach their one-cell-away targets, so neither has a target left
    obs, _, _, _, infos = env.step(
        {"robot_0": slot_of(infos["robot_0"], (1, 5)), "robot_1": slot_of(infos["robot_1"], (1, 7))}
    )
    assert obs["robot_0"]["teammates"].tolist() == [1, 7, 0, 0]
    # step 2: robot 0 heads for (1, 3), two cells away, and stops half-way (one cell per
    # step); robot 1 idles on a padding slot, so it has no target
    obs, _, _, _, infos = env.step(
        {"robot_0": slot_of(infos["robot_0"], (1, 3)), "robot_1": padding_slot(infos["robot_1"])}
    )
    assert env.world.positions.tolist() == [[1, 4], [1, 7]]
    assert obs["robot_1"]["teammates"].tolist() == [1, 4, 1, 3]
    assert obs["robot_0"]["teammates"].tolist() == [1, 7, 0, 0]
    for agent in env.agents:
        assert env.observation_space(agent).contains(obs[agent])


def test_teammates_positions_only_in_agent_order():
    env = frontier_marl.parallel_env(
        map_path=str(example_map_path("rooms-32")), n_agents=4, teammates="positions"
    )
    obs, _ = env.reset(seed=2)
    positions = env.world.positions
    for i, agent in enumerate(env.agents):
        others = np.delete(positions, i, axis=0).ravel()
        assert obs[agent]["teammates"].tolist() == others.tolist()
        assert obs[agent]["teammates"].shape == (6,)


@pytest.mark.parametrize("normalize", [False, True])
@pytest.mark.parametrize("layout", ["positions", "positions+targets"])
def test_teammates_observations_stay_in_their_space(layout, normalize):
    env = frontier_marl.parallel_env(
        map_generator="rooms",
        height=20,
        width=28,
        n_agents=3,
        teammates=layout,
        normalize=normalize,
        action_mask=True,
        map_mode="dynamic",
    )
    policy = make_policy("random", seed=0)
    obs, infos = env.reset(seed=1)
    steps = 0
    while env.agents and steps < 60:
        for agent in env.agents:
            assert env.observation_space(agent).contains(obs[agent]), (agent, obs[agent])
        obs, _, _, _, infos = env.step(policy.act_team(obs, infos))
        steps += 1
    assert steps > 5


# ----------------------------------------------------------------- joint heuristics


def free_info(
    clusters: list[tuple[int, tuple[int, int]]], position: tuple[int, int], belief: np.ndarray
) -> dict:
    """A robot's info with live slots 0.. holding (cluster index, target) in that order, their
    path lengths by BFS over the belief's free cells (which the test keeps in the info)."""
    reach = bfs_distances(belief == FREE, position)
    live = [
        live_slot(1.0, float(np.hypot(t[0] - position[0], t[1] - position[1])), int(reach[t]), t, c)
        for c, t in clusters
    ]
    return info_with(live, position=position, belief=belief)


@st.composite
def team_states(draw: st.DrawFn) -> tuple[dict[str, dict], dict[int, tuple[int, int]]]:
    """Random robots on a 9 x 9 map with a few walls, each offered up to 4 of a shared set of
    clusters (a cluster's target is the same for every robot, as with the shared belief)."""
    belief = np.full((9, 9), FREE, np.int8)
    walls = draw(st.lists(st.tuples(st.integers(0, 8), st.integers(0, 8)), max_size=12))
    for cell in walls:
        belief[cell] = OCCUPIED
    free_cells = [tuple(c) for c in np.argwhere(belief == FREE).tolist()]
    n_robots = draw(st.integers(1, 5))
    n_clusters = draw(st.integers(0, 6))
    cells = draw(
        st.lists(
            st.sampled_from(free_cells),
            min_size=n_robots + n_clusters,
            max_size=n_robots + n_clusters,
            unique=True,
        )
    )
    positions, targets = cells[:n_robots], cells[n_robots:]
    infos = {}
    for i, position in enumerate(positions):
        reach = bfs_distances(belief == FREE, position)
        reachable = [c for c in range(n_clusters) if reach[targets[c]] >= 0]
        offered = draw(
            st.lists(st.sampled_from(reachable), max_size=4, unique=True)
            if reachable
            else st.just([])
        )
        infos[f"robot_{i}"] = free_info([(c, targets[c]) for c in offered], position, belief)
    return infos, dict(enumerate(targets))


def chosen_clusters(infos: dict[str, dict], actions: dict[str, int]) -> dict[str, int | None]:
    out = {}
    for agent, slot in actions.items():
        match = [c["cluster"] for c in slot_table(infos[agent]).rows() if c["slot"] == slot]
        out[agent] = match[0] if match else None
    return out


def best_distinct_assignment(infos: dict[str, dict]) -> tuple[int, int]:
    """Brute force: the largest number of robots on distinct clusters, then the smallest sum
    of their path lengths."""
    options = []
    for info in infos.values():
        dist = bfs_distances(info["belief"] == FREE, info["position"])
        options.append([(c["cluster"], int(dist[c["target"]])) for c in slot_table(info).rows()])
    best = (0, 0)
    for combo in itertools.product(*[[None, *opts] for opts in options]):
        picked = [o for o in combo if o is not None]
        if len({c for c, _ in picked}) != len(picked):
            continue
        key = (len(picked), -sum(length for _, length in picked))
        best = max(best, key)
    return best[0], -best[1]


@settings(max_examples=150)
@given(team_states())
def test_coordinated_assignment_never_duplicates_an_avoidable_target(state):
    infos, _ = state
    policy = CoordinatedAssignment()
    actions = policy.act_team(dict.fromkeys(infos), infos)
    clusters = chosen_clusters(infos, actions)
    for agent, slot in actions.items():
        assert infos[agent]["action_mask"][slot] == 1  # always a live slot (or idle slot 0)
        assert (clusters[agent] is None) == (not slot_table(infos[agent]).rows())
    distinct, shortest = best_distinct_assignment(infos)
    picked = [c for c in clusters.values() if c is not None]
    assert len(set(picked)) == distinct  # as many robots on their own cluster as possible
    if distinct == len(picked):  # a duplicate-free assignment exists: no duplicate at all
        assert len(set(picked)) == len(picked)
        lengths = []
        for agent, cluster in clusters.items():
            if cluster is None:
                continue
            info = infos[agent]
            target = next(c["target"] for c in slot_table(info).rows() if c["cluster"] == cluster)
            lengths.append(int(bfs_distances(info["belief"] == FREE, info["position"])[target]))
        assert sum(lengths) == shortest  # and of the least total path length


@settings(max_examples=15)
@given(seed=st.integers(0, 10_000), steps=st.integers(0, 25))
def test_coordinated_assignment_on_real_team_states(seed, steps):
    env = frontier_marl.parallel_env(
        map_path=str(example_map_path("rooms-32")), n_agents=4, n_slots=4
    )
    wander = make_policy("random", seed=seed)
    obs, infos = env.reset(seed=seed)
    for _ in range(steps):
        if not env.agents:
            return
        obs, _, _, _, infos = env.step(wander.act_team(obs, infos))
    if not env.agents:
        return
    policy = CoordinatedAssignment()
    policy.attach(env)
    actions = policy.act_team(obs, infos)
    with_belief = {a: {**infos[a], "belief": env.world.belief} for a in infos}
    distinct, _ = best_distinct_assignment(with_belief)
    picked = [c for c in chosen_clusters(infos, actions).values() if c is not None]
    assert len(set(picked)) == distinct
    for agent, slot in actions.items():
        assert infos[agent]["action_mask"][slot] == 1


# 3 x 7 known map; a wall on row 1 (cols 0-5) separates the robot at (0, 0) from (2, 0):
#   R . . . . . B        A: target (2, 0), Euclidean 2 away but 14 cells by path
#   # # # # # # .        B: target (0, 6), 6 cells away
#   A . . . . . .
WALLED = np.full((3, 7), FREE, dtype=np.int8)
WALLED[1, :6] = OCCUPIED


@pytest.mark.parametrize("name", TEAM_POLICIES)
def test_one_robot_takes_the_nearest_cluster_by_path(name):
    info = free_info([(0, (2, 0)), (1, (0, 6))], (0, 0), WALLED)
    policy = make_policy(name)
    assert policy.act(None, info) == 1  # B: 6 cells by path, though A is nearer by Euclid
    assert make_policy("greedy-distance").act(None, info) == 0
    info = free_info([(0, (0, 2)), (1, (0, 6))], (0, 0), WALLED)
    assert policy.act(None, info) == 0
    assert policy.act(None, free_info([], (0, 0), WALLED)) == 0  # nothing live: idle slot 0


@pytest.mark.parametrize("name", TEAM_POLICIES)
def test_one_robot_in_a_real_episode_follows_the_shortest_path_rule(name):
    env = frontier_marl.parallel_env(height=14, width=14, obstacle_prob=0.2)
    policy = make_policy(name)
    policy.attach(env)
    obs, infos = env.reset(seed=3)
    steps = 0
    while env.agents:
        info = infos["robot_0"]
        action = policy.act_team(obs, infos)["robot_0"]
        if slot_table(info).rows():
            dist = bfs_distances(env.world.belief == FREE, tuple(info["position"]))
            lengths = {c["slot"]: dist[c["target"]] for c in slot_table(info).rows()}
            assert lengths[action] == min(lengths.values())
        obs, _, _, _, infos = env.step({"robot_0": action})
        steps += 1
    assert steps > 5


def test_two_robots_sharing_a_nearest_cluster_are_split():
    belief = np.full((1, 9), FREE, np.int8)
    # Robots at columns 3 and 2, clusters A (col 0) and B (col 8): both are nearer A, where
    # independent greedy sends both. Assignment totals: robot_0 -> A, robot_1 -> B: 3 + 6;
    # robot_0 -> B, robot_1 -> A: 5 + 2 (chosen). Utility discount (r = 2, costs / 6):
    # robot_1 -> A first (1 - 2/6), then A is worth 0 to robot_0, which takes B.
    infos = {
        "robot_0": free_info([(0, (0, 0)), (1, (0, 8))], (0, 3), belief),
        "robot_1": free_info([(0, (0, 0)), (1, (0, 8))], (0, 2), belief),
    }
    actions = CoordinatedAssignment().act_team(dict.fromkeys(infos), infos)
    assert actions == {"robot_0": 1, "robot_1": 0}
    ud = UtilityDiscount(sensor_range=2).act_team(dict.fromkeys(infos), infos)
    assert ud == {"robot_0": 1, "robot_1": 0}


def test_robots_outnumbering_clusters_share_the_nearest():
    belief = np.full((1, 9), FREE, np.int8)
    infos = {
        "robot_0": free_info([(5, (0, 8))], (0, 7), belief),
        "robot_1": free_info([(5, (0, 8))], (0, 1), belief),
        "robot_2": free_info([], (0, 4), belief),
    }
    actions = CoordinatedAssignment().act_team(dict.fromkeys(infos), infos)
    assert actions == {"robot_0": 0, "robot_1": 0, "robot_2": 0}


def test_utility_discount_formula():
    # A free 1 x 21 corridor. Robot 0 at column 10, robot 1 at column 20; clusters A (col 13),
    # B (col 15), C (col 5). Path lengths: robot 0: A 3, B 5, C 5; robot 1: A 7, B 5, C 15;
    # costs are normalised by the largest, 15.
    # Round 1, U = 1 everywhere: the best pair is robot 0 -> A (1 - 3/15 = 0.8; robot 1's
    # best is B, 1 - 5/15 = 0.667). Claiming A takes P(d) = max(0, 1 - d / r) from every
    # target: B (d = 2) keeps 2 / r, C (d = 8) keeps 1 as long as r <= 8.
    # Round 2, robot 1: B scores 2/r - 1/3 and C scores 1 - 15/15 = 0, so it takes C exactly
    # when r > 6.
    belief = np.full((1, 21), FREE, np.int8)
    targets = [(0, (0, 13)), (1, (0, 15)), (2, (0, 5))]
    infos = {
        "robot_0": free_info(targets, (0, 10), belief),
        "robot_1": free_info(targets, (0, 20), belief),
    }
    obs = dict.fromkeys(infos)
    assert UtilityDiscount(sensor_range=5.5).act_team(obs, infos) == {"robot_0": 0, "robot_1": 1}
    assert UtilityDiscount(sensor_range=6.5).act_team(obs, infos) == {"robot_0": 0, "robot_1": 2}
    # beta = 0: only utility counts, so any discount of B (r > 2) sends robot 1 to C; with
    # r = 2 nothing is discounted and the tie goes to the shorter path (B).
    assert UtilityDiscount(beta=0.0, sensor_range=3).act_team(obs, infos)["robot_1"] == 2
    assert UtilityDiscount(beta=0.0, sensor_range=2).act_team(obs, infos)["robot_1"] == 1
    assert UtilityDiscount.visibility(np.array([0.0, 1.5, 3.0, 7.0]), 3.0).tolist() == [
        1.0,
        0.5,
        0.0,
        0.0,
    ]


def test_utility_discount_moves_the_second_robot_off_a_claimed_area():
    # Two robots side by side; clusters A (0, 5) and A' (0, 6) next to each other on the right,
    # C (0, 0) far on the left. Without discount both would go right; with r = 4, A' loses
    # 1 - 1/4 of its utility once A is claimed, so the second robot goes to C.
    belief = np.full((1, 12), FREE, np.int8)
    targets = [(0, (0, 5)), (1, (0, 6)), (2, (0, 0))]
    infos = {
        "robot_0": free_info(targets, (0, 3), belief),
        "robot_1": free_info(targets, (0, 4), belief),
    }
    actions = UtilityDiscount(sensor_range=4).act_team(dict.fromkeys(infos), infos)
    chosen = chosen_clusters(infos, actions)
    assert sorted(chosen.values()) == [0, 2]
    wide = UtilityDiscount(sensor_range=0.5).act_team(dict.fromkeys(infos), infos)
    assert sorted(chosen_clusters(infos, wide).values()) == [0, 1]  # tiny range: no discount


def test_team_heuristics_need_the_slot_tables_and_a_range():
    info = free_info([(0, (0, 2))], (0, 0), WALLED)
    del info["slots"]
    for name in TEAM_POLICIES:
        with pytest.raises(ValueError, match="slots"):
            make_policy(name).act_team({"a": None, "b": None}, {"a": info, "b": info})
    belief = np.full((1, 5), FREE, np.int8)
    infos = {
        "a": free_info([(0, (0, 2))], (0, 0), belief),
        "b": free_info([(0, (0, 2))], (0, 4), belief),
    }
    with pytest.raises(ValueError, match="sensor range"):
        UtilityDiscount().act_team(dict.fromkeys(infos), infos)
    with pytest.raises(ValueError, match="beta"):
        UtilityDiscount(beta=-1.0)
    with pytest.raises(ValueError, match="sensor_range"):
        UtilityDiscount(sensor_range=0)


# ----------------------------------------------------------------- team metrics


def test_overlap_of_one_robot_is_zero():
    env = frontier_marl.parallel_env(height=12, width=12, explore_threshold=0.9)
    result = evaluate(env, make_policy("greedy-distance"), episodes=2, seed=0)
    assert [e.overlap for e in result.episodes] == [0.0, 0.0]
    assert overlap_ratio(np.asarray(env.world.seen)) == 0.0
    assert env.world.seen.shape[0] == 1 and env.world.seen.any()


def test_makespan_curve():
    curve = makespan_curve(np.array([[0, 0], [1, 3], [4, 3]]), [0.1, 0.5, 0.9])
    assert curve.tolist() == [[0, 0.1], [3, 0.5], [4, 0.9]]
    with pytest.raises(ValueError, match="robot_travelled"):
        makespan_curve(np.zeros(3), [0, 0, 0])


def manual_team_episode(kwargs: dict, seed: int) -> dict:
    env = frontier_marl.parallel_env(**kwargs)
    policy = make_policy("greedy-distance")
    obs, infos = env.reset(seed=seed)
    agents = list(env.agents)
    travelled = [[0] * len(agents)]
    coverage = [infos[agents[0]]["coverage"]]
    while env.agents:
        obs, _, _, _, infos = env.step(policy.act_team(obs, infos))
        travelled.append([infos[a]["travelled"] for a in agents])
        coverage.append(infos[agents[0]]["coverage"])
    first = {}
    for level in (0.9, 0.99):
        hit = next((i for i, c in enumerate(coverage) if c >= level), None)
        first[level] = None if hit is None else (max(travelled[hit]), sum(travelled[hit]))
    return {
        "travelled": travelled,
        "first": first,
        "overlap": overlap_ratio(np.asarray(env.world.seen)),
    }


def test_evaluation_reports_team_metrics():
    kwargs = {
        "map_path": str(example_map_path("rooms-32")),
        "n_agents": 3,
        "explore_threshold": 1.0,
        "no_progress_limit": 200,
    }
    result = evaluate(kwargs, make_policy("greedy-distance"), episodes=2, seed=1)
    for episode, seed in zip(result.episodes, (1, 2), strict=True):
        manual = manual_team_episode(kwargs, seed)
        assert episode.robot_travelled == manual["travelled"][-1]
        assert episode.makespan == max(manual["travelled"][-1])
        for level, key in ((0.9, "0.90"), (0.99, "0.99")):
            makespan, cells = manual["first"][level]
            assert episode.makespan_to_coverage[key] == makespan
            assert episode.cells_to_coverage[key] == cells
        assert episode.overlap == pytest.approx(manual["overlap"])
        assert 0.0 < episode.overlap < 2.0
        assert episode.makespan_curve[-1, 0] == episode.makespan
    row = result.to_dict()
    json.dumps(row)
    assert row["mean_makespan"] == pytest.approx(np.mean([e.makespan for e in result.episodes]))
    assert row["makespan_to_coverage"]["0.99"]["reached"] == 2
    assert row["mean_overlap"] == pytest.approx(np.mean([e.overlap for e in result.episodes]))
    episode = row["per_episode"][0]
    assert {
        "makespan",
        "makespan_to_coverage",
        "overlap",
        "robot_travelled",
        "makespan_curve",
    } <= set(episode)
    single = evaluate({**kwargs, "n_agents": 1}, make_policy("greedy-distance"), episodes=1)
    assert "mean_makespan" not in single.to_dict()
    assert "makespan" not in single.to_dict()["per_episode"][0]


def test_coordination_beats_independent_greedy_on_overlap_with_four_robots():
    # A smoke check of the experiment's direction (docs/multi-robot.md has the full numbers).
    kwargs = {
        "map_path": str(example_map_path("rooms-32")),
        "n_agents": 4,
        "explore_threshold": 1.0,
        "no_progress_limit": 200,
    }
    greedy = evaluate(kwargs, make_policy("greedy-distance"), episodes=8, seed=0)
    coordinated = evaluate(kwargs, make_policy("coordinated-assignment"), episodes=8, seed=0)
    assert coordinated.team_summary()["mean_overlap"] < greedy.team_summary()["mean_overlap"]


# ----------------------------------------------------------------- commands


SMALL = [
    "--set",
    "perception_range=3",
    "--set",
    "explore_threshold=1.0",
    "--set",
    "no_progress_limit=200",
]


def test_baselines_team_table_and_json(tmp_path, capsys):
    out_json, out_png = tmp_path / "team.json", tmp_path / "team.png"
    code = main(
        [
            "baselines",
            "--episodes",
            "2",
            "--agents",
            "2",
            "--map",
            "rooms-32",
            "--policies",
            "greedy-distance,coordinated-assignment,utility-discount",
            "--no-progress",
            "--json",
            str(out_json),
            "--plot",
            str(out_png),
            *SMALL,
        ]
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert "makespan→90%" in printed and "makespan→99%" in printed and "overlap" in printed
    assert "file rooms-32.txt" in printed
    rows = json.loads(out_json.read_text())
    assert [r["policy"] for r in rows] == [
        "greedy-distance",
        "coordinated-assignment",
        "utility-discount",
    ]
    for row in rows:
        assert row["n_agents"] == 2 and row["config"]["height"] == 32
        assert row["makespan_to_coverage"]["0.99"]["reached"] == 2
        assert row["mean_overlap"] is not None
    assert out_png.read_bytes()[:4] == b"\x89PNG"


def test_baselines_single_robot_table_has_no_team_columns(capsys):
    assert (
        main(
            [
                "baselines",
                "--episodes",
                "1",
                "--policies",
                "greedy-distance",
                "--no-progress",
                "--set",
                "max_steps=5",
            ]
        )
        == 0
    )
    assert "makespan" not in capsys.readouterr().out


def test_map_generator_and_map_options(tmp_path, capsys):
    assert (
        main(
            [
                "baselines",
                "--episodes",
                "1",
                "--agents",
                "2",
                "--map-generator",
                "rooms",
                "--policies",
                "utility-discount",
                "--no-progress",
                "--set",
                "height=16",
                "--set",
                "width=24",
                "--set",
                "max_steps=20",
            ]
        )
        == 0
    )
    assert "rooms, map_seed=0" in capsys.readouterr().out
    map_file = tmp_path / "plan.txt"
    map_file.write_text(CORRIDOR)
    out = tmp_path / "ep.gif"
    assert (
        main(
            [
                "gif",
                "--policy",
                "coordinated-assignment",
                "--agents",
                "2",
                "--map",
                str(map_file),
                "--out",
                str(out),
                "--max-steps",
                "3",
            ]
        )
        == 0
    )
    assert out.read_bytes()[:3] == b"GIF"
    for bad in (
        ["--map", "rooms-32", "--map-generator", "rooms"],
        ["--map", str(tmp_path / "missing.txt")],
        ["--map", "rooms-32", "--set", "map_path=x.txt"],
        ["--map", "rooms-32", "--map-mode", "dynamic"],
    ):
        assert main(["baselines", "--episodes", "1", "--no-progress", *bad]) == 2
    err = capsys.readouterr().err
    assert "exclude each other" in err and "does not exist" in err and "map_mode" in err


def test_multi_robot_experiment_script_runs(tmp_path):
    settings_ = {
        "tiny": {
            "map_path": str(example_map_path("rooms-32")),
            "explore_threshold": 1.0,
            "no_progress_limit": 200,
        }
    }
    policies = {
        name: (lambda name=name: make_policy(name))
        for name in ("greedy-distance", "coordinated-assignment")
    }
    rows = multi_robot.run_experiment(settings_, policies, [1, 2], episodes=2, log=lambda _: None)
    assert [(r["n_agents"], r["policy"]) for r in rows] == [
        (1, "greedy-distance"),
        (1, "coordinated-assignment"),
        (2, "greedy-distance"),
        (2, "coordinated-assignment"),
    ]
    table = multi_robot_tables.results_table(rows)
    assert table.count("\n") == 5 and "| tiny | 2 | coordinated-assignment |" in table
    entries = multi_robot_tables.comparison(rows)
    assert len(entries) == 1 and entries[0]["n_agents"] == 2
    overlap = entries[0]["overlap"]
    assert overlap["wins"] + overlap["ties"] + overlap["losses"] == 2
    assert "coordinated-assignment" in multi_robot_tables.comparison_table(entries)
    from frontier_marl.evaluation.plots import plot_team_comparison

    plot_team_comparison(rows, tmp_path / "tiny.png", title="tiny")
    assert (tmp_path / "tiny.png").read_bytes()[:4] == b"\x89PNG"


# ----------------------------------------------------------------- PettingZoo suites

API_CASES = [
    pytest.param({"map_path": "rooms-32"}, id="loaded-rooms-32"),
    pytest.param(
        {"map_path": "rooms-32", "teammates": "positions+targets", "action_mask": True},
        id="loaded-teammates",
    ),
    pytest.param({"map_generator": "rooms", "height": 24, "width": 40}, id="rooms-static"),
    pytest.param(
        {
            "map_generator": "rooms",
            "height": 30,
            "width": 22,
            "map_mode": "dynamic",
            "teammates": "positions",
        },
        id="rooms-dynamic",
    ),
]


def _resolve(kwargs: dict) -> dict:
    if kwargs.get("map_path") == "rooms-32":
        return {**kwargs, "map_path": str(example_map_path("rooms-32"))}
    return kwargs


@pytest.mark.parametrize("n_agents", [2, 8])
@pytest.mark.parametrize("kwargs", API_CASES)
def test_pettingzoo_suites_with_teams_on_structured_maps(kwargs, n_agents):
    kwargs = {**_resolve(kwargs), "n_agents": n_agents}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # Dict observations, by design
        parallel_api_test(frontier_marl.parallel_env(**kwargs), num_cycles=100)
        parallel_seed_test(lambda: frontier_marl.parallel_env(**kwargs), num_cycles=100)
    env = frontier_marl.parallel_env(**kwargs)
    assert env.possible_agents == [f"robot_{i}" for i in range(n_agents)]


def test_team_commit_keeps_each_robot_on_its_target_after_a_step_without_progress():
    # Robot 0 heads for A (col 8) but B (col 0) is nearer now; robot 1 heads nowhere. Without
    # progress, robot 0 keeps A and robot 1 gets the other cluster.
    belief = np.full((1, 9), FREE, np.int8)
    clusters = [(0, (0, 0)), (1, (0, 8))]
    infos = {
        "robot_0": {**free_info(clusters, (0, 3), belief), "target": (0, 8), "new_cells": 0},
        "robot_1": {**free_info(clusters, (0, 4), belief), "target": None, "new_cells": 0},
    }
    obs = dict.fromkeys(infos)
    for name in TEAM_POLICIES:
        kwargs = {"sensor_range": 2} if name == "utility-discount" else {}
        policy = make_policy(name, commit="until-progress", **kwargs)
        assert policy.act_team(obs, infos) == {"robot_0": 1, "robot_1": 0}, name
        progressed = {a: {**i, "new_cells": 1} for a, i in infos.items()}
        fresh = make_policy(name, **kwargs).act_team(obs, progressed)
        assert policy.act_team(obs, progressed) == fresh, name


def test_team_commit_on_cycle_keeps_the_target_of_a_robot_back_on_a_cell():
    # Robot 0 heads for A (col 8) from (0, 3), steps to (0, 2) and back to (0, 3) while no
    # robot sees anything new: it is cycling and keeps A; robot 1 moves on and is decided
    # with the team. Once a robot sees a new cell, both are decided afresh.
    belief = np.full((1, 9), FREE, np.int8)
    clusters = [(0, (0, 0)), (1, (0, 8))]

    def infos_at(step, cell_0, cell_1, new_cells=0):
        return {
            "robot_0": {
                **free_info(clusters, cell_0, belief),
                "target": (0, 8) if step else None,
                "new_cells": new_cells,
                "step": step,
            },
            "robot_1": {
                **free_info(clusters, cell_1, belief),
                "target": None,
                "new_cells": 0,
                "step": step,
            },
        }

    walk = [infos_at(0, (0, 3), (0, 4)), infos_at(1, (0, 2), (0, 5)), infos_at(2, (0, 3), (0, 6))]
    obs = dict.fromkeys(walk[0])
    for name in TEAM_POLICIES:
        kwargs = {"sensor_range": 2} if name == "utility-discount" else {}
        policy = make_policy(name, commit="on-cycle", **kwargs)
        for infos in walk[:2]:
            assert policy.act_team(obs, infos) == make_policy(name, **kwargs).act_team(obs, infos)
        assert make_policy(name, **kwargs).act_team(obs, walk[2])["robot_0"] == 0, name
        assert policy.act_team(obs, walk[2])["robot_0"] == 1, name  # keeps A
        progressed = infos_at(3, (0, 3), (0, 6), new_cells=2)
        fresh = make_policy(name, **kwargs).act_team(obs, progressed)
        assert policy.act_team(obs, progressed) == fresh, name
