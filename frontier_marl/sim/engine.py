"""The decision process shared by the PettingZoo and Gymnasium adapters.

:class:`ExplorationMDP` owns a :class:`~frontier_marl.core.world.World` and turns one action per
robot (a cluster slot index) into targets, moves the robots, applies the reward table, and
encodes the next observations. Its step returns typed arrays (:class:`StepResult`); the
adapters build their info dicts from those (:mod:`frontier_marl.envs.infos`). It holds no RNG of
its own: ``reset`` takes a ``numpy.random.Generator`` from the adapter, so one seed fixes the
whole episode.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.core.slots import SlotArrays, SlotTable, commit_to_previous
from frontier_marl.core.world import MoveResult, World
from frontier_marl.sim.decisions import decide, heading_of
from frontier_marl.sim.episodes import EpisodeSource, world_params
from frontier_marl.sim.motion import MotionTrail
from frontier_marl.sim.observations import ObservationEncoder, observed_heading, teammate_rows
from frontier_marl.sim.rewards import (
    BatchOutcome,
    OscillationHistory,
    StepOutcome,
    batch_outcome,
    first_outcome,
)

Observation = np.ndarray | dict[str, np.ndarray]
_ONE = np.ones(1, dtype=bool)  # the active flags of a batch of one world


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
        self.encoder = ObservationEncoder(cfg)
        self.params = world_params(cfg)
        self.source = EpisodeSource(cfg)
        self.world: World | None = None
        self._slot_arrays: SlotArrays | None = None
        self._packed: np.ndarray | None = None  # the same slots, packed
        self._batch_slots: tuple[np.ndarray, ...] = ()  # live and target as a batch of one
        self._tables: list[SlotTable] | None = None  # views of the arrays, made when asked
        self._oscillation = OscillationHistory(1, cfg.n_agents, cfg.reward.oscillation_window)
        self._trail = MotionTrail(1, cfg.n_agents) if cfg.observation.turn else None
        self.last: StepResult | None = None  # the latest step, None right after reset
        obs = cfg.observation  # what the observations read, fixed by the config
        self._heads = obs.features == "explorer" or obs.teammates == "positions+targets"
        self._no_mates = obs.teammates == "none"
        self._agents = range(cfg.n_agents)
        # The reward table's per-world inputs, (1,) arrays refilled every step.
        self._threshold, self._no_frontier = np.zeros(1, dtype=bool), np.zeros(1, dtype=bool)
        self._steps, self._stalled = np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64)
        self._ends = BatchOutcome(  # its outputs: fresh rewards each step, the rest reused
            np.zeros((1, cfg.n_agents)), np.zeros(1, bool), np.zeros(1, bool), np.zeros(1, np.int64)
        )
        self.steps = 0
        self.steps_without_progress = 0
        self.explored = 0.0  # the explored fraction on the threshold's basis, now
        self.done = True

    # ------------------------------------------------------------------ episode
    def reset(self, rng: np.random.Generator) -> list[Observation]:
        """Start an episode: map, start cells (``start_cells``), first sensing."""
        true_grid, starts, start_region = self.source.draw(rng)
        self.world = World(true_grid, starts, self.params, start_region)
        self._oscillation.clear(slice(None))
        if self._trail is not None:
            self._trail.clear(slice(None), self.world.positions[None])
        self.steps = 0
        self.steps_without_progress = 0
        self.explored = self.world.explored_fraction(self.cfg.reward.threshold_basis)
        self.done = False
        self.last = None
        self._refresh_slots()
        return self._observations(None, None)

    def step(self, actions: list[Any]) -> StepResult:
        """One decision per robot: ``actions[i]`` is robot i's slot index."""
        if self.world is None or self.done:
            raise RuntimeError("step() called before reset() or after the episode ended")
        cfg = self.cfg
        n = cfg.n_agents
        if len(actions) != n:
            raise ValueError(f"expected {n} actions (one per robot), got {len(actions)}")
        slots = np.array(
            [self._check_action(action, agent) for agent, action in enumerate(actions)],
            dtype=np.int64,
        )
        chosen = self._decide(slots)
        targets, padding, oscillation = chosen[0][0], chosen[1][0], chosen[2][0]
        world = self.world
        before = world.travelled.copy() if cfg.reward.kind == "travel" else None
        if self._trail is not None:
            self._trail.push(world.positions[None], _ONE)
        moved = world.move(targets)
        self.steps += 1
        new_cells = moved.new_cells
        progress = np.count_nonzero(new_cells) > 0  # faster than any() on a few cells
        self.steps_without_progress = 0 if progress else self.steps_without_progress + 1
        self._refresh_slots()
        if cfg.observation.commit != "none":
            self._commit(targets, new_cells)
        travel = None if before is None else world.travelled - before
        outcome = self._outcome(new_cells, chosen[1], chosen[2], travel)
        self.done = outcome.terminated or outcome.truncated
        self.last = StepResult(
            self._observations(targets, moved.reached),
            targets,
            padding,
            oscillation,
            moved,
            outcome,
        )
        return self.last

    # ------------------------------------------------------------------ helpers
    def _decide(self, slots: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Targets (1, N, 2), padding and oscillation flags (1, N) of the chosen ``slots``
        (fresh arrays, a batch of one world)."""
        n = len(slots)
        targets = np.empty((1, n, 2), dtype=np.int64)
        padding, oscillation = np.empty((1, n), dtype=bool), np.empty((1, n), dtype=bool)
        history = self._oscillation.history
        decide(*self._batch_slots, slots[None], _ONE, history, targets, padding, oscillation)
        return targets, padding, oscillation

    def _commit(self, targets: np.ndarray, new_cells: np.ndarray) -> None:
        """Narrow the action masks to the previous targets (the ``commit`` rule)."""
        arrays = self._slot_arrays
        assert arrays is not None
        arrays.mask[:] = commit_to_previous(
            arrays.mask,
            arrays.target,
            arrays.valid,
            targets,
            new_cells > 0,
            self.cfg.observation.commit,
        )

    def _outcome(
        self,
        new_cells: np.ndarray,
        padding: np.ndarray,
        oscillation: np.ndarray,
        travel: np.ndarray | None,
    ) -> StepOutcome:
        """The reward table on this step: ``padding`` and ``oscillation`` (1, N) as
        :meth:`_decide` gives them, the world's scalars in persistent arrays."""
        assert self.world is not None and self._slot_arrays is not None
        reward = self.cfg.reward
        fraction = self.explored = self.world.explored_fraction(reward.threshold_basis)
        self._threshold[0] = fraction >= reward.explore_threshold
        self._no_frontier[0] = not np.count_nonzero(self._slot_arrays.live)
        self._steps[0], self._stalled[0] = self.steps, self.steps_without_progress
        self._ends.rewards = np.empty((1, len(new_cells)))  # fresh: the result holds them
        outcome = batch_outcome(
            reward,
            new_cells[None],
            padding,
            oscillation,
            self._threshold,
            self._no_frontier,
            self._steps,
            self._stalled,
            None if travel is None else travel[None],
            self._ends,
        )
        return first_outcome(outcome)

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

    def _refresh_slots(self) -> None:
        assert self.world is not None
        sort = self.cfg.observation.sort_by_distance
        arrays = self.world.slot_arrays(self.cfg.n_slots, sort)
        if arrays is not self._slot_arrays:  # new buffers (a new world): new views of them
            self._slot_arrays, self._packed = arrays, self.world.packed_slots()
            self._batch_slots = (arrays.live[None], arrays.target[None])
        self._tables = None

    def slot_tables(self) -> list[SlotTable]:
        """The slot tables the robots observe now (the ones their next actions refer to):
        views of buffers that the next step overwrites."""
        if self._tables is None:
            arrays = self._slot_arrays
            assert arrays is not None
            self._tables = [arrays.table(agent) for agent in range(self.cfg.n_agents)]
        return list(self._tables)

    def slot_arrays(self) -> SlotArrays:
        """The robots' slots as ``(N, ...)`` arrays (those of :meth:`slot_tables`; views of
        buffers that the next step overwrites)."""
        assert self._slot_arrays is not None
        return self._slot_arrays

    def packed_slots(self) -> np.ndarray:
        """The robots' slots packed, ``(N, n_slots, 10)`` (a fresh copy of
        :meth:`~frontier_marl.core.slots.SlotArrays.packed` of :meth:`slot_arrays`)."""
        assert self._packed is not None
        return self._packed.copy()

    def action_masks(self) -> list[np.ndarray]:
        """Per robot, int8 mask of valid slots; with no live slot, slot 0 (idle) is valid."""
        assert self._slot_arrays is not None
        mask = self._slot_arrays.mask
        return [mask[agent].copy() for agent in range(len(mask))]

    def _observations(
        self, targets: np.ndarray | None, reached: np.ndarray | None
    ) -> list[Observation]:
        """Every robot's observation; ``targets`` and ``reached`` of the step just taken (None
        after reset) give the teammates' current targets."""
        assert self.world is not None
        positions = self.world.positions
        heading = self._heading(targets, reached) if self._heads else None  # read by those
        mates = None if self._no_mates else self._teammate_table(positions, heading)
        motion = None if self._trail is None else self._trail.motion(0, positions)
        batch = self.encoder.encode_batch(
            self._slot_arrays,
            positions,
            None if mates is None else teammate_rows(mates),
            heading,
            motion,
            self._beliefs(),
        )
        if isinstance(batch, dict):
            items = batch.items()
            return [{key: value[agent] for key, value in items} for agent in self._agents]
        return list(batch)

    def _beliefs(self) -> np.ndarray | None:
        """The robots' shared belief map, (1, H, W), for the ``unknown_near`` feature."""
        if not self.cfg.observation.unknown_near:
            return None
        assert self.world is not None
        return self.world.belief[None]

    def _heading(self, targets: np.ndarray | None, reached: np.ndarray | None) -> np.ndarray:
        """(N, 2) the cells the robots are heading to: the step's targets not reached yet
        (row -1: none, as before the first decision)."""
        if targets is None or reached is None:
            return np.full((self.cfg.n_agents, 2), -1, dtype=np.int64)
        heading = np.empty_like(targets)
        heading_of(targets[None], reached[None], heading[None])
        return heading

    def _teammate_table(
        self, positions: np.ndarray, heading: np.ndarray | None
    ) -> np.ndarray | None:
        """(N, 2) positions, or (N, 4) positions and current targets (where a robot has none:
        before its first decision, idle, or on its target, see :func:`observed_heading`); None
        if not observed."""
        layout = self.cfg.observation.teammates
        if layout == "none":
            return None
        if layout == "positions":
            return positions.astype(np.float64)
        assert heading is not None
        heading = observed_heading(heading, self.cfg.observation.features)
        return np.concatenate([positions, heading], axis=1).astype(np.float64)
