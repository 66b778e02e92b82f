"""The robots' recent motion, for the explorer layout's ``turn`` feature.

A :class:`MotionTrail` keeps, per world and robot, the cells it stood on before each of its last
:data:`TRAIL_STEPS` steps (the start cell until it has taken that many); the motion is the
current cell minus the oldest of them.
"""

from __future__ import annotations

import numpy as np

TRAIL_STEPS = 3


class MotionTrail:
    """Positions before the last :data:`TRAIL_STEPS` steps of ``n_agents`` robots in each of
    ``n_worlds`` worlds."""

    def __init__(self, n_worlds: int, n_agents: int) -> None:
        self.cells = np.zeros((n_worlds, n_agents, TRAIL_STEPS, 2), dtype=np.int64)

    def clear(self, worlds: np.ndarray | slice, positions: np.ndarray) -> None:
        """Start ``worlds`` afresh with the robots at ``positions`` ((W, K, 2))."""
        self.cells[worlds] = positions[:, :, None, :]

    def push(self, positions: np.ndarray, active: np.ndarray) -> None:
        """Record ``positions`` (N, K, 2), taken before a step, in the ``active`` worlds."""
        shifted = np.concatenate([self.cells[:, :, 1:], positions[:, :, None, :]], axis=2)
        self.cells = np.where(active[:, None, None, None], shifted, self.cells)

    def motion(self, worlds: np.ndarray | slice, positions: np.ndarray) -> np.ndarray:
        """(W, K, 2) how far the robots of ``worlds``, now at ``positions``, moved over their
        last steps."""
        return positions - self.cells[worlds, :, 0]
