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
from frontier_marl.core.frontiers import (
    cluster_stats,
    is_frontier,
    label_frontier_cells,
    split_and_renumber,
)
from frontier_marl.core.grid import FREE, UNKNOWN
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


def rollout_costs(
    sims: Worlds, start: int, coverage: float, max_cells: int, base: RolloutBase
) -> np.ndarray:
    """Cells robot 0 of each world of ``sims`` walks beyond ``start`` until ``coverage`` of its
    reachable free region is known, heading first for its current goal (``sims.goals``) and
    then where ``base`` sends it; a world that walks ``max_cells`` or has nothing reachable
    left to explore before that costs ``max_cells``."""
    n = sims.n_worlds
    state = _RolloutState(sims, max_cells)
    if isinstance(base, NearestPathBase):  # the whole rollout in one compiled call
        _rollout_nearest_path(sims, state, start, coverage, max_cells, base.n_slots)
        return state.cost
    slots = SlotArrays.empty(n, 1, base.n_slots)
    while True:
        _advance(sims, state, start, coverage, max_cells)
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
    """Per world: ended, has a new target to walk toward first, waits for a decision, its
    cost, and an upper bound on its known cells of the region (``known``; ``exact`` when it
    is the count itself). The bound grows by the cells each walk reveals, and the belief is
    counted only when the bound reaches the coverage level."""

    def __init__(self, sims: Worlds, max_cells: int) -> None:
        n = sims.n_worlds
        self.done = np.zeros(n, dtype=bool)
        self.pending = np.zeros(n, dtype=bool)
        self.deciding = np.zeros(n, dtype=bool)
        self.cost = np.full(n, max_cells, dtype=np.int64)
        self.known = sims.start_region_size.copy()  # the region itself: a bound that holds
        self.exact = np.zeros(n, dtype=bool)

    def arrays(self) -> tuple[np.ndarray, ...]:
        return self.done, self.pending, self.deciding, self.cost, self.known, self.exact


