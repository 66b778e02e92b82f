"""One world: world ``i`` of a :class:`~frontier_marl.core.worlds.Worlds` batch, seen alone.

``World(true_grid, starts, params)`` makes a batch of one and places the robots; the engine
hands out views of the worlds of its batch (:meth:`World.of`). Either way the state arrays are
read-only views of the batch's, and the transition is the batch's (the movement rules are those
of :mod:`frontier_marl.core.movement`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from frontier_marl.core.frontiers import Clusters
from frontier_marl.core.slots import SLOT_COLUMNS, SlotArrays, SlotTable, robot_slots
from frontier_marl.core.worlds import FULL_PATH, WorldParams, Worlds

__all__ = ["FULL_PATH", "MoveResult", "World", "WorldParams"]


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
    """The state of one episode, through read-only array properties."""

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
        worlds = Worlds(true_grid.shape, 1, len(starts), params)
        worlds.place(0, true_grid, starts, start_region)
        self._bind(worlds, 0)

    @classmethod
    def of(cls, worlds: Worlds, index: int) -> World:
        """A view of world ``index`` of ``worlds``."""
        view = cls.__new__(cls)
        view._bind(worlds, index)
        return view

    def _bind(self, worlds: Worlds, index: int) -> None:
        self._worlds = worlds
        self._index = index
        self.params = worlds.params
        self._active = np.zeros(worlds.n_worlds, dtype=bool)
        self._active[index] = True
        self._index_array = np.array([index])
        self._slots: SlotArrays | None = None  # the buffers of slot_arrays, made on first use
        self._slot_view: SlotArrays | None = None
        self._packed: np.ndarray | None = None
        self._packed_view: np.ndarray | None = None
        self._make_views()

    def _make_views(self) -> None:
        # Read-only views, made once: the batch arrays behind them are changed in place.
        w, i = self._worlds, self._index
        self._views = {
            name: _read_only(getattr(w, attribute)[i])
            for name, attribute in (
                ("true_grid", "true"),
                ("belief", "belief"),
                ("positions", "positions"),
                ("seen", "seen"),
                ("travelled", "travelled"),
                ("start_region", "start_region"),
            )
        }

    def __getstate__(self) -> dict[str, Any]:
        return {"worlds": self._worlds, "index": self._index}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self._bind(state["worlds"], state["index"])

    # ----------------------------------------------------------------- read-only state
    @property
    def true_grid(self) -> np.ndarray:
        return self._views["true_grid"]

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
    def batch(self) -> Worlds:
        """The batch this world belongs to (its state is row :attr:`index` of the arrays)."""
        return self._worlds

    @property
    def index(self) -> int:
        return self._index

    @property
    def n_agents(self) -> int:
        return self._worlds.n_agents

    @property
    def shape(self) -> tuple[int, int]:
        return self._worlds.shape

    def explored_fraction(self, basis: str) -> float:
        """Fraction of ``all`` cells known, of true-``free`` cells known free, or of the
        ``reachable`` free region known."""
        return float(self._worlds.explored_fraction(basis)[self._index])

    # ----------------------------------------------------------------- frontier view
    def clusters(self) -> Clusters:
        """Frontier clusters of the current belief."""
        self._worlds.refresh_clusters()
        return self._worlds.clusters(self._index)

    def cluster_gains(self) -> np.ndarray:
        self._worlds.refresh_clusters()
        return self._worlds.gains[self._index, : self._worlds.n_clusters[self._index]]

    def slot_arrays(self, n_slots: int, sort_by_distance: bool) -> SlotArrays:
        """The slots of every robot, ``(K, n_slots, ...)`` arrays from one compiled call, in
        buffers of this view that the next call overwrites (copy what must outlive it)."""
        if self._slots is None or self._slots.cluster.shape[-1] != n_slots:
            self._slots = SlotArrays.empty(self._worlds.n_worlds, self.n_agents, n_slots)
            self._slot_view = self._slots.world(self._index)
            self._packed = np.empty((*self._slots.cluster.shape, len(SLOT_COLUMNS)))
            self._packed_view = self._packed[self._index]
        self._worlds.slots(self._slots, self._index_array, sort_by_distance, self._packed)
        return self._slot_view

    def packed_slots(self) -> np.ndarray:
        """The slots of the last :meth:`slot_arrays` call packed, ``(K, n_slots, 10)``
        (:meth:`~frontier_marl.core.slots.SlotArrays.packed`), in a buffer it overwrites."""
        if self._packed_view is None:
            raise RuntimeError("packed_slots() comes after slot_arrays()")
        return self._packed_view

    def slots(self, agent: int, n_slots: int, sort_by_distance: bool) -> SlotTable:
        """The cluster slots of robot ``agent`` (see :mod:`frontier_marl.core.slots`)."""
        clusters = self.clusters()
        position = (self.positions[agent, 0], self.positions[agent, 1])
        return robot_slots(
            self.belief, position, clusters, self.cluster_gains(), n_slots, sort_by_distance
        )

    # ----------------------------------------------------------------- transition
    def move(self, targets: np.ndarray | list[tuple[int, int] | None]) -> MoveResult:
        """Move each robot toward its target cell and sense on the way.

        ``targets`` is (K, 2) with row -1 for a robot that stays, or a list of cells and
        ``None``. Each robot advances ``cells_per_step`` cells along its A* path, or all the
        way when ``cells_per_step`` is ``FULL_PATH``, stopping early at its target; an
        unreachable target leaves the robot in place. Only this world moves.
        """
        w, i = self._worlds, self._index
        if len(targets) != w.n_agents:
            raise ValueError(f"expected {w.n_agents} targets, got {len(targets)}")
        goals = w.goals  # only this world is active: the others' goals are not read
        if isinstance(targets, np.ndarray):
            goals[i] = targets
        else:
            for agent, target in enumerate(targets):
                goals[i, agent] = (-1, -1) if target is None else target
        w.move(goals, self._active)
        return move_result(w, i)


def move_result(worlds: Worlds, index: int) -> MoveResult:
    """World ``index``'s part of the batch's last move, as arrays of its own."""
    walked = worlds.walked[index]
    if walked.shape[1] > 16:  # a whole-path buffer: copy only the cells walked
        walked = walked[:, : max(worlds.walked_len[index].tolist())]
    return MoveResult(
        worlds.new_cells[index].copy(),
        walked.copy(),
        worlds.walked_len[index].copy(),
        worlds.reached[index].copy(),
    )


def _read_only(array: np.ndarray) -> np.ndarray:
    view = array.view()
    view.setflags(write=False)
    return view
