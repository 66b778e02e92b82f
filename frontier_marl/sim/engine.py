"""The decision process of one world, for the PettingZoo and Gymnasium adapters.

:class:`ExplorationMDP` is a batch of one: it owns a
:class:`~frontier_marl.sim.batch_engine.BatchMDP` of one world, whose ``step`` is the only
implementation of the transition (actions to targets, the walk, the slots, the reward table,
the observations), and presents it as one world: its step takes one action per robot and returns
typed arrays of its own (:class:`StepResult`); the adapters build their info dicts from those
(:mod:`frontier_marl.envs.infos`). It holds no RNG of its own: ``reset`` takes a
``numpy.random.Generator`` from the adapter, so one seed fixes the whole episode.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.core.slots import SlotArrays, SlotTable
from frontier_marl.core.world import MoveResult, World, move_result
from frontier_marl.sim.batch_engine import BatchMDP
from frontier_marl.sim.rewards import StepOutcome, first_outcome

Observation = np.ndarray | dict[str, np.ndarray]
_ONE = np.ones(1, dtype=bool)  # the active flags of a batch of one world
_FIRST = np.zeros(1, dtype=np.int64)  # its index


@dataclass(slots=True)
class StepResult:
    """One decision step of every robot, as arrays indexed by robot (read-only by convention).

    ``targets`` holds the cell each robot headed for (row -1: it idled); ``padding`` whether it
    chose a padding slot while a live one existed; ``move`` what the walk did (new cells,
    paths, whether each robot reached its target); ``outcome`` the rewards and the episode end.
    """

    observations: list[Observation]
    targets: np.ndarray  # int (N, 2)
    padding: np.ndarray  # bool (N,)
    oscillation: np.ndarray  # bool (N,)
    move: MoveResult
    outcome: StepOutcome

    @property
    def rewards(self) -> np.ndarray:
        return self.outcome.rewards

    @property
    def terminated(self) -> bool:
        return self.outcome.terminated

    @property
    def truncated(self) -> bool:
        return self.outcome.truncated


class ExplorationMDP:
    """Frontier-selection MDP for ``cfg.n_agents`` robots on one shared belief grid."""

    def __init__(self, cfg: EnvConfig) -> None:
        self.cfg = cfg
        self.batch = BatchMDP(cfg, 1)
        self.encoder = self.batch.encoder
        self.world: World | None = None  # a view of the batch's world, made at the first reset
        self.last: StepResult | None = None  # the latest step, None right after reset
        self._tables: list[SlotTable] | None = None  # views of the slots, made when asked
        self._agents = range(cfg.n_agents)
        self._actions = np.zeros((1, cfg.n_agents), dtype=np.int64)  # the step's slot indices
        self._make_views()

    def _make_views(self) -> None:
        """The batch's slots as views of its only world, made once (and again after a copy:
        a copied view would no longer see the batch)."""
        self._slots = self.batch.slots.world(0)  # (N, n_slots) views
        self._packed = self.batch.packed[0]

    def __getstate__(self) -> dict[str, Any]:
        return {k: v for k, v in self.__dict__.items() if k not in ("_slots", "_packed")}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._make_views()

    @property
    def steps(self) -> int:
        return int(self.batch.steps[0])

    @property
    def steps_without_progress(self) -> int:
        return int(self.batch.steps_without_progress[0])

    @property
    def done(self) -> bool:
        return bool(self.batch.done[0])

    @property
    def explored(self) -> float:
        """The explored fraction on the reward's threshold basis, now."""
        return float(self.batch.explored[0])

    # ------------------------------------------------------------------ episode
    def reset(self, rng: np.random.Generator) -> list[Observation]:
        """Start an episode: map, start cells (``start_cells``), first sensing."""
        self.batch.rngs[0] = rng
        self.batch.reset_worlds(_FIRST)
        if self.world is None:
            self.world = World.of(self.batch.worlds, 0)
        self.last = None
        self._tables = None
        return self._observations()

    def step(self, actions: list[Any]) -> StepResult:
        """One decision per robot: ``actions[i]`` is robot i's slot index."""
        if self.world is None or self.done:
            raise RuntimeError("step() called before reset() or after the episode ended")
        n = self.cfg.n_agents
        if len(actions) != n:
            raise ValueError(f"expected {n} actions (one per robot), got {len(actions)}")
        slots = self._actions
        for agent, action in enumerate(actions):
            slots[0, agent] = self._check_action(action, agent)
        batch = self.batch
        batch.step(slots, _ONE)
        self._tables = None
        self.last = StepResult(
            self._observations(),
            batch.targets[0].copy(),
            batch.padding[0].copy(),
            batch.oscillation[0].copy(),
            move_result(batch.worlds, 0),
            first_outcome(batch.outcome),
        )
        return self.last

    # ------------------------------------------------------------------ helpers
    def _check_action(self, action: Any, agent: int) -> int:
        if type(action) is int and 0 <= action < self.cfg.n_slots:  # the common case, fast
            return action
        value = action
        if isinstance(value, np.ndarray):
            if value.size != 1:
                raise ValueError(
                    f"action of robot {agent} must be one integer slot index, "
                    f"got an array of shape {value.shape}"
                )
            value = value.reshape(()).item()
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise TypeError(
                f"action of robot {agent} must be an integer slot index, "
                f"got {type(action).__name__} {action!r}"
            )
        if not 0 <= value < self.cfg.n_slots:
            raise ValueError(
                f"action of robot {agent} must be in [0, {self.cfg.n_slots - 1}] "
                f"(n_slots={self.cfg.n_slots}), got {value}"
            )
        return int(value)

    def slot_tables(self) -> list[SlotTable]:
        """The slot tables the robots observe now (the ones their next actions refer to):
        views of buffers that the next step overwrites."""
        if self._tables is None:
            self._tables = [self._slots.table(agent) for agent in self._agents]
        return list(self._tables)

    def slot_arrays(self) -> SlotArrays:
        """The robots' slots as ``(N, ...)`` arrays (those of :meth:`slot_tables`; views of
        buffers that the next step overwrites)."""
        return self._slots

    def packed_slots(self) -> np.ndarray:
        """The robots' slots packed, ``(N, n_slots, 10)`` (a fresh copy of
        :meth:`~frontier_marl.core.slots.SlotArrays.packed` of :meth:`slot_arrays`)."""
        return self._packed.copy()

    def action_masks(self) -> list[np.ndarray]:
        """Per robot, int8 mask of valid slots; with no live slot, slot 0 (idle) is valid."""
        mask = self._slots.mask
        return [mask[agent].copy() for agent in self._agents]

    def _observations(self) -> list[Observation]:
        """Every robot's observation, of the batch's only world."""
        batch = self.batch.robot_observations()
        if isinstance(batch, dict):
            items = batch.items()
            return [{key: value[agent] for key, value in items} for agent in self._agents]
        return list(batch)