def _world_arrays(sims: Worlds) -> tuple[object, ...]:
    """The arrays and settings :func:`_advance_world` reads and writes, in its order."""
    offsets, between = sims.params.sensor.rays
    return (
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


def _advance(sims: Worlds, state: _RolloutState, start: int, coverage: float, cap: int) -> None:
    advance(*state.arrays(), start, coverage, cap, *_world_arrays(sims))


def _rollout_nearest_path(
    sims: Worlds, state: _RolloutState, start: int, coverage: float, cap: int, n_slots: int
) -> None:
    cells = sims.shape[0] * sims.shape[1]
    scratch = tuple(np.empty(cells, dtype=np.int64) for _ in range(4))
    index = np.full(sims.shape, -1, dtype=np.int64)
    distance = np.full(cells, -1, dtype=np.int64)
    params = sims.params
    rollout_nearest_path(
        *state.arrays(), start, coverage, cap, *_world_arrays(sims),
        params.connectivity, params.max_cluster_cells, n_slots, *scratch, index, distance,
    )  # fmt: skip


@compiled
def advance(
    done: np.ndarray,
    pending: np.ndarray,
    deciding: np.ndarray,
    cost: np.ndarray,
    known: np.ndarray,
    exact: np.ndarray,
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
    """:func:`advance_world` for every world (``deciding``: it needs a decision)."""
    for n in range(len(done)):
        deciding[n] = False
        if done[n]:
            continue
        deciding[n] = advance_world(
            n, done, pending, cost, known, exact, start, coverage, max_cells, region,
            region_size, true, belief, seen, positions, travelled, goals, plan_cells,
            plan_meta, version, cells_per_step, offsets, between, new_cells, walked,
            walked_len, reached,
        )  # fmt: skip


@compiled
def advance_world(
    n: int,
    done: np.ndarray,
    pending: np.ndarray,
    cost: np.ndarray,
    known: np.ndarray,
    exact: np.ndarray,
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
) -> bool:
    """Walk live world ``n`` (a ``pending`` one first toward its new goal) until it ends
    (coverage reached: ``cost`` is its walk; ``max_cells`` walked; ``done`` set) or its goal is
    no longer a frontier cell or is reached (returns True: it needs a decision)."""
    moving = pending[n]
    pending[n] = False
    while True:
        if moving:
            version[n] = walk(
                true[n], belief[n], seen[n], positions[n], travelled[n], goals[n],
                plan_cells[n], plan_meta[n], version[n], cells_per_step, offsets, between,
                new_cells[n], walked[n], walked_len[n], reached[n],
            )  # fmt: skip
            revealed = new_cells[n].sum()
            if revealed:
                known[n] += revealed
                exact[n] = False
        moving = True
        size = max(region_size[n], 1)
        if not exact[n] and known[n] / size >= coverage:  # the bound says maybe: count
            known[n] = _count_known(belief[n], region[n])
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
    done: np.ndarray,
    pending: np.ndarray,
    deciding: np.ndarray,
    cost: np.ndarray,
    known: np.ndarray,
    exact: np.ndarray,
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
    connectivity: int,
    max_cluster_cells: int,
    n_slots: int,
    rows: np.ndarray,
    cols: np.ndarray,
    label: np.ndarray,
    parent: np.ndarray,
    index: np.ndarray,
    distance: np.ndarray,
) -> None:
    """Every world rolled out to its end with :class:`NearestPathBase` deciding, world after
    world (the worlds are independent); ``rows`` to ``index`` are the scratch of
    :func:`nearest_path_goal`."""
    for n in range(len(done)):
        while not done[n]:
            if not advance_world(
                n, done, pending, cost, known, exact, start, coverage, max_cells, region,
                region_size, true, belief, seen, positions, travelled, goals, plan_cells,
                plan_meta, version, cells_per_step, offsets, between, new_cells, walked,
                walked_len, reached,
            ):  # fmt: skip
                continue
            goal = nearest_path_goal(
                belief[n], positions[n, 0, 0], positions[n, 0, 1], connectivity,
                max_cluster_cells, n_slots, rows, cols, label, parent, index, distance,
            )  # fmt: skip
            if goal[0] < 0:  # nothing reachable is left to explore: it cannot finish
                done[n] = True
            else:
                goals[n, 0, 0] = goal[0]
                goals[n, 0, 1] = goal[1]
                pending[n] = True


@compiled
def nearest_path_goal(
    belief: np.ndarray,
    row: int,
    col: int,
    connectivity: int,
    max_cluster_cells: int,
    n_slots: int,
    rows: np.ndarray,
    cols: np.ndarray,
    label: np.ndarray,
    parent: np.ndarray,
    index: np.ndarray,
    distance: np.ndarray,
) -> np.ndarray:
    """:class:`NearestPathBase`'s target for the robot at (row, col) on ``belief``: its
    frontier clusters as :meth:`Worlds.refresh_clusters` makes them (labelled by
    :func:`~frontier_marl.core.frontiers.label_frontier_cells`, split above
    ``max_cluster_cells``), its slots, the nearest by path; (-1, -1) if none is live."""
    cells, count = label_frontier_cells(belief, connectivity, rows, cols, label, parent, index)
    cell_rows, cell_cols, cluster = rows[:cells], cols[:cells], label[:cells]
    if max_cluster_cells > 0 and cells > 0:
        cluster, count = split_and_renumber(
            cell_rows, cell_cols, cluster.copy(), count, max_cluster_cells
        )
    sizes, centroids = cluster_stats(cell_rows, cell_cols, cluster, count)
    if count <= n_slots:  # every live cluster gets a slot: a bounded search decides
        goal = _nearest_by_bounded_search(
            belief, row, col, cell_rows, cell_cols, cluster, centroids, parent, index, distance
        )
        if goal[0] != -2:
            return goal
    result = _robot_slots(
        belief, row, col, cell_rows, cell_cols, cluster, centroids, sizes,
        sizes.astype(np.float64), n_slots, False,
    )  # fmt: skip
    return _nearest_path(result[1], result[3], result[4], result[7])


@compiled
def _nearest_by_bounded_search(
    belief: np.ndarray,
    row: int,
    col: int,
    cell_rows: np.ndarray,
    cell_cols: np.ndarray,
    cluster: np.ndarray,
    centroids: np.ndarray,
    queue: np.ndarray,
    owner: np.ndarray,
    distance: np.ndarray,
) -> np.ndarray:
    """:func:`_nearest_path` of the slots of every cluster, found by a breadth-first search
    from (row, col) that stops as soon as the answer is sure; (-2, -2) when it cannot be
    (the caller then builds the slots). ``queue``/``distance`` (H*W; ``distance`` all -1) and
    ``owner`` ((H, W), all -1) are scratch, left as found.

    A cluster's slot target is its reachable cell nearest the centroid. Its cell nearest the
    centroid of all, once the search reaches it, is that target, at a known path length. A
    cluster none of whose cells the search has reached has its target further than the
    search has gone. So once every cell within the best known path length is reached and
    every cluster is one of those two kinds, the best is the answer. A cluster reached, but
    not at that cell, may have it unreachable and its target nearer: then the search goes on,
    and if it ends so, it cannot decide."""
    height, width = belief.shape
    count = len(centroids)
    star = np.full(count, -1, dtype=np.int64)  # the cell nearest the centroid, raster index
    best2 = np.full(count, np.inf)
    for i in range(len(cluster)):
        k = cluster[i]
        d_row = cell_rows[i] - centroids[k, 0]
        d_col = cell_cols[i] - centroids[k, 1]
        dist2 = d_row * d_row + d_col * d_col
        if dist2 < best2[k]:
            best2[k] = dist2
            star[k] = cell_rows[i] * width + cell_cols[i]
        owner[cell_rows[i], cell_cols[i]] = k
    hit = np.zeros(count, dtype=np.bool_)
    settled = np.zeros(count, dtype=np.bool_)
    unsure = 0  # clusters reached, but not at their star cell
    best, best_path, best_distance = -1, 0, 0.0
    queue[0] = row * width + col
    distance[queue[0]] = 0
    head, tail = 0, 1
    while head < tail:
        if best >= 0 and unsure == 0 and distance[queue[head]] > best_path:
            break
        cell = queue[head]
        head += 1
        r, c = cell // width, cell % width
        k = owner[r, c]
        if k >= 0:
            before = hit[k] and not settled[k]
            hit[k] = True
            if cell == star[k]:
                settled[k] = True
                d = distance[cell]
                gap = np.hypot(centroids[k, 0] - row, centroids[k, 1] - col)
                if best < 0 or d < best_path or (d == best_path and (
                    gap < best_distance or (gap == best_distance and k < best)
                )):  # fmt: skip
                    best, best_path, best_distance = k, d, gap
            unsure += (hit[k] and not settled[k]) - before
        d = distance[cell] + 1
        for nr, nc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
            if 0 <= nr < height and 0 <= nc < width and belief[nr, nc] == FREE:
                neighbour = nr * width + nc
                if distance[neighbour] < 0:
                    distance[neighbour] = d
                    queue[tail] = neighbour
                    tail += 1
    for i in range(tail):
        distance[queue[i]] = -1
    for i in range(len(cluster)):
        owner[cell_rows[i], cell_cols[i]] = -1
    out = np.full(2, -2, dtype=np.int64)
    if unsure == 0:
        out[:] = -1
        if best >= 0:
            out[0] = star[best] // width
            out[1] = star[best] % width
    return out


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
