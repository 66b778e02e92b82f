"""The engine's compiled calls around the walk, for a batch of worlds: actions to targets (with
the padding flags and the oscillation test), the step counters, and the end of a step (the
reward table, the episode ends, where each robot still heads). Outputs are passed in: numba
boxes returned arrays slowly."""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.sim.rewards import oscillation_step, reward_table


@compiled
def decide(
    live: np.ndarray,
    target: np.ndarray,
    actions: np.ndarray,
    active: np.ndarray,
    history: np.ndarray,
    targets: np.ndarray,
    padding: np.ndarray,
    oscillation: np.ndarray,
) -> None:
    """``targets`` (W, N, 2), ``padding`` and ``oscillation`` (W, N) of W worlds of N robots:
    ``live`` (W, N) and ``target`` (W, N, S, 2) are the slot tables' live counts and targets,
    ``actions`` (W, N) the chosen slots (valid indices), ``active`` (W,) the worlds that step
    and ``history`` the :class:`~frontier_marl.sim.rewards.OscillationHistory` array, updated
    for those worlds. A robot whose slot is live heads for its target; otherwise (a padding
    slot) it idles (row -1), flagged ``padding`` when a live slot existed. Inactive worlds:
    rows -1, no flags."""
    targets[:] = -1
    padding[:] = False
    oscillation[:] = False
    for w in range(actions.shape[0]):
        if not active[w]:
            continue
        for n in range(actions.shape[1]):
            slot = actions[w, n]
            if slot < live[w, n]:  # live slots come first
                targets[w, n, 0] = target[w, n, slot, 0]
                targets[w, n, 1] = target[w, n, slot, 1]
            else:
                padding[w, n] = live[w, n] > 0
            oscillation[w, n] = oscillation_step(history[w, n], targets[w, n, 0], targets[w, n, 1])


@compiled
def heading_of(targets: np.ndarray, reached: np.ndarray, heading: np.ndarray) -> None:
    """``heading`` (W, N, 2): the cells the robots head to after a step, their ``targets``
    (W, N, 2) where they have one and have not ``reached`` it (W, N), row -1 elsewhere."""
    for w in range(targets.shape[0]):
        for n in range(targets.shape[1]):
            going = targets[w, n, 0] >= 0 and not reached[w, n]
            heading[w, n, 0] = targets[w, n, 0] if going else -1
            heading[w, n, 1] = targets[w, n, 1] if going else -1


@compiled
def count_progress(
    active: np.ndarray,
    walked_cells: np.ndarray,
    new_cells: np.ndarray,
    steps: np.ndarray,
    without_progress: np.ndarray,
) -> None:
    """After a walk of the ``active`` worlds (W,): ``new_cells`` (W, N) the cells each robot
    revealed (``walked_cells``; 0 in inactive worlds), and the active worlds' step counters
    ``steps`` and ``without_progress`` (W,) advanced (the latter back to 0 when any cell was
    revealed)."""
    for w in range(len(active)):
        progress = False
        for n in range(new_cells.shape[1]):
            new_cells[w, n] = walked_cells[w, n] if active[w] else 0
            progress = progress or new_cells[w, n] > 0
        if active[w]:
            steps[w] += 1
            without_progress[w] = 0 if progress else without_progress[w] + 1


@compiled
def world_events(
    fraction: np.ndarray,
    threshold: float,
    live: np.ndarray,
    threshold_reached: np.ndarray,
    no_frontier_left: np.ndarray,
) -> None:
    """The reward table's per-world events of W worlds after a step: ``threshold_reached``
    (W,) where the explored ``fraction`` (W,) is at least ``threshold``, ``no_frontier_left``
    where no robot has a live slot (``live`` (W, N))."""
    for w in range(len(fraction)):
        threshold_reached[w] = fraction[w] >= threshold
        left = False
        for n in range(live.shape[1]):
            left = left or live[w, n] > 0
        no_frontier_left[w] = not left


@compiled
def settle(
    active: np.ndarray,
    targets: np.ndarray,
    reached: np.ndarray,
    padding: np.ndarray,
    oscillation: np.ndarray,
    rewards: np.ndarray,
    terminated: np.ndarray,
    truncated: np.ndarray,
    reason: np.ndarray,
    done: np.ndarray,
    kept_targets: np.ndarray,
    kept_heading: np.ndarray,
    kept_padding: np.ndarray,
    kept_oscillation: np.ndarray,
) -> None:
    """The end of a step of the ``active`` worlds (W,): inactive worlds get no reward, end
    or reason, and keep their ``kept_*`` arrays (targets and heading (W, N, 2), flags (W, N));
    active ones store the step's ``targets``, ``padding`` and ``oscillation``, their heading
    (:func:`heading_of` with ``reached``), and are ``done`` once terminated or truncated."""
    for w in range(len(active)):
        if not active[w]:
            rewards[w] = 0.0
            terminated[w] = False
            truncated[w] = False
            reason[w] = 0
            continue
        done[w] = done[w] or terminated[w] or truncated[w]
        heading_of(targets[w : w + 1], reached[w : w + 1], kept_heading[w : w + 1])
        kept_targets[w] = targets[w]
        kept_padding[w] = padding[w]
        kept_oscillation[w] = oscillation[w]


@compiled
def finish_step(
    constants: np.ndarray,
    travel: bool,
    padding_truncates: bool,
    no_progress_limit: int,
    max_steps: int,
    fraction: np.ndarray,
    explore_threshold: float,
    live: np.ndarray,
    new_cells: np.ndarray,
    steps: np.ndarray,
    without_progress: np.ndarray,
    moved: np.ndarray,
    active: np.ndarray,
    targets: np.ndarray,
    reached: np.ndarray,
    padding: np.ndarray,
    oscillation: np.ndarray,
    outcome: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    done: np.ndarray,
    kept: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> None:
    """The end of a step in one compiled call: :func:`world_events`, the
    reward table (:func:`~frontier_marl.sim.rewards.reward_table`, its first five arguments
    from :func:`~frontier_marl.sim.rewards.table_constants`) into ``outcome`` (rewards,
    terminated, truncated, reason), then :func:`settle` with ``kept`` (targets, heading,
    padding, oscillation)."""
    threshold_reached = np.empty(len(fraction), dtype=np.bool_)
    no_frontier_left = np.empty(len(fraction), dtype=np.bool_)
    rewards, terminated, truncated, reason = outcome
    world_events(fraction, explore_threshold, live, threshold_reached, no_frontier_left)
    reward_table(
        constants, travel, padding_truncates, no_progress_limit, max_steps, new_cells, padding,
        oscillation, threshold_reached, no_frontier_left, steps, without_progress, moved,
        rewards, terminated, truncated, reason,
    )  # fmt: skip
    settle(
        active, targets, reached, padding, oscillation, rewards, terminated, truncated, reason,
        done, *kept,
    )  # fmt: skip
