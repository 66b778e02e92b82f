"""A batch of worlds stepped together: the state of N episodes of K robots in shared arrays.

Every operation of a decision step runs for all worlds in one compiled call (the walk of every
robot, frontier masks, cluster splitting and statistics, the slots of every robot), and the
frontier masks of all worlds whose belief changed are labelled by **one**
``scipy.ndimage.label`` call: the masks, each cropped to the box around its frontier cells and
ending in a blank row, are labelled as one image
(:func:`~frontier_marl.core.frontiers.pack_frontier_masks`), so no component crosses from one
world to the next, and labels are numbered world by world in raster order, exactly as one call
per world on its whole map would number them.
:class:`~frontier_marl.core.world.World` is the same thing for one world.

Arrays are indexed ``[world, ...]`` and ``[world, robot, ...]``; read them, never write them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from frontier_marl.core.frontiers import Clusters, label_packed
from frontier_marl.core.grid import UNKNOWN
from frontier_marl.core.maps import FOUR_CONNECTED
from frontier_marl.core.planning import path_search_scratch
from frontier_marl.core.sensing import Sensor, reveal
from frontier_marl.core.slots import SLOT_COLUMNS, SlotArrays
from frontier_marl.core.world_kernels import (
    all_slots,
    basis_code,
    explored_fractions,
    recluster,
    stale_masks,
    walk_worlds,
)

FULL_PATH = -1  # ``cells_per_step`` value meaning "walk the whole path"


@dataclass(frozen=True)
class WorldParams:
    """Static parameters of the world transition."""

    sensor: Sensor
    cells_per_step: int  # >= 1, or FULL_PATH
    connectivity: int = 8
    max_cluster_cells: int = 0
    gain: str = "size"  # or "unknown"


class Worlds:
    """N worlds of K robots each; worlds are placed (reset) one by one and stepped together."""

    def __init__(
        self, shape: tuple[int, int], n_worlds: int, n_agents: int, params: WorldParams
    ) -> None:
        height, width = shape
        n, k = n_worlds, n_agents
        cells = height * width
        self.params = params
        self.shape = (height, width)
        self.n_worlds, self.n_agents = n, k
        self.true = np.zeros((n, height, width), dtype=bool)
        self.belief = np.full((n, height, width), UNKNOWN, dtype=np.int8)
        self.positions = np.zeros((n, k, 2), dtype=np.int64)
        self.seen = np.zeros((n, k, height, width), dtype=bool)
        self.travelled = np.zeros((n, k), dtype=np.int64)
        self.start_region = np.zeros((n, height, width), dtype=bool)
        self.start_region_size = np.zeros(n, dtype=np.int64)
        self.true_free = np.zeros(n, dtype=np.int64)
        self.version = np.zeros(n, dtype=np.int64)  # bumped whenever a belief changes
        # The walk: plan cache and outputs (see movement.walk).
        budget = params.cells_per_step
        walk_cells = cells if budget == FULL_PATH else min(budget + 1, cells)
        self.plan_cells = np.zeros((n, k, cells, 2), dtype=np.int64)
        self.plan_meta = np.full((n, k, 5), -1, dtype=np.int64)
        self.goals = np.full((n, k, 2), -1, dtype=np.int64)
        self.new_cells = np.zeros((n, k), dtype=np.int64)
        self.walked = np.zeros((n, k, walk_cells, 2), dtype=np.int64)
        self.walked_len = np.zeros((n, k), dtype=np.int64)
        self.reached = np.zeros((n, k), dtype=bool)
        self.search = path_search_scratch((height, width))  # the planner's, for every world
        # Frontier clusters per world, cells and clusters in raster order (capacity: all cells).
        self.cell_rows = np.zeros((n, cells), dtype=np.int64)
        self.cell_cols = np.zeros((n, cells), dtype=np.int64)
        self.cell_cluster = np.zeros((n, cells), dtype=np.int64)
        self.n_cells = np.zeros(n, dtype=np.int64)
        self.sizes = np.zeros((n, cells), dtype=np.int64)
        self.centroids = np.zeros((n, cells, 2))
        self.gains = np.zeros((n, cells))
        self.n_clusters = np.zeros(n, dtype=np.int64)
        self.clustered_version = np.full(n, -1, dtype=np.int64)
        # a recluster's buffers: the stale worlds, their frontier masks, the same packed and
        # their labels (flat, room for every world's whole map and a blank row), the crops'
        # boxes and the packed image's height and width (see pack_frontier_masks)
        self.stale = np.zeros(n, dtype=np.int64)
        self.frontier = np.zeros((n, height, width), dtype=bool)
        self.masks = np.zeros(n * (height + 1) * width, dtype=bool)
        self.labels = np.zeros(n * (height + 1) * width, dtype=np.int32)
        self.boxes = np.zeros((n, 4), dtype=np.int64)
        self.packed_shape = np.zeros(2, dtype=np.int64)
        # per basis code: the explored fractions and the belief versions they were counted at
        self._fractions = {code: (np.zeros(n), np.full(n, -1, dtype=np.int64)) for code in range(3)}

    # ----------------------------------------------------------------- episodes
    def place(
        self,
        world: int,
        true_grid: np.ndarray,
        starts: np.ndarray,
        start_region: np.ndarray | None = None,
    ) -> None:
        """Start world ``world`` on ``true_grid`` with robots at ``starts`` (K, 2), sensing at
        their cells. ``start_region``: the free cells reachable from the starts, if known."""
        starts = np.asarray(starts, dtype=np.int64).reshape(-1, 2)
        true_grid = np.asarray(true_grid, dtype=bool)
        if true_grid.shape != self.shape:
            raise ValueError(f"true grid of shape {true_grid.shape}, expected {self.shape}")
        if len(starts) != self.n_agents:
            raise ValueError(f"expected {self.n_agents} start cells, got {len(starts)}")
        if true_grid[starts[:, 0], starts[:, 1]].any():
            raise ValueError("every start cell must be free")
        if len({tuple(s) for s in starts.tolist()}) != len(starts):
            raise ValueError("start cells must be distinct")
        if start_region is None:
            start_region = reachable_region(true_grid, starts)
        elif not start_region[starts[:, 0], starts[:, 1]].all():
            raise ValueError("start_region must contain every start cell")
        i = world
        self.true[i] = true_grid
        self.belief[i] = UNKNOWN
        self.positions[i] = starts
        self.seen[i] = False
        self.travelled[i] = 0
        self.plan_meta[i] = -1
        self.goals[i] = -1
        self.start_region[i] = start_region
        self.start_region_size[i] = np.count_nonzero(start_region)
        self.true_free[i] = np.count_nonzero(~true_grid)
        self.version[i] += 1
        offsets, between = self.params.sensor.rays
        for agent in range(self.n_agents):
            row, col = int(starts[agent, 0]), int(starts[agent, 1])
            if reveal(
                self.true[i], self.belief[i], self.seen[i, agent], row, col, offsets, between
            ):
                self.version[i] += 1

    # ----------------------------------------------------------------- transition
    def move(self, goals: np.ndarray, active: np.ndarray) -> None:
        """Walk every robot of the ``active`` worlds toward ``goals`` (N, K, 2; row -1: stay);
        the outputs are left in ``new_cells``, ``walked``, ``walked_len`` and ``reached``."""
        if goals is not self.goals:
            self.goals[:] = goals
        offsets, between = self.params.sensor.rays
        walk_worlds(
            active,
            self.true,
            self.belief,
            self.seen,
            self.positions,
            self.travelled,
            self.goals,
            self.plan_cells,
            self.plan_meta,
            self.version,
            self.params.cells_per_step,
            offsets,
            between,
            self.new_cells,
            self.walked,
            self.walked_len,
            self.reached,
            self.search,
        )

    # ----------------------------------------------------------------- frontier view
    def refresh_clusters(self) -> None:
        """Recluster the worlds whose belief changed since they were last clustered."""
        stale = stale_masks(
            self.version, self.clustered_version, self.belief, self.stale, self.frontier,
            self.masks, self.boxes, self.packed_shape,
        )  # fmt: skip
        if stale:
            self.label_stale()
            recluster(
                self.labels, self.boxes, int(self.packed_shape[1]), self.stale[:stale],
                self.params.max_cluster_cells, self.params.gain != "unknown", self.belief,
                self.cell_rows, self.cell_cols, self.cell_cluster, self.n_cells, self.sizes,
                self.centroids, self.gains, self.n_clusters, self.version, self.clustered_version,
            )  # fmt: skip

    def label_stale(self) -> None:
        """Label the packed frontier masks of the stale worlds (one ``scipy.ndimage.label``
        call, :func:`~frontier_marl.core.frontiers.label_packed`)."""
        height, width = self.packed_shape
        label_packed(self.masks, self.labels, int(height), int(width), self.params.connectivity)

    def walk_arrays(self) -> tuple:
        """The reachable region and its size, then the settings and arrays of the walk
        (``walk_worlds``' arguments after ``active``, ``search`` last), as one tuple for the
        rollouts' compiled loops."""
        offsets, between = self.params.sensor.rays
        return (
            self.start_region, self.start_region_size, self.true, self.belief, self.seen,
            self.positions, self.travelled, self.goals, self.plan_cells, self.plan_meta,
            self.version, self.params.cells_per_step, offsets, between, self.new_cells,
            self.walked, self.walked_len, self.reached, self.search,
        )  # fmt: skip

    def clusters(self, world: int) -> Clusters:
        """World ``world``'s clusters as of its last :meth:`refresh_clusters`."""
        cells, count = int(self.n_cells[world]), int(self.n_clusters[world])
        return Clusters(
            self.shape,
            self.cell_rows[world, :cells],
            self.cell_cols[world, :cells],
            self.cell_cluster[world, :cells],
            self.sizes[world, :count],
            self.centroids[world, :count],
        )

    def slots(
        self,
        out: SlotArrays,
        worlds: np.ndarray,
        sort_by_distance: bool,
        packed: np.ndarray | None = None,
    ) -> None:
        """The slots of every robot of ``worlds`` (indices) into ``out`` and, packed, into
        ``packed`` ``(N, K, n_slots, 10)`` if given (clusters refreshed first); ``out``'s last
        axis is the number of slots."""
        if packed is None:
            packed = np.empty((*out.cluster.shape, len(SLOT_COLUMNS)))
        self.refresh_clusters()
        all_slots(
            worlds,
            self.belief,
            self.positions,
            self.cell_rows,
            self.cell_cols,
            self.cell_cluster,
            self.n_cells,
            self.centroids,
            self.sizes,
            self.gains,
            self.n_clusters,
            sort_by_distance,
            out.cluster,
            out.valid,
            out.centroid,
            out.target,
            out.distance,
            out.size,
            out.gain,
            out.path_length,
            out.mask,
            out.live,
            packed,
        )

    def explored_fraction(self, basis: str) -> np.ndarray:
        """Per world: the fraction of ``all`` cells known, of true-``free`` cells known free, or
        of the ``reachable`` free region known (a copy; worlds whose belief did not change since
        the last call are not recounted)."""
        code = basis_code(basis)
        fraction, counted = self._fractions[code]
        explored_fractions(
            code, self.belief, self.true_free, self.start_region, self.start_region_size,
            self.version, counted, fraction,
        )  # fmt: skip
        return fraction.copy()


def reachable_region(true_grid: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """The free cells 4-connected to any of the ``starts`` on ``true_grid``."""
    labels, _ = ndimage.label(~true_grid, structure=FOUR_CONNECTED)
    ids = np.unique(labels[starts[:, 0], starts[:, 1]])
    return np.isin(labels, ids)
