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
from frontier_marl.core.compiled import compiled


class OscillationHistory:
    """The oscillation test of W worlds of N robots: a robot oscillates when its target differs
    from its previous one but was chosen in the ``window`` steps before that (it cycles between
    the same targets). Targets are (row, col) cells; a row of -1 means no target (idle)."""

    _EMPTY = -2  # a history entry not yet filled: equal to no target

    def __init__(self, n_worlds: int, n_agents: int, window: int) -> None:
        self.window = window
        # the last window + 1 targets, oldest first
        self._history = np.full((n_worlds, n_agents, window + 1, 2), self._EMPTY, dtype=np.int64)

    @property
    def history(self) -> np.ndarray:
        """The ``(W, N, window + 1, 2)`` targets, oldest first (changed in place)."""
        return self._history

    def clear(self, worlds: np.ndarray | slice) -> None:
        """Forget the history of ``worlds`` (a new episode)."""
        self._history[worlds] = self._EMPTY

    def update(self, targets: np.ndarray, active: np.ndarray | None = None) -> np.ndarray:
        """Record ``targets`` (W, N, 2) of the ``active`` worlds (bool (W,), None: all);
        returns bool (W, N): which robots oscillate (False in inactive worlds)."""
        targets = np.asarray(targets, dtype=np.int64)
        out = np.zeros(targets.shape[:2], dtype=np.bool_)
        if active is None or active.all():
            _oscillation_update(self._history, targets, out)
            return out
        history, moved = self._history[active], out[active]
        _oscillation_update(history, targets[active], moved)
        self._history[active], out[active] = history, moved
        return out


@compiled
def _oscillation_update(history: np.ndarray, targets: np.ndarray, out: np.ndarray) -> None:
    """:meth:`OscillationHistory.update` on its ``(W, N, window + 1, 2)`` history."""
    for w in range(targets.shape[0]):
        for n in range(targets.shape[1]):
            out[w, n] = oscillation_step(history[w, n], targets[w, n, 0], targets[w, n, 1])


@compiled
def oscillation_step(history: np.ndarray, row: int, col: int) -> bool:
    """One robot's oscillation test on its ``(window + 1, 2)`` history, which then records
    the target (row, col)."""
    depth = history.shape[0]
    last_row, last_col = history[depth - 1, 0], history[depth - 1, 1]
    flag = False
    if row >= 0 and last_row >= 0 and (row != last_row or col != last_col):
        for i in range(depth - 1):
            if history[i, 0] == row and history[i, 1] == col:
                flag = True
                break
    for i in range(depth - 1):
        history[i, 0] = history[i + 1, 0]
        history[i, 1] = history[i + 1, 1]
    history[depth - 1, 0] = row
    history[depth - 1, 1] = col
    return flag


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
    code: int = 0  # the reason's code: REASONS[code] == reason


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


def reason_name(code: int | str) -> str:
    """The name of an end-reason code (``REASONS[code]``; a name is returned as it is)."""
    if isinstance(code, str):
        return code
    return REASONS[int(code)]


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
    out: BatchOutcome | None = None,
) -> BatchOutcome:
    """Apply the reward table to one step of W worlds of N robots: per-robot arrays are
    ``(W, N)``, per-world ones ``(W,)`` (the fields of :class:`StepEvents`, batched; numpy
    arrays of integers or bools, as they come: converting them cost more than the table);
    ``moved`` (cells walked) is needed by the ``travel`` reward only. The outcome is written
    into ``out`` when given (arrays of those shapes), into fresh arrays otherwise."""
    constants, travel, padding_truncates, no_progress_limit, max_steps = table_constants(cfg)
    if travel and moved is None:
        raise ValueError("the travel reward needs the cells each robot walked")
    worlds, robots = new_cells.shape
    outcome = out or BatchOutcome(
        np.empty((worlds, robots)),
        np.empty(worlds, dtype=bool),
        np.empty(worlds, dtype=bool),
        np.empty(worlds, dtype=np.int64),
    )
    reward_table(
        constants,
        travel,
        padding_truncates,
        no_progress_limit,
        max_steps,
        new_cells,
        padding,
        oscillation,
        threshold_reached,
        no_frontier_left,
        steps_taken,
        steps_without_progress,
        new_cells if moved is None else moved,  # read by the travel reward only
        outcome.rewards,
        outcome.terminated,
        outcome.truncated,
        outcome.reason,
    )
    return outcome


