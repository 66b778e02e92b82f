"""Single-robot heuristics: each robot picks a slot from its own step info.

The heuristics read only a robot's step info: its typed slot table ``info["slots"]`` (cluster,
target, Euclidean centroid ``distance``, known-free ``path_length``, size and ``gain`` per
slot; see :class:`~frontier_marl.core.slots.SlotTable`) and ``action_mask``, never hidden env
state:

* ``greedy-distance``: the nearest cluster (smallest Euclidean centroid ``distance``; ties:
  lowest slot).
* ``greedy-gain``: the largest information ``gain`` (ties: nearest, then lowest slot).
* ``nearest-path``: the nearest cluster by known-free path (Yamauchi 1997's nearest frontier):
  the smallest ``path_length``, the 4-connected shortest path from the robot to the cluster's
  target through known-free cells (what A* walks), not the Euclidean distance to the
  centroid. Ties: nearest centroid, then lowest slot.
* ``cost-utility``: the largest ``gain / path length``, the path length being the 4-connected
  shortest path (what A* returns) from the robot to the cluster's target over the known-free
  cells of the belief (a length of 0 counts as 1). Ties: nearest, then lowest slot.
* ``random``: uniform over the valid slots of ``action_mask``, from its own seeded generator.
* ``first-slot``: always slot 0, the thesis's degenerate policy as a baseline (greedy distance
  when slots are sorted; the top-most of the selected clusters when unsorted).

Every heuristic but ``random`` takes ``commit`` (:class:`~frontier_marl.policies.base.
HeuristicPolicy`): ``none`` re-decides at every step; ``until-progress`` keeps the previous
target while the last step revealed nothing; ``on-cycle`` re-decides every step until the robot
stands again on a cell without having seen anything new since it stood there, then keeps its
target until it sees something (the thesis protocol's greedy distance,
:data:`frontier_marl.experiments.baselines.THESIS_PROTOCOL`).
"""

from __future__ import annotations

import numpy as np

from frontier_marl.core.slots import SlotTable
from frontier_marl.policies.base import HeuristicPolicy, Info, first_by, slot_table


class GreedyDistance(HeuristicPolicy):
    """Nearest cluster: smallest centroid distance; ties go to the lowest slot."""

    name = "greedy-distance"

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if not table.live:
            return 0
        return int(np.argmin(table.distance[: table.live]))


class GreedyGain(HeuristicPolicy):
    """Largest information gain; ties go to the nearest, then the lowest slot."""

    name = "greedy-gain"

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if not table.live:
            return 0
        live = table.live
        return first_by(-table.gain[:live], table.distance[:live])


class FirstSlot(HeuristicPolicy):
    """Always slot 0, the thesis's degenerate "reward hacking" policy as a baseline.

    With distance-sorted slots this is greedy distance; unsorted (the default), slot 0 is the
    first of the selected clusters in raster order, i.e. the top-most of the nearest ones.
    """

    name = "first-slot"

    def choose(self, info: Info) -> int:
        return 0


class NearestPath(HeuristicPolicy):
    """Nearest cluster by known-free path length (Yamauchi's nearest frontier); ties go to the
    nearest centroid, then the lowest slot."""

    name = "nearest-path"

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if not table.live:
            return 0
        live = table.live
        return first_by(table.path_length[:live], table.distance[:live])


class CostUtility(HeuristicPolicy):
    """Largest ``gain / path length`` (known-free path; a length of 0 counts as 1); ties go to
    the nearest, then the lowest slot."""

    name = "cost-utility"

    @staticmethod
    def utilities(table: SlotTable) -> np.ndarray:
        """``gain / max(path length, 1)`` of each live slot."""
        live = table.live
        return table.gain[:live] / np.maximum(table.path_length[:live], 1)

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if not table.live:
            return 0
        return first_by(-self.utilities(table), table.distance[: table.live])


class RandomValid(HeuristicPolicy):
    """Uniform over the valid slots of ``action_mask`` (slot 0 when none is valid).

    One generator serves every robot (drawn in agent order); :meth:`reset` reseeds it.
    """

    name = "random"
    deterministic = False

    def __init__(self, seed: int | None = None) -> None:
        super().__init__()
        self._rng = np.random.default_rng(seed)

    def reset(self, seed: int | None = None) -> None:
        if seed is not None:
            self._rng = np.random.default_rng(seed)

    def choose(self, info: Info) -> int:
        valid = np.flatnonzero(np.asarray(info["action_mask"]))
        if len(valid) == 0:
            return 0
        return int(valid[self._rng.integers(len(valid))])
