"""Roll many team worlds out at once: every robot walks, a team base policy re-targets them.

:func:`team_rollout_costs` finishes every world of a :class:`~frontier_marl.core.worlds.Worlds`
batch of K robots (typically clones of one world made by
:func:`frontier_marl.sim.branching.branch`, each with its own first targets) until ``coverage``
of the reachable free region is known, and returns each world's *makespan to go*: the longest
path of any robot at that moment, less the longest at the start. It is the team version of
:func:`frontier_marl.sim.rollouts.rollout_costs`, run in decision rounds: one compiled call
steps every world, one cell per robot per step, until one of its robots needs a target or the
world ends; the deciding worlds' slots come from one :meth:`Worlds.slots` call and the base
(:class:`ClaimingNearestBase` by default) re-targets their deciding robots.

A robot needs a target when it has none, its target is no longer a frontier cell or it reached
it, or it has waited two steps in a row behind a teammate (the walk lets a robot wait when its
next cell is occupied; without a new target two robots can block each other for good). If it
and a teammate each stand on the other's next cell (head-on in a corridor), the two swap their
targets instead: each turns back toward the other's. A robot the
base leaves without a target idles until the world reveals a cell again.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontiers import is_frontier
from frontier_marl.core.movement import walk
from frontier_marl.core.slots import SlotArrays
from frontier_marl.core.world_kernels import basis_code, count_cells
from frontier_marl.core.worlds import Worlds
from frontier_marl.sim.rollouts import ROLLOUT_SLOTS

_REACHABLE = basis_code("reachable")
BLOCKED_STEPS = 2  # steps a robot waits behind a teammate before it is given a new target


class TeamRolloutBase(Protocol):
    """A team base policy for the rollouts: ``n_slots`` slots per robot, the ``gain`` model of
    the simulations, and :meth:`goals`: new targets ``(len(worlds), K, 2)`` for the robots
    ``deciding[i, a]`` of ``worlds[i]`` (row -1: none; other robots' rows are ignored), from
    their slots and the robots' current goals (``sims.goals``)."""

    n_slots: int
    gain: str

    def goals(
        self, sims: Worlds, slots: SlotArrays, worlds: np.ndarray, deciding: np.ndarray
    ) -> np.ndarray: ...


class ClaimingNearestBase:
    """Each deciding robot, in robot order, takes its live slot nearest by known-free path
    (ties: nearest centroid, then the lower slot) among those whose target lies more than
    ``reach`` cells (Euclidean) from every teammate's target (those kept and those just
    given); the nearest of all its slots if every one is claimed. It never takes its previous
    target again while it has another slot (a blocked robot turns elsewhere). ``reach`` is
    the sensor range: a target that close to a teammate's is seen from there."""

    n_slots = ROLLOUT_SLOTS  # every reachable cluster, as the heuristics see them
    gain = "size"  # reads no gain

    def __init__(self, reach: float) -> None:
        if not reach > 0:
            raise ValueError(f"reach must be > 0, got {reach}")
        self.reach = float(reach)

    def goals(
        self, sims: Worlds, slots: SlotArrays, worlds: np.ndarray, deciding: np.ndarray
    ) -> np.ndarray:
        previous = sims.goals[worlds]
        out = previous.copy()
        out[deciding] = -1  # a robot still to decide claims nothing yet
        for i, world in enumerate(worlds.tolist()):
            for robot in np.flatnonzero(deciding[i]).tolist():
                targets = slots.target[world, robot]
                others = np.delete(out[i], robot, axis=0)
                slot = claimed_nearest_slot(
                    slots.valid[world, robot], targets, slots.distance[world, robot],
                    slots.path_length[world, robot], previous[i, robot], others, self.reach,
                )  # fmt: skip
                out[i, robot] = targets[slot] if slot >= 0 else -1
        return out


def claimed_nearest_slot(
    valid: np.ndarray,
    targets: np.ndarray,
    distance: np.ndarray,
    path_length: np.ndarray,
    previous: np.ndarray,
    others: np.ndarray,
    reach: float,
) -> int:
    """:class:`ClaimingNearestBase`'s slot for one robot (-1: none valid): ``valid``,
    ``targets``, ``distance`` and ``path_length`` are its slots' (S,), ``previous`` its last
    target (row -1: none) and ``others`` (K, 2) its teammates' targets (row -1: none)."""
    allowed = np.asarray(valid, dtype=bool).copy()
    again = (targets == previous).all(axis=1)
    if (allowed & ~again).any():
        allowed &= ~again
    others = others[others[:, 0] >= 0]
    if len(others):
        gaps = targets[:, None, :].astype(np.float64) - others[None, :, :]
        near = (np.hypot(gaps[..., 0], gaps[..., 1]) <= reach).any(axis=1)
        if (allowed & ~near).any():
            allowed &= ~near
    candidates = np.flatnonzero(allowed)
    if len(candidates) == 0:
        return -1
    order = np.lexsort((candidates, distance[candidates], path_length[candidates]))
    return int(candidates[order[0]])


def team_rollout_costs(
    sims: Worlds,
    coverage: float,
    max_steps: int,
    base: TeamRolloutBase,
    prune: bool = False,
) -> np.ndarray:
    """Each world's makespan to go (the module's docstring) until ``coverage`` of its reachable
    free region is known, its robots heading first for their current goals (``sims.goals``;
    row -1: the base decides at once) and then where ``base`` sends them. A world that takes
    ``max_steps`` steps, or can no longer move, costs ``max_steps``.

    ``prune``: only the cheapest worlds matter (branch and bound); a world whose makespan to
    go passes the cheapest finished one's is stopped and costs ``max_steps``."""
    n, k = sims.n_worlds, sims.n_agents
    start = sims.travelled.max(axis=1)
    done = np.zeros(n, dtype=bool)
    pending = np.zeros(n, dtype=bool)
    cost = np.full(n, max_steps, dtype=np.int64)
    known = sims.start_region_size.copy()
    exact = np.zeros(n, dtype=bool)
    steps = np.zeros(n, dtype=np.int64)
    waits = np.zeros((n, k), dtype=np.int64)
    idle = np.zeros((n, k), dtype=bool)
    deciding = np.zeros((n, k), dtype=bool)
    state = (done, pending, cost, known, exact, steps, waits, idle, deciding, start)
    slots = SlotArrays.empty(n, k, base.n_slots)
    while True:
        cap = max_steps
        if prune:
            cap = min(max_steps, int(cost.min(initial=max_steps)) + 1)
        advance_teams(state, sims.walk_arrays(), coverage, max_steps, cap)
        worlds = np.flatnonzero(deciding.any(axis=1))
        if len(worlds) == 0:
            return cost
        sims.slots(slots, worlds, False)
        chosen = base.goals(sims, slots, worlds, deciding[worlds])
        mask = deciding[worlds]
        goals = sims.goals[worlds]
        goals[mask] = chosen[mask]
        sims.goals[worlds] = goals
        idle[worlds] = np.where(mask, goals[..., 0] < 0, idle[worlds])
        waits[worlds] = np.where(mask, 0, waits[worlds])
        pending[worlds] = True


@compiled
def advance_teams(state: tuple, world: tuple, coverage: float, max_steps: int, cap: int) -> None:
    """:func:`advance_team_world` for every live world."""
    done, deciding = state[0], state[8]
    for n in range(len(done)):
        deciding[n, :] = False
        if not done[n]:
            advance_team_world(n, state, world, coverage, max_steps, cap)


@compiled
def advance_team_world(
    n: int, state: tuple, world: tuple, coverage: float, max_steps: int, cap: int
) -> None:
    """Step live world ``n`` (a ``pending`` one first, with its new goals) until it ends
    (coverage reached: ``cost`` is its makespan to go; ``max_steps`` steps, or no robot can
    move; or past ``cap``: ``done`` set) or one of its robots needs a target (its row of
    ``deciding`` set). ``state``: the arrays of :func:`team_rollout_costs`; ``world``:
    :meth:`Worlds.walk_arrays`."""
    done, pending, cost, known, exact, steps, waits, idle, deciding, start = state
    # The walk and the coverage test as in rollouts.advance_world, written out: the same
    # two steps through helpers taking the world tuple cost the single-robot oracle about
    # 5 % of its time (benchmarks/bench_oracle.py, measured 2026-12-08).
    (
        region, region_size, true, belief, seen, positions, travelled, goals, plan_cells,
        plan_meta, version, cells_per_step, offsets, between, new_cells, walked, walked_len,
        reached, search,
    ) = world  # fmt: skip
    robots = positions.shape[1]
    moving = pending[n]
    pending[n] = False
    while True:
        if moving:
            version[n] = walk(
                true[n], belief[n], seen[n], positions[n], travelled[n], goals[n],
                plan_cells[n], plan_meta[n], version[n], cells_per_step, offsets, between,
                new_cells[n], walked[n], walked_len[n], reached[n], search,
            )  # fmt: skip
            steps[n] += 1
            revealed = new_cells[n].sum()
            if revealed:
                known[n] += revealed
                exact[n] = False
                idle[n, :] = False
            for a in range(robots):
                blocked = goals[n, a, 0] >= 0 and walked_len[n, a] == 1 and not reached[n, a]
                waits[n, a] = waits[n, a] + 1 if blocked else 0
            _swap_blocked_pairs(goals[n], positions[n], waits[n], plan_cells[n], plan_meta[n])
        moving = True
        size = max(region_size[n], 1)
        if not exact[n] and known[n] / size >= coverage:  # the bound says maybe: count
            known[n] = count_cells(_REACHABLE, belief[n], region[n])
            exact[n] = True
        covered = known[n] / size >= coverage
        makespan = travelled[n].max() - start[n]
        if covered:
            done[n] = True
            cost[n] = makespan
            return
        if steps[n] >= max_steps or makespan >= cap:
            done[n] = True
            return
        need = False
        heading = False
        for a in range(robots):
            row, col = goals[n, a, 0], goals[n, a, 1]
            if row < 0:
                stale = not idle[n, a]
            else:
                stale = (
                    not is_frontier(belief[n], row, col)
                    or reached[n, a]
                    or waits[n, a] >= BLOCKED_STEPS
                )
                heading = heading or not stale
            deciding[n, a] = stale
            need = need or stale
        if need:
            return
        if not heading:  # every robot idles and nothing changes: it cannot finish
            done[n] = True
            return


@compiled
def _swap_blocked_pairs(
    goals: np.ndarray,
    positions: np.ndarray,
    waits: np.ndarray,
    plans: np.ndarray,
    plan_meta: np.ndarray,
) -> None:
    """A robot that has waited :data:`BLOCKED_STEPS` steps and a teammate, each on the
    other's next cell (head-on), swap their targets and start counting again."""
    robots = len(waits)
    for a in range(robots):
        if waits[a] < BLOCKED_STEPS:
            continue
        for b in range(robots):
            if (
                b != a
                and _heads_into(a, b, goals, positions, plans, plan_meta)
                and _heads_into(b, a, goals, positions, plans, plan_meta)
            ):
                for k in range(2):
                    goals[a, k], goals[b, k] = goals[b, k], goals[a, k]
                waits[a] = 0
                waits[b] = 0
                break


@compiled
def _heads_into(
    a: int,
    b: int,
    goals: np.ndarray,
    positions: np.ndarray,
    plans: np.ndarray,
    plan_meta: np.ndarray,
) -> bool:
    """Whether robot ``b`` stands on the next cell of robot ``a``'s planned path."""
    first, end = plan_meta[a, 2], plan_meta[a, 3]
    if plan_meta[a, 0] != goals[a, 0] or plan_meta[a, 1] != goals[a, 1] or end <= first + 1:
        return False
    return plans[a, first + 1, 0] == positions[b, 0] and plans[a, first + 1, 1] == positions[b, 1]
