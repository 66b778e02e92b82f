"""The world: true grid, one shared belief grid, robots, and the movement transition.

Multi-robot rules (documented in docs/environment.md):

* Robots move in sub-steps of one cell. In each sub-step they act in agent order; a robot
  whose next cell is occupied by another robot *at that moment* waits (its path is kept).
  Hence no two robots ever share a cell, and two robots can never swap cells (the first to
  act finds the other's cell occupied and waits, then so does the second).
* A robot senses at its start cell and at every cell it enters. A cell newly known in a
  sub-step is credited to the first robot (in agent order) that sensed it, so the robots'
  ``new_cells`` add up to the number of cells the team revealed.
* Paths are planned with A* on the known-free cells (other robots are not obstacles; a
  blocked robot waits). A plan is reused while the belief is unchanged and the target is the
  same, which keeps it optimal (a suffix of a shortest path is a shortest path).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from frontier_marl.core import kernels
from frontier_marl.core.frontiers import (
    Clusters,
    cluster_frontiers,
    free_components,
    nearest_cells_to_centroids,
    unknown_around,
)
from frontier_marl.core.grid import FREE, UNKNOWN, new_belief
from frontier_marl.core.maps import FOUR_CONNECTED
from frontier_marl.core.planning import astar
from frontier_marl.core.sensing import Sensor
from frontier_marl.core.slots import SlotTable, build_slots

FULL_PATH = -1  # ``cells_per_step`` value meaning "walk the whole path"


@dataclass(frozen=True)
class WorldParams:
    """Static parameters of the world transition."""

    sensor: Sensor
    cells_per_step: int  # >= 1, or FULL_PATH
    connectivity: int = 8
    max_cluster_cells: int = 0
    gain: str = "size"  # or "unknown"


@dataclass(frozen=True)
class MoveResult:
    """What one transition did, per robot."""

    new_cells: np.ndarray  # int (N,), cells first revealed by each robot
    paths: list[np.ndarray]  # per robot, (L, 2) cells occupied this step, start included
    reached: np.ndarray  # bool (N,), robot stands on its target


class World:
    """Mutable state of one episode. Read it through the read-only array properties."""

    def __init__(
        self,
        true_grid: np.ndarray,
        starts: np.ndarray,
        params: WorldParams,
        start_region: np.ndarray | None = None,
    ) -> None:
        """``start_region``: the free cells reachable from ``starts`` on ``true_grid``, if the
        caller already has them (computed here otherwise)."""
        true_grid = np.asarray(true_grid, dtype=bool)
        starts = np.asarray(starts, dtype=np.int64).reshape(-1, 2)
        if true_grid[starts[:, 0], starts[:, 1]].any():
            raise ValueError("every start cell must be free")
        if len({tuple(s) for s in starts.tolist()}) != len(starts):
            raise ValueError("start cells must be distinct")
        self.params = params
        self._true = true_grid
        self._true.setflags(write=False)
        self._belief = new_belief(true_grid.shape)
        self._positions = starts.copy()
        self._seen = np.zeros((len(starts),) + true_grid.shape, dtype=bool)
        self._travelled = np.zeros(len(starts), dtype=np.int64)
        # Per robot: (target, remaining path from the robot's cell, belief version planned on).
        self._plans: list[tuple[tuple[int, int], np.ndarray, int] | None] = [None] * len(starts)
        self._version = 0
        self._cache_version = -1
        self._cache: tuple[Clusters, np.ndarray] | None = None
        self._components_version = -1
        self._components = np.zeros(true_grid.shape, dtype=np.int32)
        self._cell_component = np.zeros(0, dtype=np.int32)
        self._passable_version = -1
        self._passable = np.zeros_like(true_grid)
        if start_region is None:
            start_region = _reachable_region(true_grid, starts)
        elif not start_region[starts[:, 0], starts[:, 1]].all():
            raise ValueError("start_region must contain every start cell")
        self._start_region = start_region
        self._start_region_size = int(np.count_nonzero(self._start_region))
        self._true_free_count = int(np.count_nonzero(~true_grid))
        self._fractions: dict[str, float] = {}
        self._fraction_version = -1
        self._targets: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._make_buffers(len(starts))
        self._make_views()
        for agent in range(len(starts)):
            self._sense(agent)

    def _make_buffers(self, n: int) -> None:
        """Arrays of the compiled ``move``: its plan cache and its outputs."""
        cells = self._true.size  # a shortest path has at most this many cells
        budget = self.params.cells_per_step
        walk = cells if budget == FULL_PATH else min(budget + 1, cells)
        self._plan_cells = np.zeros((n, cells, 2), dtype=np.int64)
        self._plan_meta = np.full((n, 5), -1, dtype=np.int64)  # see kernels.walk
        self._goals = np.full((n, 2), -1, dtype=np.int64)
        self._new_cells = np.zeros(n, dtype=np.int64)
        self._walked = np.zeros((n, walk, 2), dtype=np.int64)
        self._walked_len = np.zeros(n, dtype=np.int64)
        self._reached = np.zeros(n, dtype=bool)

    def _make_views(self) -> None:
        # Read-only views, made once: the arrays behind them are only ever changed in place.
        self._views = {
            name: _read_only(getattr(self, f"_{name}"))
            for name in ("belief", "positions", "seen", "travelled", "start_region")
        }

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        del state["_views"]  # a pickled view would become a copy, detached from its array
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._make_views()

    # ----------------------------------------------------------------- read-only state
    @property
    def true_grid(self) -> np.ndarray:
        return self._true

    @property
    def belief(self) -> np.ndarray:
        return self._views["belief"]

    @property
    def positions(self) -> np.ndarray:
        return self._views["positions"]

    @property
    def seen(self) -> np.ndarray:
        """(N, H, W) bool: cells each robot has perceived at least once."""
        return self._views["seen"]

    @property
    def travelled(self) -> np.ndarray:
        """Cells moved by each robot since the start."""
        return self._views["travelled"]

    @property
    def start_region(self) -> np.ndarray:
        """Free cells reachable from the start cells on the true grid."""
        return self._views["start_region"]

    @property
    def n_agents(self) -> int:
        return len(self._positions)

    @property
    def shape(self) -> tuple[int, int]:
        return self._true.shape

    def explored_fraction(self, basis: str) -> float:
        """Fraction of ``all`` cells known, of true-``free`` cells known free, or of the
        ``reachable`` free region known (cached until the belief changes)."""
        if self._fraction_version != self._version:
            self._fractions.clear()
            self._fraction_version = self._version
        fraction = self._fractions.get(basis)
        if fraction is None:
            fraction = self._fractions[basis] = self._compute_fraction(basis)
        return fraction

    def _compute_fraction(self, basis: str) -> float:
        belief = self._belief
        if basis == "all":
            return float(np.count_nonzero(belief != UNKNOWN)) / belief.size
        if basis == "free":
            return float(np.count_nonzero(belief == FREE)) / max(self._true_free_count, 1)
        if basis == "reachable":
            if kernels.ENABLED:
                known = kernels.count_known(belief, self._start_region)
            else:
                known = np.count_nonzero(belief[self._start_region] != UNKNOWN)
            return float(known) / max(self._start_region_size, 1)
        raise ValueError(f"threshold_basis must be 'all', 'free' or 'reachable', got {basis!r}")

    # ----------------------------------------------------------------- frontier view
    def clusters(self) -> Clusters:
        """Frontier clusters of the current belief (cached until the belief changes)."""
        return self._frontier_cache()[0]

    def cluster_gains(self) -> np.ndarray:
        return self._frontier_cache()[1]

    def slots(self, agent: int, n_slots: int, sort_by_distance: bool) -> SlotTable:
        """The cluster slots of robot ``agent`` (see :mod:`frontier_marl.core.slots`)."""
        clusters, gains = self._frontier_cache()
        if kernels.ENABLED:  # one compiled call: flood fill, targets, selection, padding
            arrays = kernels.robot_slots(
                self._belief,
                int(self._positions[agent, 0]),
                int(self._positions[agent, 1]),
                clusters.cell_rows,
                clusters.cell_cols,
                clusters.cell_cluster,
                clusters.centroids,
                clusters.sizes,
                gains,
                n_slots,
                sort_by_distance,
            )
            return SlotTable(*arrays, live=int(np.count_nonzero(arrays[1])))
        has_target, targets = self._targets_by_component(agent, clusters)
        return build_slots(
            self._positions[agent],
            clusters.centroids,
            clusters.sizes,
            gains,
            has_target,
            targets,
            n_slots,
            sort_by_distance,
        )

    def _targets_by_component(
        self, agent: int, clusters: Clusters
    ) -> tuple[np.ndarray, np.ndarray]:
        """Without kernels: per cluster, whether robot ``agent`` reaches it, and its target."""
        row, col = int(self._positions[agent, 0]), int(self._positions[agent, 1])
        # Robots in one known-free component share their targets.
        if self._components_version != self._version:
            self._components = free_components(self._belief)
            self._cell_component = self._components[clusters.cell_rows, clusters.cell_cols]
            self._targets = {}
            self._components_version = self._version
        component = int(self._components[row, col])
        found = self._targets.get(component)
        if found is None:
            found = nearest_cells_to_centroids(clusters, self._cell_component == component)
            self._targets[component] = found
        return found

    def _frontier_cache(self) -> tuple[Clusters, np.ndarray]:
        if self._cache_version != self._version or self._cache is None:
            p = self.params
            clusters = cluster_frontiers(self._belief, p.connectivity, p.max_cluster_cells)
            if p.gain == "unknown":
                gains = unknown_around(self._belief, clusters).astype(float)
            else:
                gains = clusters.sizes.astype(float)
            self._cache = (clusters, gains)
            self._cache_version = self._version
        return self._cache

    # ----------------------------------------------------------------- transition
    def plan(self, agent: int, target: tuple[int, int]) -> np.ndarray | None:
        """Shortest path (L, 2) from robot ``agent`` to ``target`` over known-free cells."""
        position = (int(self._positions[agent, 0]), int(self._positions[agent, 1]))
        cached = self._plans[agent]
        if cached is not None and cached[0] == target and cached[2] == self._version:
            path = cached[1]
            if len(path) and (int(path[0, 0]), int(path[0, 1])) == position:
                return path
        if kernels.ENABLED:  # plans on the belief directly
            found = kernels.astar_path(self._belief, FREE, *position, *target)
            path = found if len(found) else None
        else:
            if self._passable_version != self._version:
                np.equal(self._belief, FREE, out=self._passable)
                self._passable_version = self._version
            path = astar(self._passable, position, target)
        self._plans[agent] = None if path is None else (target, path, self._version)
        return path

    def move(self, targets: list[tuple[int, int] | None]) -> MoveResult:
        """Move each robot toward its target (``None`` = stay) and sense on the way.

        Each robot advances ``cells_per_step`` cells along its A* path, or all the way when
        ``cells_per_step`` is ``FULL_PATH``, stopping early at its target.
        """
        n = self.n_agents
        if len(targets) != n:
            raise ValueError(f"expected {n} targets, got {len(targets)}")
        if kernels.ENABLED:
            return self._move_compiled(targets)
        budget = self.params.cells_per_step
        stop = None if budget == FULL_PATH else budget + 1
        remaining: list[list[list[int]]] = []  # the cells this step may enter, per robot
        path_lengths: list[int] = []  # moves left to the target, per robot
        for agent, target in enumerate(targets):
            path = None if target is None else self.plan(agent, target)
            remaining.append([] if path is None else path[1:stop].tolist())
            path_lengths.append(0 if path is None else len(path) - 1)
        walked: list[list[tuple[int, int]]] = [[tuple(cell)] for cell in self._positions.tolist()]
        new_cells = [0] * n
        progress = [0] * n
        occupied = {cells[0] for cells in walked}
        sub_step = 0
        while budget == FULL_PATH or sub_step < budget:
            moved = False
            for agent in range(n):
                if progress[agent] >= len(remaining[agent]):
                    continue
                row, col = remaining[agent][progress[agent]]
                nxt = (row, col)
                if nxt in occupied:
                    continue
                occupied.discard(walked[agent][-1])
                occupied.add(nxt)
                self._positions[agent] = nxt
                walked[agent].append(nxt)
                progress[agent] += 1
                new_cells[agent] += self._sense(agent, nxt)
                moved = True
            sub_step += 1
            if not moved:
                break
        for agent in range(n):
            plan = self._plans[agent]
            if plan is not None and progress[agent]:
                self._plans[agent] = (plan[0], plan[1][progress[agent] :], plan[2])
            self._travelled[agent] += progress[agent]
        reached = np.array([0 < path_lengths[a] == progress[a] for a in range(n)])
        paths = [np.array(cells, dtype=np.int64) for cells in walked]
        return MoveResult(np.array(new_cells, dtype=np.int64), paths, reached)

    def _move_compiled(self, targets: list[tuple[int, int] | None]) -> MoveResult:
        """``move`` as one compiled call (:func:`kernels.walk`), same results."""
        goals = self._goals
        for agent, target in enumerate(targets):
            goals[agent] = (-1, -1) if target is None else target
        self._walk()
        walked, lengths = self._walked, self._walked_len.tolist()
        paths = [walked[agent, :length].copy() for agent, length in enumerate(lengths)]
        return MoveResult(self._new_cells.copy(), paths, self._reached.copy())

    def _walk(self) -> None:
        """:func:`kernels.walk` toward ``self._goals`` (row -1: stay); its outputs are left in
        ``_new_cells``, ``_walked``, ``_walked_len`` and ``_reached``."""
        offsets, between = self.params.sensor.rays
        self._version = kernels.walk(
            self._true,
            self._belief,
            self._seen,
            self._positions,
            self._travelled,
            self._goals,
            self._plan_cells,
            self._plan_meta,
            self._version,
            self.params.cells_per_step,
            offsets,
            between,
            self._new_cells,
            self._walked,
            self._walked_len,
            self._reached,
        )

    def _sense(self, agent: int, cell: tuple[int, int] | None = None) -> int:
        """Sense from robot ``agent``'s cell (given as ``cell`` when known); count new cells."""
        if cell is None:
            cell = (int(self._positions[agent, 0]), int(self._positions[agent, 1]))
        count = self.params.sensor.sense(self._true, self._belief, cell, self._seen[agent])
        if count:
            self._version += 1
        return count


def _reachable_region(true_grid: np.ndarray, starts: np.ndarray) -> np.ndarray:
    labels, _ = ndimage.label(~true_grid, structure=FOUR_CONNECTED)
    ids = np.unique(labels[starts[:, 0], starts[:, 1]])
    return np.isin(labels, ids)


def _read_only(array: np.ndarray) -> np.ndarray:
    view = array.view()
    view.setflags(write=False)
    return view
