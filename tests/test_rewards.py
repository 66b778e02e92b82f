"""Tests for frontier_marl.sim.rewards: the thesis's reward tables and the oscillation test."""

from __future__ import annotations

import numpy as np
import pytest

from frontier_marl.config import RewardConfig
from frontier_marl.sim.rewards import OscillationDetector, StepEvents, step_outcome

R1 = RewardConfig(kind="reward1")
R2 = RewardConfig(kind="reward2")


def events(
    new_cells=(0,),
    padding=None,
    oscillation=None,
    threshold_reached=False,
    no_frontier_left=False,
    steps_taken=1,
    steps_without_progress=0,
) -> StepEvents:
    n = len(new_cells)
    return StepEvents(
        new_cells=np.array(new_cells, dtype=np.int64),
        padding=np.array(padding if padding is not None else [False] * n, dtype=bool),
        oscillation=np.array(oscillation if oscillation is not None else [False] * n, dtype=bool),
        threshold_reached=threshold_reached,
        no_frontier_left=no_frontier_left,
        steps_taken=steps_taken,
        steps_without_progress=steps_without_progress,
    )


# (config, events, expected reward, terminated, truncated, reason)
TABLE = [
    # no new cell: -0.05 in both
    (R1, events((0,)), -0.05, False, False, ""),
    (R2, events((0,)), -0.05, False, False, ""),
    # n new cells: +0.05 n in both
    (R1, events((1,)), 0.05, False, False, ""),
    (R2, events((7,)), 0.35, False, False, ""),
    (R1, events((20,)), 1.0, False, False, ""),
    # padding: R1 -1.0 and truncated; R2 -0.1 and the episode continues (plus no new cell)
    (R1, events((0,), padding=[True]), -1.05, False, True, "padding"),
    (R2, events((0,), padding=[True]), -0.15, False, False, ""),
    # explored fraction >= threshold: +1.0, terminated
    (R1, events((3,), threshold_reached=True), 1.15, True, False, "threshold"),
    (R2, events((0,), threshold_reached=True), 0.95, True, False, "threshold"),
    # step limit: -1.0, truncated (default max_steps 400)
    (R1, events((0,), steps_taken=400), -1.05, False, True, "step_limit"),
    (R2, events((2,), steps_taken=400), -0.9, False, True, "step_limit"),
    (R2, events((0,), steps_taken=399), -0.05, False, False, ""),
    # no progress for >= 20 consecutive steps: -0.5, truncated
    (R1, events((0,), steps_without_progress=20), -0.55, False, True, "no_progress"),
    (R2, events((0,), steps_without_progress=25), -0.55, False, True, "no_progress"),
    (R2, events((0,), steps_without_progress=19), -0.05, False, False, ""),
    # both truncation causes in one step add up
    (
        R2,
        events((0,), steps_taken=400, steps_without_progress=20),
        -1.55,
        False,
        True,
        "no_progress+step_limit",
    ),
    # oscillation: -0.05 only in Reward 2
    (R2, events((0,), oscillation=[True]), -0.10, False, False, ""),
    (R2, events((4,), oscillation=[True]), 0.15, False, False, ""),
    (R1, events((0,), oscillation=[True]), -0.05, False, False, ""),
    # R2 padding and oscillation together
    (R2, events((0,), padding=[True], oscillation=[True]), -0.2, False, False, ""),
    # no frontier left: terminated without a bonus
    (R2, events((2,), no_frontier_left=True), 0.1, True, False, "no_frontier"),
    (R1, events((0,), no_frontier_left=True), -0.05, True, False, "no_frontier"),
]


@pytest.mark.parametrize(("cfg", "ev", "reward", "terminated", "truncated", "reason"), TABLE)
def test_reward_table(cfg, ev, reward, terminated, truncated, reason):
    outcome = step_outcome(cfg, ev)
    np.testing.assert_allclose(outcome.rewards, [reward], atol=1e-12)
    assert outcome.terminated is terminated
    assert outcome.truncated is truncated
    assert outcome.reason == reason


