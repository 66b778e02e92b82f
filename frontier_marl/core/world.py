"""The world: true grid, one shared belief grid, robots, and the movement transition.

The movement rules are those of :mod:`frontier_marl.core.movement`; this module keeps the state
of one episode and caches what depends only on the belief (clusters, gains, explored fractions)
until the belief changes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from frontier_marl.core.compiled import compiled
from frontier_marl.core.frontiers import Clusters, cluster_frontiers, unknown_around
from frontier_marl.core.grid import FREE, UNKNOWN, new_belief
from frontier_marl.core.maps import FOUR_CONNECTED
from frontier_marl.core.movement import walk
from frontier_marl.core.sensing import Sensor
from frontier_marl.core.slots import SlotTable, robot_slots

FULL_PATH = -1  # ``cells_per_step`` value meaning "walk the whole path"


@dataclass(frozen=True)
class WorldParams:
    """Static parameters of the world transition."""

    sensor: Sensor
    cells_per_step: int  # >= 1, or FULL_PATH
    connectivity: int = 8
    max_cluster_cells: int = 0
    gain: str = "size"  # or "unknown"


@dataclass(slots=True)
class MoveResult:
    """What one transition did, per robot (arrays owned by the result)."""

    new_cells: np.ndarray  # int (N,), cells first revealed by each robot
    walked: np.ndarray  # int (N, L, 2): robot a occupied walked[a, :walked_len[a]], start first
    walked_len: np.ndarray  # int (N,)
    reached: np.ndarray  # bool (N,), robot stands on its target

    def path(self, agent: int) -> np.ndarray:
        """(L, 2) cells robot ``agent`` occupied this step, its start cell first."""
        return self.walked[agent, : self.walked_len[agent]]

    @property
    def paths(self) -> list[np.ndarray]:
        return [self.path(agent) for agent in range(len(self.walked_len))]


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
        self._version = 0  # bumped whenever the belief changes
        self._cache_version = -1
        self._cache: tuple[Clusters, np.ndarray] | None = None
        if start_region is None:
            start_region = _reachable_region(true_grid, starts)
        elif not start_region[starts[:, 0], starts[:, 1]].all():
            raise ValueError("start_region must contain every start cell")
        self._start_region = start_region
        self._start_region_size = int(np.count_nonzero(self._start_region))
        self._true_free_count = int(np.count_nonzero(~true_grid))
        self._fractions: dict[str, float] = {}
        self._fraction_version = -1
        self._make_buffers(len(starts))
        self._make_views()
        for agent in range(len(starts)):
            self._sense(agent)

    def _make_buffers(self, n: int) -> None:
        """Arrays of the compiled walk: its plan cache and its outputs."""
        cells = self._true.size  # a shortest path has at most this many cells
        budget = self.params.cells_per_step
        walk_cells = cells if budget == FULL_PATH else min(budget + 1, cells)
        self._plan_cells = np.zeros((n, cells, 2), dtype=np.int64)
        self._plan_meta = np.full((n, 5), -1, dtype=np.int64)  # see movement.walk
        self._goals = np.full((n, 2), -1, dtype=np.int64)
        self._new_cells = np.zeros(n, dtype=np.int64)
        self._walked = np.zeros((n, walk_cells, 2), dtype=np.int64)
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
            known = count_known(belief, self._start_region)
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
        position = (self._positions[agent, 0], self._positions[agent, 1])
        return robot_slots(self._belief, position, clusters, gains, n_slots, sort_by_distance)

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
    def move(self, targets: np.ndarray | list[tuple[int, int] | None]) -> MoveResult:
        """Move each robot toward its target cell and sense on the way.

        ``targets`` is (N, 2) with row -1 for a robot that stays, or a list of cells and
        ``None``. Each robot advances ``cells_per_step`` cells along its A* path, or all the
        way when ``cells_per_step`` is ``FULL_PATH``, stopping early at its target; an
        unreachable target leaves the robot in place.
        """
        n = self.n_agents
        if len(targets) != n:
            raise ValueError(f"expected {n} targets, got {len(targets)}")
        if isinstance(targets, np.ndarray):
            self._goals[:] = targets
        else:
            for agent, target in enumerate(targets):
                self._goals[agent] = (-1, -1) if target is None else target
        self._walk()
        walked = self._walked
        if walked.shape[1] > 16:  # a whole-path buffer: copy only the cells walked
            walked = walked[:, : int(self._walked_len.max())]
        return MoveResult(
            self._new_cells.copy(), walked.copy(), self._walked_len.copy(), self._reached.copy()
        )

    def _walk(self) -> None:
        """:func:`movement.walk` toward ``self._goals`` (row -1: stay); its outputs are left in
        ``_new_cells``, ``_walked``, ``_walked_len`` and ``_reached``."""
        offsets, between = self.params.sensor.rays
        self._version = walk(
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

    def _sense(self, agent: int) -> int:
        """Sense from robot ``agent``'s cell; count the new cells."""
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


@compiled
def count_known(belief: np.ndarray, region: np.ndarray) -> int:
    """Known cells of ``belief`` inside the bool mask ``region``."""
    count = 0
    for r in range(belief.shape[0]):
        for c in range(belief.shape[1]):
            if region[r, c] and belief[r, c] != UNKNOWN:
                count += 1
    return count
