"""Roll many worlds of a batch out at once, each with its own target, to its own end.

:func:`rollout_costs` finishes every world of a :class:`~frontier_marl.core.worlds.Worlds`
batch (typically the K clones of one world made by :func:`frontier_marl.sim.branching.branch`,
each sent to its own first target) with a base policy of one robot, until ``coverage`` of the
reachable free region is known or ``max_cells`` are walked, and returns the cells each walked.
The base policy keeps a target while it is still a frontier cell and not reached, then picks
the next one: by default the nearest cluster by known-free path (ties: nearest centroid,
:class:`NearestPathBase`); any :class:`RolloutBase` can take its place.

The worlds run in *decision rounds*, not in lockstep: one compiled call walks every world, cell
after cell, until it needs a decision or ends; the frontier masks of all deciding worlds are
labelled by one ``scipy.ndimage.label`` call; one compiled call (nearest-path) or the base
policy (any other) gives all of them their next targets. The worlds are independent, so each
sees exactly the sequence of checks, decisions and moves it would see alone.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontiers import is_frontier
from frontier_marl.core.grid import UNKNOWN
from frontier_marl.core.movement import walk
from frontier_marl.core.slots import SlotArrays, _robot_slots
from frontier_marl.core.worlds import Worlds

ROLLOUT_SLOTS = 256  # the base policy sees every reachable cluster, as the heuristics do


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
            goals[k] = _nearest_path(
                slots.valid[world, 0],
                slots.target[world, 0],
                slots.distance[world, 0],
                slots.path_length[world, 0],
            )
        return goals

    def decide(self, sims: Worlds, deciding: np.ndarray) -> np.ndarray:
        """:meth:`goals` with the slots built and read in one compiled call."""
        sims.refresh_clusters()
        goals = np.empty((len(deciding), 2), dtype=np.int64)
        nearest_path_goals(
            deciding,
            sims.belief,
            sims.positions,
            sims.cell_rows,
            sims.cell_cols,
            sims.cell_cluster,
            sims.n_cells,
            sims.centroids,
            sims.sizes,
            sims.gains,
            sims.n_clusters,
            self.n_slots,
            goals,
        )
        return goals


def rollout_costs(
    sims: Worlds, start: int, coverage: float, max_cells: int, base: RolloutBase
) -> np.ndarray:
    """Cells robot 0 of each world of ``sims`` walks beyond ``start`` until ``coverage`` of its
    reachable free region is known, heading first for its current goal (``sims.goals``) and
    then where ``base`` sends it; a world that walks ``max_cells`` or has nothing reachable
    left to explore before that costs ``max_cells``."""
    n = sims.n_worlds
    state = _RolloutState(n, max_cells)
    nearest = base if isinstance(base, NearestPathBase) else None
    slots = SlotArrays.empty(n, 1, base.n_slots) if nearest is None else None
    while True:
        _advance(sims, state, start, coverage, max_cells)
        deciding = np.flatnonzero(state.deciding)
        if len(deciding) == 0:
            return state.cost
        if nearest is not None:
            goals = nearest.decide(sims, deciding)
        else:
            assert slots is not None
            sims.slots(slots, deciding, False)
            goals = base.goals(sims, slots, deciding)
        stuck = goals[:, 0] < 0  # nothing reachable is left to explore: it cannot finish
        state.done[deciding[stuck]] = True
        sims.goals[deciding[~stuck], 0] = goals[~stuck]
        state.pending[deciding[~stuck]] = True


class _RolloutState:
    """Per world: ended, has a new target to walk toward first, waits for a decision, its
    cost, and its count of known cells of the region (as of belief version ``known_version``)."""

    def __init__(self, n: int, max_cells: int) -> None:
        self.done = np.zeros(n, dtype=bool)
        self.pending = np.zeros(n, dtype=bool)
        self.deciding = np.zeros(n, dtype=bool)
        self.cost = np.full(n, max_cells, dtype=np.int64)
        self.known = np.zeros(n, dtype=np.int64)
        self.known_version = np.full(n, -1, dtype=np.int64)


def _advance(sims: Worlds, state: _RolloutState, start: int, coverage: float, cap: int) -> None:
    offsets, between = sims.params.sensor.rays
    advance(
        state.done,
        state.pending,
        state.deciding,
        state.cost,
        state.known,
        state.known_version,
        start,
        coverage,
        cap,
        sims.start_region,
        sims.start_region_size,
        sims.true,
        sims.belief,
        sims.seen,
        sims.positions,
        sims.travelled,
        sims.goals,
        sims.plan_cells,
        sims.plan_meta,
        sims.version,
        sims.params.cells_per_step,
        offsets,
        between,
        sims.new_cells,
        sims.walked,
        sims.walked_len,
        sims.reached,
    )


@compiled
def advance(
    done: np.ndarray,
    pending: np.ndarray,
    deciding: np.ndarray,
    cost: np.ndarray,
    known: np.ndarray,
    known_version: np.ndarray,
    start: int,
    coverage: float,
    max_cells: int,
    region: np.ndarray,
    region_size: np.ndarray,
    true: np.ndarray,
    belief: np.ndarray,
    seen: np.ndarray,
    positions: np.ndarray,
    travelled: np.ndarray,
    goals: np.ndarray,
    plan_cells: np.ndarray,
    plan_meta: np.ndarray,
    version: np.ndarray,
    cells_per_step: int,
    offsets: np.ndarray,
    between: np.ndarray,
    new_cells: np.ndarray,
    walked: np.ndarray,
    walked_len: np.ndarray,
    reached: np.ndarray,
) -> None:
    """Walk every live world (a ``pending`` one first toward its new goal) until it ends
    (coverage reached: ``cost`` is its walk; ``max_cells`` walked) or its goal is no longer a
    frontier cell or is reached (``deciding``)."""
    for n in range(len(done)):
        deciding[n] = False
        if done[n]:
            continue
        moving = pending[n]
        pending[n] = False
        while True:
            if moving:
                version[n] = walk(
                    true[n], belief[n], seen[n], positions[n], travelled[n], goals[n],
                    plan_cells[n], plan_meta[n], version[n], cells_per_step, offsets, between,
                    new_cells[n], walked[n], walked_len[n], reached[n],
                )  # fmt: skip
            moving = True
            if known_version[n] != version[n]:
                known[n] = _count_known(belief[n], region[n])
                known_version[n] = version[n]
            covered = known[n] / max(region_size[n], 1) >= coverage
            walked_cells = travelled[n, 0] - start
            if covered or walked_cells >= max_cells:
                done[n] = True
                if covered:
                    cost[n] = walked_cells
                break
            row, col = goals[n, 0, 0], goals[n, 0, 1]
            if row < 0 or not is_frontier(belief[n], row, col) or reached[n, 0]:
                deciding[n] = True
                break


@compiled
def _count_known(belief: np.ndarray, region: np.ndarray) -> int:
    count = 0
    for r in range(belief.shape[0]):
        for c in range(belief.shape[1]):
            if region[r, c] and belief[r, c] != UNKNOWN:
                count += 1
    return count


@compiled
def _nearest_path(
    valid: np.ndarray, target: np.ndarray, distance: np.ndarray, path_length: np.ndarray
) -> np.ndarray:
    """The target of the live slot of shortest path (ties: nearest centroid, lower slot);
    (-1, -1) if none is live."""
    best = -1
    for s in range(len(valid)):
        if not valid[s]:
            continue
        if (
            best < 0
            or path_length[s] < path_length[best]
            or (path_length[s] == path_length[best] and distance[s] < distance[best])
        ):
            best = s
    out = np.full(2, -1, dtype=np.int64)
    if best >= 0:
        out[0] = target[best, 0]
        out[1] = target[best, 1]
    return out


@compiled
def nearest_path_goals(
    deciding: np.ndarray,
    belief: np.ndarray,
    positions: np.ndarray,
    cell_rows: np.ndarray,
    cell_cols: np.ndarray,
    cell_cluster: np.ndarray,
    n_cells: np.ndarray,
    centroids: np.ndarray,
    sizes: np.ndarray,
    gains: np.ndarray,
    n_clusters: np.ndarray,
    n_slots: int,
    goals: np.ndarray,
) -> None:
    """:meth:`NearestPathBase.goals` of robot 0 of each ``deciding`` world, its slots (unsorted)
    built in place, into ``goals`` (len(deciding), 2)."""
    for m in range(len(deciding)):
        n = deciding[m]
        cells, count = n_cells[n], n_clusters[n]
        result = _robot_slots(
            belief[n], positions[n, 0, 0], positions[n, 0, 1], cell_rows[n, :cells],
            cell_cols[n, :cells], cell_cluster[n, :cells], centroids[n, :count],
            sizes[n, :count], gains[n, :count], n_slots, False,
        )  # fmt: skip
        goals[m] = _nearest_path(result[1], result[3], result[4], result[7])