def test_threshold_terminates_instead_of_truncating():
    ev = events((1,), threshold_reached=True, steps_taken=400, steps_without_progress=0)
    outcome = step_outcome(R2, ev)
    assert outcome.terminated and not outcome.truncated
    np.testing.assert_allclose(outcome.rewards, [1.05])


def test_team_rewards_per_robot_and_episode_terms_for_everyone():
    # Robot 0 picks padding and reveals nothing, robot 1 reveals 4 cells.
    ev = events((0, 4), padding=[True, False])
    outcome = step_outcome(R1, ev)
    np.testing.assert_allclose(outcome.rewards, [-1.05, 0.2])
    assert outcome.truncated and outcome.reason == "padding"  # ends the episode for the team
    outcome = step_outcome(R2, ev)
    np.testing.assert_allclose(outcome.rewards, [-0.15, 0.2])
    assert not outcome.truncated
    # Step limit adds -1 to every robot.
    outcome = step_outcome(R2, events((0, 4), steps_taken=400))
    np.testing.assert_allclose(outcome.rewards, [-1.05, -0.8])
    # Goal bonus for every robot.
    outcome = step_outcome(R1, events((0, 1, 2), threshold_reached=True))
    np.testing.assert_allclose(outcome.rewards, [0.95, 1.05, 1.1])
    # Oscillation is per robot.
    outcome = step_outcome(R2, events((0, 0), oscillation=[False, True]))
    np.testing.assert_allclose(outcome.rewards, [-0.05, -0.1])


def test_reward_parameters_are_used():
    cfg = RewardConfig(
        kind="reward1",
        padding_penalty=-0.3,
        cell_reward=0.5,
        no_new_cell_penalty=-0.2,
        max_steps=10,
        step_limit_penalty=-3.0,
        no_progress_limit=2,
        no_progress_penalty=-4.0,
        goal_bonus=7.0,
    )
    np.testing.assert_allclose(step_outcome(cfg, events((2,))).rewards, [1.0])
    np.testing.assert_allclose(step_outcome(cfg, events((0,), padding=[True])).rewards, [-0.5])
    outcome = step_outcome(cfg, events((0,), steps_taken=10, steps_without_progress=2))
    np.testing.assert_allclose(outcome.rewards, [-7.2])
    assert outcome.truncated
    np.testing.assert_allclose(
        step_outcome(cfg, events((1,), threshold_reached=True)).rewards, [7.5]
    )


def test_rewards_array_shape_and_dtype():
    outcome = step_outcome(R2, events((0, 1, 2, 3)))
    assert outcome.rewards.shape == (4,)
    assert outcome.rewards.dtype.kind == "f"


# ----------------------------------------------------------------------------- oscillation
A, B, C, D = (1, 1), (2, 5), (3, 0), (0, 4)


def flags(window: int, targets) -> list[bool]:
    detector = OscillationDetector(window)
    return [detector.update(t) for t in targets]


def test_oscillation_a_b_a():
    assert flags(4, [A, B, A]) == [False, False, True]


def test_no_oscillation_when_repeating_or_moving_on():
    assert flags(4, [A, A]) == [False, False]
    assert flags(4, [A, A, A, A]) == [False] * 4
    assert flags(4, [A, B, C]) == [False, False, False]
    assert flags(4, [A, B, B]) == [False, False, False]


def test_oscillation_keeps_cycling():
    assert flags(4, [A, B, A, B, A]) == [False, False, True, True, True]


def test_oscillation_window_limits_the_memory():
    assert flags(4, [A, B, C, A]) == [False, False, False, True]
    assert flags(1, [A, B, A]) == [False, False, True]
    assert flags(1, [A, B, C, A]) == [False, False, False, False]
    assert flags(2, [A, B, C, D, A]) == [False] * 5


def test_oscillation_none_targets():
    assert flags(4, [None, None]) == [False, False]
    assert flags(4, [A, None, A]) == [False, False, False]
    assert flags(4, [A, B, None]) == [False, False, False]
