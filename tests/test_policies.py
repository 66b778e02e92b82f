"""Tests for frontier_marl.evaluation: each heuristic on hand-made infos, and on the real envs."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import frontier_marl
from frontier_marl import reason_name, slot_table
from frontier_marl.core.grid import FREE
from frontier_marl.policies import (
    POLICIES,
    CallablePolicy,
    CostUtility,
    FirstSlot,
    GreedyDistance,
    GreedyGain,
    ModelPolicy,
    RandomValid,
    make_policy,
)
from frontier_marl.policies.registry import env_settings
from tests.helpers import info_with, live_slot
from tests.oracles import bfs

# ----------------------------------------------------------------- greedy distance / gain


def test_first_slot_is_greedy_distance_when_slots_are_sorted():
    from frontier_marl.evaluation import evaluate

    env = {"preset": "thesis-20x20", "sort_by_distance": True}
    first = evaluate(env, FirstSlot(), episodes=3)
    greedy = evaluate(env, GreedyDistance(), episodes=3)
    assert first.rewards == greedy.rewards
    unsorted = evaluate({"preset": "thesis-20x20"}, FirstSlot(), episodes=3)
    assert unsorted.rewards != first.rewards  # slot 0 is another cluster when unsorted
    info = info_with([live_slot(9, 4.0), live_slot(1, 0.5)])
    assert FirstSlot().act(None, info) == 0


def test_greedy_distance_picks_the_nearest_centroid():
    info = info_with([live_slot(9, 4.0), live_slot(2, 1.5), live_slot(5, 3.0)])
    assert GreedyDistance().act(None, info) == 1


def test_greedy_distance_ties_go_to_the_lowest_slot():
    info = info_with([live_slot(5, 3.0), live_slot(1, 2.0), live_slot(9, 2.0)])
    assert GreedyDistance().act(None, info) == 1


def test_greedy_gain_picks_the_largest_gain():
    info = info_with([live_slot(3, 1.0), live_slot(2, 1.5), live_slot(7, 6.0)])
    assert GreedyGain().act(None, info) == 2


def test_greedy_gain_ties_go_to_the_nearest_then_the_lowest_slot():
    info = info_with([live_slot(7, 5.0), live_slot(2, 0.5), live_slot(7, 2.0)])
    assert GreedyGain().act(None, info) == 2
    info = info_with([live_slot(1, 0.5), live_slot(7, 2.0), live_slot(7, 2.0)])
    assert GreedyGain().act(None, info) == 1


#: The heuristics that read the slot table alone (frontier-rule reads its own observation:
#: tests/test_frontier_rule.py).
SLOT_TABLE_POLICIES = [name for name in POLICIES if not env_settings(name)]


@pytest.mark.parametrize("name", SLOT_TABLE_POLICIES)
def test_no_live_cluster_gives_slot_0(name):
    policy = make_policy(name, seed=0)
    assert policy.act(None, info_with([])) == 0


# ----------------------------------------------------------------- cost-utility

# A wall between the robot and target A: A is 2 cells away by Euclid but 14 by path, B 6 and 6.


def walled_info(gain_a: float, gain_b: float) -> dict:
    return info_with(
        [live_slot(gain_a, 2.0, path_length=14), live_slot(gain_b, 6.0, path_length=6)]
    )


def test_cost_utility_uses_path_length_not_euclidean_distance():
    info = walled_info(gain_a=4, gain_b=3)  # utilities 4/14 and 3/6
    np.testing.assert_allclose(CostUtility.utilities(info["slots"]), [4 / 14, 0.5])
    assert CostUtility().act(None, info) == 1
    # the other heuristics prefer A (nearer by Euclid, larger gain)
    assert GreedyDistance().act(None, info) == 0
    assert GreedyGain().act(None, info) == 0


def test_cost_utility_prefers_a_large_enough_gain_behind_the_wall():
    assert CostUtility().act(None, walled_info(gain_a=10, gain_b=3)) == 0  # 10/14 > 3/6


def test_cost_utility_ties_go_to_the_nearest():
    # 7/14 == 3/6: tie on utility, then the smaller Euclidean distance (A: 2.0)
    assert CostUtility().act(None, walled_info(gain_a=7, gain_b=3)) == 0


def test_cost_utility_counts_a_path_of_zero_as_one():
    info = info_with([live_slot(2, 0.0, path_length=0), live_slot(3, 2.0, path_length=2)])
    np.testing.assert_allclose(CostUtility.utilities(info["slots"]), [2.0, 1.5])
    assert CostUtility().act(None, info) == 0


def test_heuristics_need_the_slot_table():
    with pytest.raises(ValueError, match="slots"):
        CostUtility().act(None, {"action_mask": np.ones(4, np.int8)})


def test_cost_utility_in_a_real_episode_maximises_gain_over_the_bfs_path():
    env = frontier_marl.parallel_env(height=8, width=9, obstacle_prob=0.15)
    policy = CostUtility()
    obs, infos = env.reset(seed=3)
    steps = 0
    while env.agents and steps < 15:
        info = infos["robot_0"]
        table = slot_table(info)
        dist = bfs(env.world.belief == FREE, tuple(info["position"]))
        lengths = [dist[tuple(table.target[s])] for s in range(table.live)]
        np.testing.assert_array_equal(table.path_length[: table.live], lengths)
        utility = table.gain[: table.live] / np.maximum(lengths, 1)
        action = policy.act(obs["robot_0"], info)
        assert utility[action] == utility.max()
        obs, _, _, _, infos = env.step({"robot_0": action})
        steps += 1
    assert steps > 3


# ----------------------------------------------------------------- random


def test_random_draws_only_valid_slots_uniformly_and_reproducibly():
    info = info_with([live_slot(), live_slot()], n_slots=5)
    policy = RandomValid()
    policy.reset(7)
    draws = [policy.act(None, info) for _ in range(400)]
    assert set(draws) == {0, 1}
    assert 150 < draws.count(1) < 250
    again = make_policy("random", seed=7)
    assert [again.act(None, info) for _ in range(400)] == draws


# ----------------------------------------------------------------- interface


def test_make_policy_lists_valid_names():
    with pytest.raises(ValueError, match="greedy-distance.*greedy-gain.*cost-utility.*random"):
        make_policy("nearest")
    assert make_policy("greedy-gain").name == "greedy-gain"


def test_act_team_decides_for_every_robot_independently():
    infos = {
        "robot_0": info_with([live_slot(1, 3.0), live_slot(1, 1.0)]),
        "robot_1": info_with([live_slot(1, 0.5), live_slot(1, 1.0)]),
    }
    actions = GreedyDistance().act_team({"robot_0": None, "robot_1": None}, infos)
    assert actions == {"robot_0": 1, "robot_1": 0}


def test_callable_and_model_adapters():
    assert CallablePolicy(lambda obs: np.array([2])).act(None, {}) == 2

    class FakeModel:
        def predict(self, obs, deterministic=True):
            return np.int64(3 if deterministic else 0), None

    assert ModelPolicy(FakeModel()).act(np.zeros(3), {}) == 3
    with pytest.raises(ValueError, match="predict"):
        ModelPolicy(object())
    with pytest.raises(ValueError, match="one slot"):
        CallablePolicy(lambda obs: [1, 2]).act(None, {})


@pytest.mark.parametrize("name", list(POLICIES))
def test_heuristics_choose_valid_slots_in_a_team(name):
    env = frontier_marl.parallel_env(
        height=10, width=10, n_agents=2, obstacle_prob=0.15, explore_threshold=0.8,
        **env_settings(name),
    )  # fmt: skip
    policy = make_policy(name, seed=1)
    policy.attach(env)
    obs, infos = env.reset(seed=1)
    steps = 0
    while env.agents:
        actions = policy.act_team(obs, infos)
        assert set(actions) == {"robot_0", "robot_1"}
        for agent, slot in actions.items():
            assert infos[agent]["action_mask"][slot] == 1
        obs, _, _, _, infos = env.step(actions)
        steps += 1
    assert steps >= 1


def test_heuristic_drives_the_gymnasium_env():
    # explore_threshold < 1 so that the episode ends before the last frontier vanishes (see
    # test_evaluation.py::test_fully_known_map_gives_exact_numbers for that case).
    env = gym.make(
        frontier_marl.GYM_ID,
        height=8,
        width=8,
        obstacle_prob=0.1,
        perception_range=2,
        explore_threshold=0.8,
    )
    policy = make_policy("cost-utility")
    policy.attach(env)
    obs, info = env.reset(seed=0)
    done = False
    while not done:
        action = policy.act(obs, info)
        assert info["action_mask"][action] == 1
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    assert reason_name(info["end_reason"]) == "threshold"


# ----------------------------------------------------------------- commitment (livelocks)


def test_commit_keeps_the_previous_target_while_nothing_new_was_seen() -> None:
    live = [live_slot(1, 2.0, target=(0, 1)), live_slot(1, 1.0, target=(0, 2))]
    policy = GreedyDistance(commit="until-progress")
    stuck = info_with(live, target=(0, 1), new_cells=0)
    assert GreedyDistance().act(None, stuck) == 1  # the nearest centroid
    assert policy.act(None, stuck) == 0  # walks on to (0, 1)
    assert policy.act(None, {**stuck, "new_cells": 3}) == 1  # progress: decide afresh
    assert policy.act(None, {**stuck, "target": (5, 5)}) == 1  # no longer offered
    assert policy.act(None, {**stuck, "target": None}) == 1  # no previous target


def test_commit_on_cycle_keeps_the_target_once_a_cell_repeats_without_progress():
    # two clusters; the robot walks (0, 3) -> (0, 4) -> (0, 3) seeing nothing new, the
    # nearest centroid flipping at each cell: at its second stand on (0, 3) it is in a cycle
    toward_a = [live_slot(1, 2.0, target=(0, 1)), live_slot(1, 1.0, target=(0, 2))]
    toward_b = [live_slot(1, 1.0, target=(0, 1)), live_slot(1, 2.0, target=(0, 2))]
    steps = [
        info_with(toward_a, step=0, position=(0, 3), target=None, new_cells=0),
        info_with(toward_b, step=1, position=(0, 4), target=(0, 2), new_cells=0),
        info_with(toward_a, step=2, position=(0, 3), target=(0, 1), new_cells=0),
        info_with(toward_b, step=3, position=(0, 4), target=(0, 1), new_cells=0),
        info_with(toward_a, step=4, position=(0, 5), target=(0, 1), new_cells=4),
    ]
    plain = [GreedyDistance().act(None, info) for info in steps]
    assert plain == [1, 0, 1, 0, 1]
    policy = GreedyDistance(commit="on-cycle")
    # steps 2 and 3: cycling, keeps (0, 1) (slot 0); step 4 saw something: decides afresh
    assert [policy.act(None, info) for info in steps] == [1, 0, 0, 0, 1]
    # a new episode (step 0) forgets the cells; so does reset()
    assert [policy.act(None, info) for info in steps[:3]] == [1, 0, 0]
    policy.reset()
    assert policy.act(None, steps[2]) == 1
    # a kept target no longer offered: the nearest centroid, as without the rule
    assert policy.act(None, {**steps[2], "step": 5, "target": (7, 7)}) == 1
    gain = make_policy("greedy-gain", commit="on-cycle")
    assert gain.commit == "on-cycle"
    team = {"robot_0": steps[0], "robot_1": {**steps[0], "position": (0, 9)}}
    chosen = make_policy("greedy-distance", commit="on-cycle").act_team(dict.fromkeys(team), team)
    assert chosen == {"robot_0": 1, "robot_1": 1}


#: A hand-made 8 x 8 map (``#`` obstacle) on which greedy distance, started from reset seed 0
#: at (6, 7) with the thesis-20x20 defaults (r = 3), ends up turning back and forth between
#: (6, 5) and (5, 5): one cell toward the target (3, 5) makes the centroid of the cluster at
#: (6, 3) the nearer one, and one cell toward that makes the first nearer again.
CYCLE_MAP = """\
......#.
........
.......#
#.......
#....#..
......#.
....#...
........
"""


@pytest.mark.parametrize("commit", ["none", "on-cycle"])
def test_a_greedy_distance_cycle_on_a_tiny_map_and_the_on_cycle_rule(tmp_path, commit):
    """Re-deciding every step, greedy distance cycles between two cells with the map 44 %
    known until the no-progress rule ends the episode; keeping its target once it stands on
    a cell again without having seen anything new, it reaches the threshold."""
    path = tmp_path / "cycle.txt"
    path.write_text(CYCLE_MAP)
    env = frontier_marl.parallel_env(preset="thesis-20x20", map_path=str(path))
    policy = make_policy("greedy-distance", commit=commit)
    observations, infos = env.reset(seed=0)
    cells = []
    while env.agents:
        cells.append(tuple(infos["robot_0"]["position"].tolist()))
        observations, _, _, _, infos = env.step(policy.act_team(observations, infos))
    end = infos["robot_0"]
    if commit == "none":
        assert reason_name(end["end_reason"]) == "no_progress" and end["coverage"] < 0.5
        assert set(cells[-20:]) == {(6, 5), (5, 5)}  # the last 20 steps: two cells
    else:
        assert reason_name(end["end_reason"]) == "threshold"


def test_policy_options_are_checked() -> None:
    assert make_policy("greedy-gain", commit="until-progress").commit == "until-progress"
    assert make_policy("coordinated-assignment", commit="until-progress").commit == "until-progress"
    with pytest.raises(ValueError, match="commit"):
        make_policy("greedy-distance", commit="forever")
    with pytest.raises(ValueError, match="no option 'beta'"):
        make_policy("greedy-distance", beta=2.0)


@pytest.mark.parametrize("commit", ["none", "until-progress", "on-cycle"])
def test_the_thesis_30x30_livelock_and_its_fix(commit: str) -> None:
    """Greedy distance on thesis-30x30, static, seed 16: turning back and forth between two
    clusters ends the episode by the no-progress rule at 37 % coverage; committing to the
    target until something new is seen, or only once a cell repeats without anything new
    seen (``on-cycle``), reaches the threshold."""
    from frontier_marl.evaluation import evaluate

    result = evaluate(
        {"preset": "thesis-30x30"}, make_policy("greedy-distance", commit=commit), 1, seed=16
    )
    (episode,) = result.episodes
    if commit == "none":
        assert episode.end_reason == "no_progress" and episode.coverage < 0.4
    else:
        assert episode.end_reason == "threshold"
