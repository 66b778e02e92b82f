"""A privileged reference: one-step lookahead on the true map, finished by nearest-path.

For each candidate target of one robot, :func:`lookahead_costs` copies the robot's world into a
batch of simulations (one per candidate), walks the robot to that target, then lets
nearest-path finish the map, and returns the cells each simulation travelled until the coverage
level. The simulations sense the true map, so they know what the robot does not: which
frontier will be cleared on the way, which room is a dead end. Choosing the cheapest candidate
is a rollout policy on nearest-path (Bertsekas's rollout: one step of policy improvement).
:class:`LookaheadOracle` is that choice as a benchmark contender
(``lookahead-oracle``): it reads the true map, so it is a bound on what choosing among the same
clusters can gain, not a heuristic; :mod:`frontier_marl.training.imitation` labels decisions
with its costs for a student that sees only its own observation.

The base policy of the simulations keeps a target while it is still a frontier cell and then
picks the next one: by default the nearest cluster by known-free path (ties: nearest
centroid, :class:`NearestPathBase`), one cell per move; any :class:`RolloutBase` can take its
place (:mod:`frontier_marl.experiments.explorer_studies.rollout_probe` finishes the
simulations with the explorer).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Protocol

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontiers import is_frontier
from frontier_marl.core.slots import SlotArrays
from frontier_marl.core.worlds import Worlds
from frontier_marl.policies.base import HeuristicPolicy, Info, first_by, slot_table

_COPIED = (
    "true", "belief", "positions", "seen", "travelled", "start_region", "start_region_size",
    "true_free",
)  # fmt: skip
ROLLOUT_SLOTS = 256  # the base policy sees every reachable cluster, as the heuristics do


def copy_world(source: Worlds, index: int, target: Worlds, rows: np.ndarray) -> None:
    """World ``index`` of ``source`` into worlds ``rows`` of ``target`` (same shape, robots and
    parameters); their plans and targets are cleared."""
    for name in _COPIED:
        getattr(target, name)[rows] = getattr(source, name)[index]
    target.plan_meta[rows] = -1
    target.goals[rows] = -1
    target.version[rows] += 1


@compiled
def _still_frontier(belief: np.ndarray, goals: np.ndarray, worlds: np.ndarray) -> np.ndarray:
    """Per listed world: robot 0's goal is still a frontier cell."""
    out = np.zeros(len(worlds), dtype=np.bool_)
    for m in range(len(worlds)):
        n = worlds[m]
        r, c = goals[n, 0, 0], goals[n, 0, 1]
        out[m] = r >= 0 and is_frontier(belief[n], r, c)
    return out


class NearestPathBase:
    """The rollouts' default base policy: robot 0's nearest live slot target by known-free
    path (ties: nearest centroid), among every reachable cluster."""

    n_slots = ROLLOUT_SLOTS
    gain = "size"  # reads no gain: the cheapest gain model, no unknown cells counted

    def goals(self, sims: Worlds, slots: SlotArrays, deciding: np.ndarray) -> np.ndarray:
        """(len(deciding), 2) next targets of the ``deciding`` simulations (row -1: none)."""
        goals = np.full((len(deciding), 2), -1, dtype=np.int64)
        for k, world in enumerate(deciding.tolist()):
            live = np.flatnonzero(slots.valid[world, 0])
            if len(live):
                best = first_by(slots.path_length[world, 0, live], slots.distance[world, 0, live])
                goals[k] = slots.target[world, 0, live[best]]
        return goals


class RolloutBase(Protocol):
    """A base policy for the rollouts: ``n_slots`` slots per decision, the ``gain`` model of
    the simulations, and :meth:`goals`, as :class:`NearestPathBase`."""

    n_slots: int
    gain: str

    def goals(self, sims: Worlds, slots: SlotArrays, deciding: np.ndarray) -> np.ndarray: ...


def lookahead_costs(
    source: Worlds,
    index: int,
    targets: np.ndarray,
    coverage: float,
    max_cells: int,
    base: RolloutBase | None = None,
) -> np.ndarray:
    """Cells travelled by robot 0 of world ``index`` until ``coverage`` of the reachable free
    region is known, if it first walks to ``targets[m]`` (M, 2) and ``base`` (default:
    :class:`NearestPathBase`) finishes; ``max_cells`` caps each simulation (a simulation that
    stalls costs ``max_cells``)."""
    if source.n_agents != 1:
        raise ValueError(f"the lookahead teacher drives one robot, got {source.n_agents}")
    targets = np.asarray(targets, dtype=np.int64).reshape(-1, 2)
    count = len(targets)
    base = NearestPathBase() if base is None else base
    sims = Worlds(source.shape, count, 1, replace(source.params, gain=base.gain))
    copy_world(source, index, sims, np.arange(count))
    start = int(source.travelled[index, 0])
    sims.goals[:, 0] = targets
    slots = SlotArrays.empty(count, 1, base.n_slots)
    done = np.zeros(count, dtype=bool)
    cost = np.full(count, max_cells, dtype=np.int64)
    while True:
        covered = sims.explored_fraction("reachable") >= coverage
        walked = sims.travelled[:, 0] - start
        finished = ~done & (covered | (walked >= max_cells))
        cost[finished & covered] = walked[finished & covered]
        done |= finished
        if done.all():
            return cost
        active = np.flatnonzero(~done)
        keep = _still_frontier(sims.belief, sims.goals, active) & ~sims.reached[active, 0]
        deciding = active[~keep]
        if len(deciding):
            sims.slots(slots, deciding, False)
            goals = base.goals(sims, slots, deciding)
            stuck = goals[:, 0] < 0  # nothing reachable is left to explore: it cannot finish
            done[deciding[stuck]] = True
            sims.goals[deciding[~stuck], 0] = goals[~stuck]
        sims.move(sims.goals, ~done)  # resets ``reached`` of every world it moves


class LookaheadOracle(HeuristicPolicy):
    """The cheapest live slot by :func:`lookahead_costs` with rollout ``base`` (default
    nearest-path; ties: nearest path, then nearest centroid), kept until reached (``commit =
    "until-reached"``). One robot only; it reads the attached env's world, true map included,
    and its coverage level (``explore_threshold`` of the reachable free cells)."""

    name = "lookahead-oracle"

    def __init__(self, base: RolloutBase | None = None) -> None:
        super().__init__("until-reached")
        self.base = base
        self._env: Any = None

    def attach(self, env: Any) -> None:
        agents = len(getattr(env, "possible_agents", ["robot_0"]))
        if agents != 1:
            raise ValueError(f"lookahead-oracle drives one robot, the env has {agents}")
        self._env = env

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if table.live <= 1:
            return 0
        if self._env is None:
            raise RuntimeError("lookahead-oracle needs attach(env) before it acts")
        world = self._env.world
        height, width = world.shape
        live = table.live
        coverage = self._env.config.reward.explore_threshold
        costs = lookahead_costs(
            world.batch, world.index, table.target[:live], coverage, 4 * height * width, self.base
        )
        return first_by(costs, table.path_length[:live], table.distance[:live])
