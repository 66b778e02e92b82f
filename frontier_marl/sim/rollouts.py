"""Roll many worlds of a batch out at once, each with its own target, to its own end.

:func:`rollout_costs` finishes every world of a :class:`~frontier_marl.core.worlds.Worlds`
batch (typically the K clones of one world made by :func:`frontier_marl.sim.branching.branch`,
each sent to its own first target) with a base policy of one robot, until ``coverage`` of the
reachable free region is known or ``max_cells`` are walked, and returns the cells each walked.
The base policy keeps a target while it is still a frontier cell and not reached, then picks
the next one: by default the nearest cluster by known-free path (ties: nearest centroid,
:class:`NearestPathBase`); any :class:`RolloutBase` can take its place.

With :class:`NearestPathBase` the whole rollout of every world is one compiled call
(:func:`rollout_nearest_path`; its decisions in :mod:`frontier_marl.sim.nearest_path`). Any
other base runs in *decision rounds*: one compiled call walks every world, cell after cell,
until it needs a decision or ends; the deciding worlds' frontiers are labelled by one
``scipy.ndimage.label`` call and the base gives all of them their next targets. Either way the
worlds are independent, so each sees exactly the checks, decisions and moves it would see
alone; the region's known cells are counted only when an upper bound says the coverage level
may be reached.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontier_union import update_frontier
from frontier_marl.core.frontiers import is_frontier
from frontier_marl.core.movement import walk
from frontier_marl.core.slots import SlotArrays
from frontier_marl.core.world_kernels import basis_code, count_cells
from frontier_marl.core.worlds import Worlds
from frontier_marl.sim.nearest_path import (
    DecisionScratch,
    nearest_path,
    nearest_path_goal,
    start_frontier,
)

ROLLOUT_SLOTS = 256  # the base policy sees every reachable cluster, as the heuristics do
_REACHABLE = basis_code("reachable")


class RolloutBase(Protocol):
    """A base policy for the rollouts: ``n_slots`` slots per decision, the ``gain`` model of
    the simulations, and :meth:`goals`: the next targets ``(len(deciding), 2)`` (row -1:
    none) of robot 0 of the ``deciding`` worlds, from their slots."""

    n_slots: int
    gain: str

    def goals(self, sims: Worlds, slots: SlotArrays, deciding: np.ndarray) -> np.ndarray: ...


class NearestPathBase:
    """The rollouts' default base policy: robot 0's nearest live slot target by known-free
    path (ties: nearest centroid, then the lower slot), among every reachable cluster."""

    n_slots = ROLLOUT_SLOTS
    gain = "size"  # reads no gain: the cheapest gain model, no unknown cells counted

    def goals(self, sims: Worlds, slots: SlotArrays, deciding: np.ndarray) -> np.ndarray:
        """(len(deciding), 2) next targets of the ``deciding`` worlds (row -1: none)."""
        goals = np.full((len(deciding), 2), -1, dtype=np.int64)
        for k, world in enumerate(deciding.tolist()):
            goals[k] = nearest_path(
                slots.valid[world, 0],
                slots.target[world, 0],
                slots.distance[world, 0],
                slots.path_length[world, 0],
            )
        return goals


def rollout_costs(
    sims: Worlds,
    start: int,
    coverage: float,
    max_cells: int,
    base: RolloutBase,
    prune: bool = False,
) -> np.ndarray:
    """Cells robot 0 of each world of ``sims`` walks beyond ``start`` until ``coverage`` of its
    reachable free region is known, heading first for its current goal (``sims.goals``) and
    then where ``base`` sends it; a world that walks ``max_cells`` or has nothing reachable
    left to explore before that costs ``max_cells``.

    ``prune``: only the cheapest worlds matter (branch and bound). A world is stopped as soon
    as it has walked more than the cheapest one finished so far, and then costs ``max_cells``:
    every world of the least cost keeps its exact cost, the others only read as dearer."""
    n = sims.n_worlds
    state = _RolloutState(sims, max_cells)
    if isinstance(base, NearestPathBase):  # the whole rollout in one compiled call
        _rollout_nearest_path(sims, state, start, coverage, max_cells, base.n_slots, prune)
        return state.cost
    slots = SlotArrays.empty(n, 1, base.n_slots)
    while True:
        _advance(sims, state, start, coverage, _cap(state, max_cells) if prune else max_cells)
        deciding = np.flatnonzero(state.deciding)
        if len(deciding) == 0:
            return state.cost
        sims.slots(slots, deciding, False)
        goals = base.goals(sims, slots, deciding)
        stuck = goals[:, 0] < 0  # nothing reachable is left to explore: it cannot finish
        state.done[deciding[stuck]] = True
        sims.goals[deciding[~stuck], 0] = goals[~stuck]
        state.pending[deciding[~stuck]] = True


class _RolloutState:
    """Per world: ended, has a new target to walk toward first, its cost, an upper bound on
    its known cells of the region (``known``; ``exact`` when it is the count itself), and the
    box of the cells its robots sensed from since it was last cleared (``sensed``: first row,
    last row, first column, last column; empty while the first row is above the last). The
    bound grows by the cells each walk reveals, and the belief is counted only when the bound
    reaches the coverage level."""

    def __init__(self, sims: Worlds, max_cells: int) -> None:
        n = sims.n_worlds
        self.done = np.zeros(n, dtype=bool)
        self.pending = np.zeros(n, dtype=bool)
        self.cost = np.full(n, max_cells, dtype=np.int64)
        self.known = sims.start_region_size.copy()  # the region itself: a bound that holds
        self.exact = np.zeros(n, dtype=bool)
        self.deciding = np.zeros(n, dtype=bool)  # the worlds :func:`advance` left deciding
        self.sensed = np.zeros((n, 4), dtype=np.int64)
        self.sensed[:, 0] = 1  # empty

    def arrays(self) -> tuple[np.ndarray, ...]:
        """The per-world arrays :func:`advance_world` reads and writes, in its order."""
        return self.done, self.pending, self.cost, self.known, self.exact, self.sensed


def _advance(sims: Worlds, state: _RolloutState, start: int, coverage: float, cap: int) -> None:
    advance(state.arrays(), sims.walk_arrays(), start, coverage, cap, state.deciding)


def _cap(state: _RolloutState, max_cells: int) -> int:
    """The walk at which a world can no longer be among the cheapest: one cell more than the
    cheapest finished world (``max_cells`` while none has)."""
    return min(max_cells, int(state.cost.min(initial=max_cells)) + 1)


def _rollout_nearest_path(
    sims: Worlds,
    state: _RolloutState,
    start: int,
    coverage: float,
    cap: int,
    n_slots: int,
    prune: bool,
) -> None:
    params = sims.params
    scratch = DecisionScratch(sims.shape)
    reach = int(np.abs(params.sensor.rays[0]).max(initial=0))  # a sensed cell's farthest change
    rollout_nearest_path(
        state.arrays(), sims.walk_arrays(), start, coverage, cap, params.connectivity,
        params.max_cluster_cells, n_slots, reach, scratch.arrays(), prune,
    )  # fmt: skip


@compiled
def advance(
    state: tuple, world: tuple, start: int, coverage: float, max_cells: int, deciding: np.ndarray
) -> None:
    """:func:`advance_world` for every live world (``deciding``: it needs a decision)."""
    done = state[0]
    for n in range(len(done)):
        deciding[n] = False
        if not done[n]:
            deciding[n] = advance_world(n, state, world, start, coverage, max_cells)


@compiled
def advance_world(
    n: int, state: tuple, world: tuple, start: int, coverage: float, max_cells: int
) -> bool:
    """Walk live world ``n`` (a ``pending`` one first toward its new goal) until it ends
    (coverage reached: ``cost`` is its walk; ``max_cells`` walked; ``done`` set) or its goal is
    no longer a frontier cell or is reached (returns True: it needs a decision). ``state``:
    :meth:`_RolloutState.arrays`; ``world``: :meth:`Worlds.walk_arrays`."""
    done, pending, cost, known, exact, sensed = state
    (
        region, region_size, true, belief, seen, positions, travelled, goals, plan_cells,
        plan_meta, version, cells_per_step, offsets, between, new_cells, walked, walked_len,
        reached, search,
    ) = world  # fmt: skip
    moving = pending[n]
    pending[n] = False
    while True:
        if moving:
            version[n] = walk(
                true[n], belief[n], seen[n], positions[n], travelled[n], goals[n],
                plan_cells[n], plan_meta[n], version[n], cells_per_step, offsets, between,
                new_cells[n], walked[n], walked_len[n], reached[n], search,
            )  # fmt: skip
            revealed = new_cells[n].sum()
            if revealed:
                known[n] += revealed
                exact[n] = False
                _add_sensed(sensed[n], walked[n], walked_len[n])
        moving = True
        size = max(region_size[n], 1)
        if not exact[n] and known[n] / size >= coverage:  # the bound says maybe: count
            known[n] = count_cells(_REACHABLE, belief[n], region[n])
            exact[n] = True
        covered = known[n] / size >= coverage
        walked_cells = travelled[n, 0] - start
        if covered or walked_cells >= max_cells:
            done[n] = True
            if covered:
                cost[n] = walked_cells
            return False
        row, col = goals[n, 0, 0], goals[n, 0, 1]
        if row < 0 or not is_frontier(belief[n], row, col) or reached[n, 0]:
            return True


@compiled
def rollout_nearest_path(
    state: tuple,
    world: tuple,
    start: int,
    coverage: float,
    max_cells: int,
    connectivity: int,
    max_cluster_cells: int,
    n_slots: int,
    reach: int,
    scratch: tuple,
    prune: bool,
) -> None:
    """Every world rolled out to its end with :class:`NearestPathBase` deciding, world after
    world (the worlds are independent); ``scratch``: :meth:`DecisionScratch.arrays`. The
    frontier mask is made once per world, then brought up to date before each decision
    within ``reach`` + 1 cells of where the robots sensed (``reach``: the sensor's farthest
    offset). ``prune``: each world stops once it has walked more than the cheapest one before
    it (:func:`rollout_costs`)."""
    done, pending, cost, sensed = state[0], state[1], state[2], state[5]
    belief, positions, goals = world[3], world[5], world[7]
    frontier, row_count = scratch[6], scratch[7]
    margin = reach + 1
    cap = max_cells
    for n in range(len(done)):
        start_frontier(belief[n], scratch)
        sensed[n, 0], sensed[n, 1] = 1, 0
        while not done[n]:
            if not advance_world(n, state, world, start, coverage, cap):
                continue
            box = sensed[n]
            if box[0] <= box[1]:
                update_frontier(
                    belief[n], frontier, row_count, box[0] - margin, box[1] + margin + 1,
                    box[2] - margin, box[3] + margin + 1,
                )  # fmt: skip
                box[0], box[1] = 1, 0
            goal = nearest_path_goal(
                belief[n], positions[n, 0, 0], positions[n, 0, 1], connectivity,
                max_cluster_cells, n_slots, scratch,
            )  # fmt: skip
            if goal[0] < 0:  # nothing reachable is left to explore: it cannot finish
                done[n] = True
            else:
                goals[n, 0, 0] = goal[0]
                goals[n, 0, 1] = goal[1]
                pending[n] = True
        if prune:
            cap = min(cap, cost[n] + 1)


@compiled
def _add_sensed(box: np.ndarray, walked: np.ndarray, walked_len: np.ndarray) -> None:
    """Grow the box (first row, last row, first column, last column; empty while the first
    row is above the last) over the cells each robot entered in a walk (``walked[a, 1:]``)."""
    for a in range(len(walked_len)):
        for i in range(1, walked_len[a]):
            r, c = walked[a, i, 0], walked[a, i, 1]
            if box[0] > box[1]:
                box[0], box[1], box[2], box[3] = r, r, c, c
            else:
                box[0], box[1] = min(box[0], r), max(box[1], r)
                box[2], box[3] = min(box[2], c), max(box[3], c)
