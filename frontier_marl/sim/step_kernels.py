"""A step of a batch of worlds in two compiled calls, one on each side of the labelling.

:func:`before_labelling` turns the actions into targets, walks every robot, counts the step and
makes the frontier masks of the worlds whose belief changed, each cropped to the box around its
frontier cells; ``scipy.ndimage.label`` labels them
(:meth:`~frontier_marl.core.worlds.Worlds.label_stale`); :func:`after_labelling` builds their
clusters, every robot's slots, the explored fractions, the rewards and the episode ends. Each
calls the one implementation of its parts (:mod:`frontier_marl.sim.decisions`,
:mod:`frontier_marl.core.world_kernels`).

Numba pays for every array it is handed (about 80 ns to type and unbox one), so the arguments
are flat (a tuple's elements are typed in Python, more slowly) and each array is passed once:
:class:`~frontier_marl.sim.batch_engine.BatchMDP` makes the argument lists once, in the order of
the signatures below.
"""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.world_kernels import (
    all_slots,
    explored_fractions,
    recluster,
    stale_masks,
    walk_worlds,
)
from frontier_marl.sim.decisions import count_progress, decide, finish_step


@compiled
def before_labelling(
    actions: np.ndarray,
    active: np.ndarray,
    new_cells: np.ndarray,
    # the decision: slot live counts and targets, oscillation history, the chosen targets,
    # padding and oscillation flags, the distance walked before the step, the step counters
    live: np.ndarray,
    slot_target: np.ndarray,
    history: np.ndarray,
    targets: np.ndarray,
    padding: np.ndarray,
    oscillation: np.ndarray,
    travel: bool,
    before: np.ndarray,
    steps: np.ndarray,
    idle: np.ndarray,
    # the walk (walk_worlds' arguments after ``active``, the planner's scratch flat)
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
    walk_new_cells: np.ndarray,
    walked: np.ndarray,
    walked_len: np.ndarray,
    reached: np.ndarray,
    search_cost: np.ndarray,
    search_parent: np.ndarray,
    search_touched: np.ndarray,
    heap_f: np.ndarray,
    heap_g: np.ndarray,
    heap_cell: np.ndarray,
    # the start of a recluster
    clustered_version: np.ndarray,
    stale: np.ndarray,
    frontier: np.ndarray,
    masks: np.ndarray,
    boxes: np.ndarray,
    packed_shape: np.ndarray,
) -> int:
    """The ``active`` worlds' robots head for the targets of their ``actions`` and walk
    (``travel``: the distance before the walk is kept in ``before``); the cells each revealed
    go into ``new_cells``; returns how many worlds are ``stale`` (to recluster), their frontier
    masks in ``frontier`` and packed for the labelling in ``masks`` (crops in ``boxes``, the
    image's shape in ``packed_shape``)."""
    decide(live, slot_target, actions, active, history, targets, padding, oscillation)
    if travel:
        before[:] = travelled
    goals[:] = targets
    search = (search_cost, search_parent, search_touched, heap_f, heap_g, heap_cell)
    walk_worlds(
        active, true, belief, seen, positions, travelled, goals, plan_cells, plan_meta, version,
        cells_per_step, offsets, between, walk_new_cells, walked, walked_len, reached, search,
    )  # fmt: skip
    count_progress(active, walk_new_cells, new_cells, steps, idle)
    return stale_masks(
        version, clustered_version, belief, stale, frontier, masks, boxes, packed_shape
    )


@compiled
def after_labelling(
    active: np.ndarray,
    new_cells: np.ndarray,
    n_stale: int,
    explored: np.ndarray,
    rewards: np.ndarray,
    # the decision, as before_labelling's
    live: np.ndarray,
    targets: np.ndarray,
    padding: np.ndarray,
    oscillation: np.ndarray,
    travel: bool,
    before: np.ndarray,
    steps: np.ndarray,
    idle: np.ndarray,
    # the worlds
    region: np.ndarray,
    region_size: np.ndarray,
    true_free: np.ndarray,
    belief: np.ndarray,
    positions: np.ndarray,
    travelled: np.ndarray,
    version: np.ndarray,
    reached: np.ndarray,
    # the recluster (recluster's arguments; the packed image's width read from its shape)
    labels: np.ndarray,
    boxes: np.ndarray,
    packed_shape: np.ndarray,
    stale: np.ndarray,
    max_cells: int,
    by_size: bool,
    cell_rows: np.ndarray,
    cell_cols: np.ndarray,
    cell_cluster: np.ndarray,
    n_cells: np.ndarray,
    sizes: np.ndarray,
    centroids: np.ndarray,
    gains: np.ndarray,
    n_clusters: np.ndarray,
    clustered_version: np.ndarray,
    # the slots (all_slots' outputs)
    sort: bool,
    cluster: np.ndarray,
    valid: np.ndarray,
    centroid: np.ndarray,
    slot_target: np.ndarray,
    distance: np.ndarray,
    size: np.ndarray,
    gain: np.ndarray,
    path_length: np.ndarray,
    mask: np.ndarray,
    packed: np.ndarray,
    # the explored fraction: its basis code, the versions counted at and the fractions
    basis: int,
    counted: np.ndarray,
    fractions: np.ndarray,
    # the end of the step (finish_step's arguments; the travel switch is the decision's)
    constants: np.ndarray,
    padding_truncates: bool,
    no_progress_limit: int,
    max_steps: int,
    threshold: float,
    terminated: np.ndarray,
    truncated: np.ndarray,
    reason: np.ndarray,
    done: np.ndarray,
    kept_targets: np.ndarray,
    kept_heading: np.ndarray,
    kept_padding: np.ndarray,
    kept_oscillation: np.ndarray,
) -> None:
    """The rest of the step: the clusters of the ``n_stale`` first stale worlds, the slots of
    every robot of the ``active`` worlds, each world's explored fraction into ``explored`` (N,)
    and the step's ``rewards``, ends and kept arrays
    (:func:`~frontier_marl.sim.decisions.finish_step`)."""
    recluster(
        labels, boxes, packed_shape[1], stale[:n_stale], max_cells, by_size, belief, cell_rows,
        cell_cols, cell_cluster, n_cells, sizes, centroids, gains, n_clusters, version,
        clustered_version,
    )  # fmt: skip
    all_slots(
        np.flatnonzero(active), belief, positions, cell_rows, cell_cols, cell_cluster, n_cells,
        centroids, sizes, gains, n_clusters, sort, cluster, valid, centroid, slot_target,
        distance, size, gain, path_length, mask, live, packed,
    )  # fmt: skip
    explored_fractions(basis, belief, true_free, region, region_size, version, counted, fractions)
    explored[:] = fractions
    moved = travelled - before if travel else new_cells
    finish_step(
        constants, travel, padding_truncates, no_progress_limit, max_steps, explored,
        threshold, live, new_cells, steps, idle, moved, active, targets, reached, padding,
        oscillation, (rewards, terminated, truncated, reason), done,
        (kept_targets, kept_heading, kept_padding, kept_oscillation),
    )  # fmt: skip
