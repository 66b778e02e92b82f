"""The compiled loops of :class:`~frontier_marl.core.worlds.Worlds` over a batch of worlds: the
walk of every robot, the start and end of a recluster, the slots of every robot, the explored
fractions.
Each calls the one implementation of its operation for world after world."""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontiers import cluster_worlds, count_unknown_around, pack_frontier_masks
from frontier_marl.core.grid import FREE, UNKNOWN
from frontier_marl.core.movement import walk
from frontier_marl.core.slot_kernels import fill_robot_slots
from frontier_marl.core.slots import _pack


@compiled
def walk_worlds(
    active: np.ndarray,
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
    search: tuple,
) -> None:
    """:func:`~frontier_marl.core.movement.walk` for every active world (``search``: the
    planner's scratch, shared by the worlds)."""
    for n in range(len(active)):
        if not active[n]:
            continue
        version[n] = walk(
            true[n],
            belief[n],
            seen[n],
            positions[n],
            travelled[n],
            goals[n],
            plan_cells[n],
            plan_meta[n],
            version[n],
            cells_per_step,
            offsets,
            between,
            new_cells[n],
            walked[n],
            walked_len[n],
            reached[n],
            search,
        )


@compiled
def stale_masks(
    version: np.ndarray,
    clustered_version: np.ndarray,
    belief: np.ndarray,
    stale: np.ndarray,
    frontier: np.ndarray,
    masks: np.ndarray,
    boxes: np.ndarray,
    packed_shape: np.ndarray,
) -> int:
    """The start of a recluster: the worlds whose belief ``version`` is not the one they were
    clustered at go into ``stale`` (their count is returned), their frontier masks into
    ``frontier`` and packed into ``masks``
    (:func:`~frontier_marl.core.frontiers.pack_frontier_masks`: the crops' ``boxes``, the
    image's height and width into ``packed_shape``)."""
    count = 0
    for n in range(len(version)):
        if clustered_version[n] != version[n]:
            stale[count] = n
            count += 1
    packed_shape[0], packed_shape[1] = pack_frontier_masks(
        belief, stale[:count], frontier, masks, boxes
    )
    return count


@compiled
def recluster(
    labels: np.ndarray,
    boxes: np.ndarray,
    width: int,
    stale: np.ndarray,
    max_cells: int,
    by_size: bool,
    belief: np.ndarray,
    cell_rows: np.ndarray,
    cell_cols: np.ndarray,
    cell_cluster: np.ndarray,
    n_cells: np.ndarray,
    sizes: np.ndarray,
    centroids: np.ndarray,
    gains: np.ndarray,
    n_clusters: np.ndarray,
    version: np.ndarray,
    clustered_version: np.ndarray,
) -> None:
    """The end of a recluster of the ``stale`` worlds, from their packed ``labels`` (``width``
    columns, the crops' ``boxes``): their clusters
    (:func:`~frontier_marl.core.frontiers.cluster_worlds`), the clusters' gains (their sizes
    ``by_size``, else the unknown cells around them), and clustered as of ``version``."""
    cluster_worlds(
        labels, boxes, width, stale, max_cells, cell_rows, cell_cols, cell_cluster, n_cells,
        sizes, centroids, n_clusters,
    )  # fmt: skip
    for n in stale:
        count, cells = n_clusters[n], n_cells[n]
        if by_size:
            gains[n, :count] = sizes[n, :count]
        else:
            around = np.zeros(count, dtype=np.int64)
            count_unknown_around(
                belief[n], cell_rows[n, :cells], cell_cols[n, :cells], cell_cluster[n, :cells],
                around,
            )  # fmt: skip
            gains[n, :count] = around
        clustered_version[n] = version[n]


@compiled
def all_slots(
    worlds: np.ndarray,
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
    sort: bool,
    cluster: np.ndarray,
    valid: np.ndarray,
    centroid: np.ndarray,
    target: np.ndarray,
    distance: np.ndarray,
    size: np.ndarray,
    gain: np.ndarray,
    path_length: np.ndarray,
    mask: np.ndarray,
    live: np.ndarray,
    packed: np.ndarray,
) -> None:
    """:func:`~frontier_marl.core.slot_kernels.fill_robot_slots` of every robot of ``worlds``,
    into the outputs, and the same slots packed
    (:meth:`~frontier_marl.core.slots.SlotArrays.packed`) into ``packed`` (N, K, S, 10)."""
    field = np.empty(belief.shape[1:], dtype=np.int64)  # the distance fields' scratch
    queue = np.empty(belief.shape[1] * belief.shape[2], dtype=np.int64)
    for n in worlds:
        cells, count = n_cells[n], n_clusters[n]
        for k in range(positions.shape[1]):
            live[n, k] = fill_robot_slots(
                belief[n],
                positions[n, k, 0],
                positions[n, k, 1],
                cell_rows[n, :cells],
                cell_cols[n, :cells],
                cell_cluster[n, :cells],
                centroids[n, :count],
                sizes[n, :count],
                gains[n, :count],
                sort,
                field,
                queue,
                cluster[n, k],
                valid[n, k],
                centroid[n, k],
                target[n, k],
                distance[n, k],
                size[n, k],
                gain[n, k],
                path_length[n, k],
                mask[n, k],
            )
            _pack(
                cluster[n, k], valid[n, k], centroid[n, k], target[n, k], distance[n, k],
                path_length[n, k], size[n, k], gain[n, k], packed[n, k],
            )  # fmt: skip


#: The bases of the explored fraction, by their code in the kernels below: the fraction of
#: ``all`` cells known, of the true-``free`` cells known free, of the ``reachable`` region known.
EXPLORED_BASES = ("all", "free", "reachable")


def basis_code(basis: str) -> int:
    """The kernels' code of an explored-fraction ``basis`` (:data:`EXPLORED_BASES`)."""
    if basis not in EXPLORED_BASES:
        raise ValueError(f"threshold_basis must be 'all', 'free' or 'reachable', got {basis!r}")
    return EXPLORED_BASES.index(basis)


@compiled
def count_cells(basis: int, belief: np.ndarray, region: np.ndarray) -> int:
    """The cells of one world's ``belief`` that count as explored on ``basis`` (a code of
    :data:`EXPLORED_BASES`): known, known free, or known inside the bool mask ``region``."""
    count = 0
    for r in range(belief.shape[0]):
        for c in range(belief.shape[1]):
            state = belief[r, c]
            if basis == 0:
                count += state != UNKNOWN
            elif basis == 1:
                count += state == FREE
            else:
                count += region[r, c] and state != UNKNOWN
    return count


@compiled
def explored_fractions(
    basis: int,
    belief: np.ndarray,
    true_free: np.ndarray,
    region: np.ndarray,
    region_size: np.ndarray,
    version: np.ndarray,
    counted_version: np.ndarray,
    fraction: np.ndarray,
) -> None:
    """Per world whose belief ``version`` is not its ``counted_version``, its explored
    fraction on ``basis`` (:func:`count_cells` over all cells, the true free cells or the
    reachable ``region``'s ``region_size``) into ``fraction`` (N,); both updated in place."""
    for n in range(belief.shape[0]):
        if counted_version[n] == version[n]:
            continue
        count = count_cells(basis, belief[n], region[n])
        if basis == 0:
            fraction[n] = count / belief[n].size
        else:
            fraction[n] = count / max(true_free[n] if basis == 1 else region_size[n], 1)
        counted_version[n] = version[n]
