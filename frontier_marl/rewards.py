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


class OscillationHistory:
    """The oscillation test of W worlds of N robots: a robot oscillates when its target differs
    from its previous one but was chosen in the ``window`` steps before that (it cycles between
    the same targets). Targets are (row, col) cells; a row of -1 means no target (idle)."""

    _EMPTY = -2  # a history entry not yet filled: equal to no target

    def __init__(self, n_worlds: int, n_agents: int, window: int) -> None:
        self.window = window
        # the last window + 1 targets, oldest first
        self._history = np.full((n_worlds, n_agents, window + 1, 2), self._EMPTY, dtype=np.int64)

    def clear(self, worlds: np.ndarray | slice) -> None:
        """Forget the history of ``worlds`` (a new episode)."""
        self._history[worlds] = self._EMPTY

    def update(self, targets: np.ndarray) -> np.ndarray:
        """Record ``targets`` (W, N, 2); returns bool (W, N): which robots oscillate."""
        history = self._history
        last = history[:, :, -1]
        earlier = history[:, :, :-1]
        oscillates = (
            (targets[..., 0] >= 0)
            & (last[..., 0] >= 0)
            & (targets != last).any(axis=-1)
            & (earlier == targets[:, :, None]).all(axis=-1).any(axis=-1)
        )
        history[:, :, :-1] = history[:, :, 1:]
        history[:, :, -1] = targets
        return oscillates


class OscillationDetector:
    """:class:`OscillationHistory` of one robot, for targets given as cells or ``None``."""

    def __init__(self, window: int) -> None:
        self._history = OscillationHistory(1, 1, window)

    def update(self, target: tuple[int, int] | None) -> bool:
        cell = np.array([[(-1, -1) if target is None else target]], dtype=np.int64)
        return bool(self._history.update(cell)[0, 0])


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
    moved: Sequence[int] | None = None  # cells each robot walked (the travel reward's term)


@dataclass(slots=True)
class StepOutcome:
    rewards: np.ndarray  # float (N,)
    terminated: bool
    truncated: bool
    reason: str  # "threshold" | "no_frontier" | truncation causes joined by "+" | ""


# End reasons as bits of an int code (:func:`batch_outcome`); :data:`REASONS` decodes them.
THRESHOLD, NO_FRONTIER, PADDING, NO_PROGRESS, STEP_LIMIT = 1, 2, 4, 8, 16
_REASON_NAMES = ((PADDING, "padding"), (NO_PROGRESS, "no_progress"), (STEP_LIMIT, "step_limit"))
REASONS: tuple[str, ...] = tuple(
    "threshold"
    if code == THRESHOLD
    else "no_frontier"
    if code == NO_FRONTIER
    else "+".join(name for bit, name in _REASON_NAMES if code & bit)
    for code in range(32)
)


@dataclass(slots=True)
class BatchOutcome:
    """The reward table applied to a batch of worlds: rewards ``(W, N)``, flags and end-reason
    codes ``(W,)`` (``REASONS[code]`` is the reason's name, "" while the episode goes on)."""

    rewards: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
    reason: np.ndarray


def batch_outcome(
    cfg: RewardConfig,
    new_cells: np.ndarray,
    padding: np.ndarray,
    oscillation: np.ndarray,
    threshold_reached: np.ndarray,
    no_frontier_left: np.ndarray,
    steps_taken: np.ndarray,
    steps_without_progress: np.ndarray,
    moved: np.ndarray | None = None,
) -> BatchOutcome:
    """Apply the reward table to one step of W worlds of N robots: per-robot arrays are
    ``(W, N)``, per-world ones ``(W,)`` (the fields of :class:`StepEvents`, batched);
    ``moved`` (cells walked) is needed by the ``travel`` reward only."""
    weight = cfg.team_weight
    if weight:
        credited = (1.0 - weight) * new_cells + weight * new_cells.sum(axis=1, keepdims=True)
    else:
        credited = new_cells
    rewards = cfg.cell_reward * credited
    if cfg.kind == "travel":
        if moved is None:
            raise ValueError("the travel reward needs the cells each robot walked")
        rewards = rewards + cfg.travel_cost * np.maximum(moved, 1)
    else:
        rewards = rewards + np.where(new_cells == 0, cfg.no_new_cell_penalty, 0.0)
    rewards = rewards + np.where(padding, cfg.padding, 0.0)
    if cfg.kind == "reward2":
        rewards = rewards + np.where(oscillation, cfg.oscillation_penalty, 0.0)
    threshold = np.asarray(threshold_reached, dtype=bool)
    no_frontier = np.asarray(no_frontier_left, dtype=bool) & ~threshold
    going_on = ~(threshold | no_frontier)
    no_progress = going_on & (steps_without_progress >= cfg.no_progress_limit)
    step_limit = going_on & (steps_taken >= cfg.max_steps)
    reason = threshold * THRESHOLD + no_frontier * NO_FRONTIER
    reason = reason + no_progress * NO_PROGRESS + step_limit * STEP_LIMIT
    if cfg.padding_truncates:
        reason = reason + (going_on & padding.any(axis=1)) * PADDING
    rewards = rewards + np.where(threshold, cfg.goal_bonus, 0.0)[:, None]
    rewards = rewards + np.where(no_progress, cfg.no_progress_penalty, 0.0)[:, None]
    rewards = rewards + np.where(step_limit, cfg.step_limit_penalty, 0.0)[:, None]
    truncated = going_on & (reason > 0)
    return BatchOutcome(rewards, threshold | no_frontier, truncated, reason)


def step_outcome(cfg: RewardConfig, events: StepEvents) -> StepOutcome:
    """Apply the reward table to one step's events (:func:`batch_outcome` for one world)."""
    outcome = batch_outcome(
        cfg,
        np.asarray(events.new_cells, dtype=np.int64)[None],
        np.asarray(events.padding, dtype=bool)[None],
        np.asarray(events.oscillation, dtype=bool)[None],
        np.array([events.threshold_reached]),
        np.array([events.no_frontier_left]),
        np.array([events.steps_taken]),
        np.array([events.steps_without_progress]),
        None if events.moved is None else np.asarray(events.moved, dtype=np.int64)[None],
    )
    return StepOutcome(
        outcome.rewards[0],
        bool(outcome.terminated[0]),
        bool(outcome.truncated[0]),
        REASONS[int(outcome.reason[0])],
    )
