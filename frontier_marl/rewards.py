"""Reward 1 and Reward 2 of the thesis (docs/environment.md), and the oscillation test.

Per robot and step, the terms add up:

================================  =========  =========  ===================================
event                             Reward 1   Reward 2   episode
================================  =========  =========  ===================================
chose a padding slot              -1.0       -0.1       Reward 1: truncated; Reward 2: goes on
revealed no new cell              -0.05      -0.05
revealed n new cells              +0.05 n    +0.05 n
explored fraction >= threshold    +1.0       +1.0       terminated
step limit reached                -1.0       -1.0       truncated
no new cell for N steps in a row  -0.5       -0.5       truncated
oscillation (A -> B -> A)                    -0.05
================================  =========  =========  ===================================

Team rules (N robots): with ``team_weight`` w, a robot's cell term is
``0.05 * ((1 - w) * own + w * team)``, ``own`` being the cells it revealed first and ``team``
all cells the team revealed this step; the no-new-cell penalty still follows its own cells.
Episode-level events (threshold, step limit, no progress, Reward 1's
padding truncation) end the episode for every robot and add their term to every robot's
reward; the per-cell and padding terms are each robot's own. "No progress" counts steps in
which no robot revealed a cell. A robot that has no live slot at all idles without the padding
penalty. The episode also terminates when no robot has a reachable frontier left.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from frontier_marl.config import RewardConfig


class OscillationDetector:
    """Flags a target that differs from the previous one but was chosen in the ``window``
    steps before it (the robot cycles between the same targets)."""

    def __init__(self, window: int) -> None:
        self.window = window
        self._history: tuple[tuple[int, int] | None, ...] = ()  # the last window + 1 targets

    def update(self, target: tuple[int, int] | None) -> bool:
        history = self._history
        oscillates = (
            target is not None
            and len(history) > 0
            and history[-1] is not None
            and target != history[-1]
            and target in history[:-1]
        )
        self._history = (*history[-self.window :], target) if self.window else (target,)
        return oscillates


@dataclass(slots=True)
class StepEvents:
    """What happened in one decision step, per robot (sequences of length N) and for the team."""

    new_cells: Sequence[int]
    padding: Sequence[bool]  # chose a padding slot while a live slot existed
    oscillation: Sequence[bool]
    threshold_reached: bool
    no_frontier_left: bool
    steps_taken: int  # decision steps so far, this one included
    steps_without_progress: int  # consecutive, this one included


@dataclass(slots=True)
class StepOutcome:
    rewards: np.ndarray  # float (N,)
    terminated: bool
    truncated: bool
    reason: str  # "threshold" | "no_frontier" | truncation causes joined by "+" | ""


def step_outcome(cfg: RewardConfig, events: StepEvents) -> StepOutcome:
    """Apply the reward table to one step's events."""
    padding = cfg.padding
    oscillation = cfg.oscillation_penalty if cfg.kind == "reward2" else 0.0
    weight = cfg.team_weight
    new_cells = [int(new) for new in events.new_cells]
    team = sum(new_cells)
    values = []
    for new, pad, osc in zip(new_cells, events.padding, events.oscillation, strict=True):
        credited = (1.0 - weight) * new + weight * team if weight else new
        value = cfg.cell_reward * credited
        if new == 0:
            value += cfg.no_new_cell_penalty
        if pad:
            value += padding
        if osc:
            value += oscillation
        values.append(value)
    rewards = np.array(values)
    if events.threshold_reached:
        return StepOutcome(rewards + cfg.goal_bonus, True, False, "threshold")
    if events.no_frontier_left:
        return StepOutcome(rewards, True, False, "no_frontier")
    reasons = []
    if cfg.padding_truncates and any(events.padding):
        reasons.append("padding")
    if events.steps_without_progress >= cfg.no_progress_limit:
        rewards = rewards + cfg.no_progress_penalty
        reasons.append("no_progress")
    if events.steps_taken >= cfg.max_steps:
        rewards = rewards + cfg.step_limit_penalty
        reasons.append("step_limit")
    return StepOutcome(rewards, False, bool(reasons), "+".join(reasons))
