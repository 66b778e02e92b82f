"""Branching: copy one world into K worlds of a batch, to play K futures of it at once.

* :func:`clone_world` copies everything that decides a world's future (true map, belief,
  robots, what each robot has seen, the distance walked, the reachable region, the plan cache)
  from one world of a :class:`~frontier_marl.core.worlds.Worlds` batch into rows of another.
* :func:`branch` makes a batch of K such clones; :func:`~frontier_marl.sim.rollouts.rollout_costs`
  then rolls them all out together, each with its own first target (the lookahead oracle,
  :mod:`frontier_marl.policies.lookahead`, and the cost-to-go labels are built on this).
* :func:`clone_mdp` does the same one level up: one world of a decision process (its world,
  slots, step counters, oscillation history, motion trail and episode generator) becomes K
  worlds of a :class:`~frontier_marl.sim.batch_engine.BatchMDP`, which steps each with its own
  slot actions exactly as the original would; :func:`branch_mdp` clones a single env's.
"""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np

from frontier_marl.core.worlds import Worlds
from frontier_marl.sim.batch_engine import BatchMDP
from frontier_marl.sim.engine import ExplorationMDP

_STATE = (
    "true", "belief", "positions", "seen", "travelled", "start_region", "start_region_size",
    "true_free", "new_cells", "walked", "walked_len", "reached",
)  # fmt: skip
_PLANS = ("plan_cells", "plan_meta", "goals")
_DECISIONS = (
    "steps", "steps_without_progress", "done", "targets", "heading", "padding", "oscillation",
    "new_cells",
)  # fmt: skip


def clone_world(
    source: Worlds, index: int, target: Worlds, rows: np.ndarray, plans: bool = True
) -> None:
    """World ``index`` of ``source`` into worlds ``rows`` of ``target`` (same shape, robots and
    sensor). ``plans``: keep the robots' plan cache and goals (then a clone walks exactly as
    its original), or clear them (each clone plans afresh toward its next goal)."""
    rows = np.asarray(rows, dtype=np.int64)
    for name in _STATE:
        getattr(target, name)[rows] = getattr(source, name)[index]
    # Versions only grow (caches are keyed by them): the clones get a version above any they
    # or the source had, and a plan keeps matching the belief it was planned on.
    version = max(int(target.version[rows].max(initial=0)), int(source.version[index])) + 1
    shift = version - int(source.version[index])
    target.version[rows] = version
    if plans:
        for name in _PLANS:
            getattr(target, name)[rows] = getattr(source, name)[index]
        meta = target.plan_meta[rows]
        meta[..., 4] = np.where(meta[..., 4] >= 0, meta[..., 4] + shift, -1)
        target.plan_meta[rows] = meta
    else:
        target.plan_meta[rows] = -1
        target.goals[rows] = -1


def branch(source: Worlds, index: int, count: int, gain: str | None = None) -> Worlds:
    """A new batch of ``count`` clones of world ``index`` of ``source`` (plans cleared), whose
    clusters are scored with ``gain`` (default: the source's)."""
    params = source.params if gain is None else replace(source.params, gain=gain)
    sims = Worlds(source.shape, count, source.n_agents, params)
    clone_world(source, index, sims, np.arange(count), plans=False)
    return sims


def branch_mdp(mdp: ExplorationMDP, count: int, rng: np.random.Generator | None = None) -> BatchMDP:
    """A :class:`BatchMDP` of ``count`` exact copies of the single-world ``mdp`` mid-episode:
    ``step(actions, active)`` then plays each copy with its own actions as ``mdp.step`` would
    (same belief, positions, slots, rewards and ends). ``rng``: the generator of the env's
    later episodes (an adapter's), copied into every world's (default: fresh ones)."""
    if mdp.world is None or mdp.done:
        raise RuntimeError("branch_mdp needs an episode in progress (after reset, not ended)")
    return clone_mdp(mdp.batch, 0, count, rng)


def clone_mdp(
    source: BatchMDP, index: int, count: int, rng: np.random.Generator | None = None
) -> BatchMDP:
    """A :class:`BatchMDP` of ``count`` copies of world ``index`` of ``source`` (its world,
    slots, step counters, oscillation history, motion trail and last decisions), each of
    which then steps exactly as the original would with the same actions. ``rng``: copied
    into every world's episode generator (default: fresh ones)."""
    batch = BatchMDP(source.cfg, count)
    rows = np.arange(count)
    clone_world(source.worlds, index, batch.worlds, rows)
    if rng is not None:
        batch.rngs = [copy.deepcopy(rng) for _ in rows]
    for name in source.slots.__slots__:
        getattr(batch.slots, name)[rows] = getattr(source.slots, name)[index]
    batch.packed[rows] = source.packed[index]
    batch._oscillation.history[rows] = source._oscillation.history[index]
    if source._trail is not None and batch._trail is not None:
        batch._trail.cells[rows] = source._trail.cells[index]
    for name in _DECISIONS:
        getattr(batch, name)[rows] = getattr(source, name)[index]
    batch.explored = batch.worlds.explored_fraction(source.cfg.reward.threshold_basis)
    return batch