#: The reward table's constants by config, found by identity (hashing a config costs more
#: than the table): ``id(cfg) -> (cfg, constants)``, the config kept so its id stays its own.
_CONSTANTS: dict[int, tuple[RewardConfig, tuple[np.ndarray, bool, bool, int, int]]] = {}


def table_constants(cfg: RewardConfig) -> tuple[np.ndarray, bool, bool, int, int]:
    """The reward table's constants, in :func:`reward_table`'s order: the float array, the
    travel and padding-truncation switches, the no-progress and step limits."""
    cached = _CONSTANTS.get(id(cfg))
    if cached is not None and cached[0] is cfg:
        return cached[1]
    if len(_CONSTANTS) >= 64:
        _CONSTANTS.clear()
    switches = (cfg.kind == "travel", cfg.padding_truncates)
    limits = (cfg.no_progress_limit, cfg.max_steps)
    _CONSTANTS[id(cfg)] = (cfg, (_table_constants(cfg), *switches, *limits))
    return _CONSTANTS[id(cfg)][1]


def _table_constants(cfg: RewardConfig) -> np.ndarray:
    travel = cfg.kind == "travel"
    constants = np.array(
        [
            cfg.team_weight,
            cfg.cell_reward,
            cfg.travel_cost if travel else cfg.no_new_cell_penalty,
            cfg.padding,
            cfg.oscillation_penalty if cfg.kind == "reward2" else 0.0,
            cfg.goal_bonus,
            cfg.no_progress_penalty,
            cfg.step_limit_penalty,
        ]
    )
    constants.setflags(write=False)
    return constants


@compiled
def reward_table(
    constants: np.ndarray,
    travel: bool,
    padding_truncates: bool,
    no_progress_limit: int,
    max_steps: int,
    new_cells: np.ndarray,
    padding: np.ndarray,
    oscillation: np.ndarray,
    threshold: np.ndarray,
    no_frontier: np.ndarray,
    steps: np.ndarray,
    without_progress: np.ndarray,
    moved: np.ndarray,
    rewards: np.ndarray,
    terminated: np.ndarray,
    truncated: np.ndarray,
    reason: np.ndarray,
) -> None:
    """The reward table, term by term in a fixed order (the same sums to the last bit for one
    world or many): cells, then no-new-cell or travel, padding, oscillation, then the episode
    terms. ``constants``: team weight, cell reward, no-new-cell penalty or travel cost,
    padding, oscillation, goal bonus, no-progress and step-limit penalties."""
    weight, cell, per_step, pad, osc, goal, stall, limit = constants
    for w in range(new_cells.shape[0]):
        team = 0
        for n in range(new_cells.shape[1]):
            team += new_cells[w, n]
        any_padding = False
        for n in range(new_cells.shape[1]):
            new = new_cells[w, n]
            credited = (1.0 - weight) * new + weight * team if weight != 0.0 else float(new)
            value = cell * credited
            if travel:
                value += per_step * max(moved[w, n], 1)
            elif new == 0:
                value += per_step
            if padding[w, n]:
                value += pad
                any_padding = True
            if oscillation[w, n]:
                value += osc
            rewards[w, n] = value
        code = 0
        if threshold[w]:
            code = THRESHOLD
            for n in range(new_cells.shape[1]):
                rewards[w, n] += goal
        elif no_frontier[w]:
            code = NO_FRONTIER
        else:
            if padding_truncates and any_padding:
                code |= PADDING
            if without_progress[w] >= no_progress_limit:
                code |= NO_PROGRESS
                for n in range(new_cells.shape[1]):
                    rewards[w, n] += stall
            if steps[w] >= max_steps:
                code |= STEP_LIMIT
                for n in range(new_cells.shape[1]):
                    rewards[w, n] += limit
        reason[w] = code
        terminated[w] = code == THRESHOLD or code == NO_FRONTIER  # noqa: SIM109 (numba)
        truncated[w] = code != 0 and not terminated[w]


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
    return first_outcome(outcome)


def first_outcome(outcome: BatchOutcome) -> StepOutcome:
    """World 0 of a batch's outcome, as one world's :class:`StepOutcome`."""
    code = int(outcome.reason[0])
    ended = bool(outcome.terminated[0]), bool(outcome.truncated[0])
    return StepOutcome(outcome.rewards[0], *ended, REASONS[code], code)
