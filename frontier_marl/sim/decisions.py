"""Actions to targets: the one compiled call that turns slot choices into the cells the robots
head for, with the padding flags and the oscillation test, for a batch of worlds."""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.sim.rewards import oscillation_step


@compiled
def decide(
    live: np.ndarray,
    target: np.ndarray,
    actions: np.ndarray,
    active: np.ndarray,
    history: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(targets, padding, oscillation)`` of W worlds of N robots: ``live`` (W, N) and
    ``target`` (W, N, S, 2) are the slot tables' live counts and targets, ``actions`` (W, N)
    the chosen slots (valid indices), ``active`` (W,) the worlds that step and ``history`` the
    :class:`~frontier_marl.sim.rewards.OscillationHistory` array, updated for those worlds.
    A robot whose slot is live heads for its target; otherwise (a padding slot) it idles (row
    -1), flagged ``padding`` when a live slot existed. Inactive worlds: rows -1, no flags."""
    worlds, robots = actions.shape
    targets = np.full((worlds, robots, 2), -1, dtype=np.int64)
    padding = np.zeros((worlds, robots), dtype=np.bool_)
    oscillation = np.zeros((worlds, robots), dtype=np.bool_)
    for w in range(worlds):
        if not active[w]:
            continue
        for n in range(robots):
            slot = actions[w, n]
            if slot < live[w, n]:  # live slots come first
                targets[w, n, 0] = target[w, n, slot, 0]
                targets[w, n, 1] = target[w, n, slot, 1]
            else:
                padding[w, n] = live[w, n] > 0
            oscillation[w, n] = oscillation_step(history[w, n], targets[w, n, 0], targets[w, n, 1])
    return targets, padding, oscillation


@compiled
def heading_of(targets: np.ndarray, reached: np.ndarray) -> np.ndarray:
    """(W, N, 2) the cells the robots head to after a step: their ``targets`` (W, N, 2) where
    they have one and have not ``reached`` it (W, N), row -1 elsewhere."""
    heading = np.full(targets.shape, -1, dtype=np.int64)
    for w in range(targets.shape[0]):
        for n in range(targets.shape[1]):
            if targets[w, n, 0] >= 0 and not reached[w, n]:
                heading[w, n, 0] = targets[w, n, 0]
                heading[w, n, 1] = targets[w, n, 1]
    return heading
