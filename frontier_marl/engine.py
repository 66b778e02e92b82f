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
from frontier_marl.core.map_files import load_map
from frontier_marl.core.maps import (
    largest_free_component,
    random_obstacle_map,
    rooms_map,
    sample_start_cells,
)
from frontier_marl.core.sensing import make_sensor
from frontier_marl.core.slots import SlotTable
from frontier_marl.core.world import FULL_PATH, MoveResult, World, WorldParams
from frontier_marl.observations import ObservationEncoder
from frontier_marl.rewards import OscillationDetector, StepEvents, StepOutcome, step_outcome

Observation = np.ndarray | dict[str, np.ndarray]


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
        self.params = WorldParams(
            sensor=make_sensor(cfg.sensor, cfg.perception_range),
            cells_per_step=FULL_PATH if cfg.walks_full_path else int(cfg.cells_per_step),
            connectivity=cfg.connectivity,
            max_cluster_cells=cfg.max_cluster_cells,
            gain=cfg.gain,
        )
        self._static_map: np.ndarray | None = None
        self._region_grid: np.ndarray | None = None  # the grid _start_region belongs to
        self._start_region = np.zeros((0, 0), dtype=bool)
        self.world: World | None = None
        self._slots: list[SlotTable] = []
        self._oscillation: list[OscillationDetector] = []
        self.last: StepResult | None = None  # the latest step, None right after reset
        self.steps = 0
        self.steps_without_progress = 0
        self.done = True

    # ------------------------------------------------------------------ episode
    def true_grid_for_episode(self, rng: np.random.Generator) -> np.ndarray:
        """The layout from ``map_path``, the static one (from ``map_seed``), or a fresh dynamic
        one (from ``rng``)."""
        cfg = self.cfg
        if cfg.map_path is not None:
            if self._static_map is None:
                self._static_map = load_map(cfg.map_path)
            return self._static_map
        if cfg.map_mode == "static":
            if self._static_map is None:
                self._static_map = self._generate(np.random.default_rng(cfg.map_seed))
            return self._static_map
        return self._generate(rng)

    def _generate(self, rng: np.random.Generator) -> np.ndarray:
        cfg = self.cfg
        if cfg.map_generator == "rooms":
            return rooms_map(cfg.height, cfg.width, rng)
        density = cfg.obstacle_prob
        if cfg.obstacle_prob_spread > 0 and cfg.map_mode == "dynamic":
            low = max(0.0, density - cfg.obstacle_prob_spread)
            density = float(rng.uniform(low, min(0.9, density + cfg.obstacle_prob_spread)))
        return random_obstacle_map(cfg.height, cfg.width, density, rng)

    def reset(self, rng: np.random.Generator) -> list[Observation]:
        """Start an episode: map, start cells (``start_cells``), first sensing."""
        cfg = self.cfg
        true_grid = self.true_grid_for_episode(rng)
        if true_grid is not self._region_grid:  # a static map keeps its start region
            self._region_grid = true_grid
            if cfg.start_cells == "any-free":
                self._start_region = ~true_grid
            else:
                self._start_region = largest_free_component(true_grid)
            self._start_region.setflags(write=False)
        starts = sample_start_cells(self._start_region, cfg.n_agents, rng)
        if cfg.start_cells == "any-free":  # the world finds the region reachable from them
            self.world = World(true_grid, starts, self.params)
        else:  # starts in one 4-connected component: it is the region reachable from them
            self.world = World(true_grid, starts, self.params, self._start_region)
        self._oscillation = [
            OscillationDetector(cfg.reward.oscillation_window) for _ in range(cfg.n_agents)
        ]
        self.steps = 0
        self.steps_without_progress = 0
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
        slots = [self._check_action(action, agent) for agent, action in enumerate(actions)]
        goals: list[tuple[int, int] | None] = []
        padding: list[bool] = []
        oscillation: list[bool] = []
        for slot, table, detector in zip(slots, self._slots, self._oscillation, strict=True):
            if slot < table.live:  # live slots come first
                row, col = table.target[slot].tolist()
                goals.append((row, col))
                padding.append(False)
            else:
                goals.append(None)
                padding.append(table.live > 0)
            oscillation.append(detector.update(goals[-1]))
        world = self.world
        moved = world.move(goals)
        self.steps += 1
        new_cells = moved.new_cells.tolist()
        self.steps_without_progress = 0 if any(new_cells) else self.steps_without_progress + 1
        self._refresh_slots()
        fraction = world.explored_fraction(cfg.reward.threshold_basis)
        events = StepEvents(
            new_cells=new_cells,
            padding=padding,
            oscillation=oscillation,
            threshold_reached=fraction >= cfg.reward.explore_threshold,
            no_frontier_left=not any(table.live for table in self._slots),
            steps_taken=self.steps,
            steps_without_progress=self.steps_without_progress,
        )
        outcome = step_outcome(cfg.reward, events)
        self.done = outcome.terminated or outcome.truncated
        targets = np.array([(-1, -1) if goal is None else goal for goal in goals], dtype=np.int64)
        self.last = StepResult(
            self._observations(targets, moved.reached),
            targets,
            np.array(padding),
            np.array(oscillation),
            moved,
            outcome,
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

    def _refresh_slots(self) -> None:
        assert self.world is not None
        sort = self.cfg.observation.sort_by_distance
        self._slots = [
            self.world.slots(agent, self.cfg.n_slots, sort) for agent in range(self.cfg.n_agents)
        ]

    def slot_tables(self) -> list[SlotTable]:
        """The slot tables the robots observe now (the ones their next actions refer to)."""
        return list(self._slots)

    def action_masks(self) -> list[np.ndarray]:
        """Per robot, int8 mask of valid slots; with no live slot, slot 0 (idle) is valid."""
        return [table.mask for table in self._slots]

    def _observations(
        self, targets: np.ndarray | None, reached: np.ndarray | None
    ) -> list[Observation]:
        """Every robot's observation; ``targets`` and ``reached`` of the step just taken (None
        after reset) give the teammates' current targets."""
        assert self.world is not None
        positions = self.world.positions
        mates = self._teammate_table(positions, targets, reached)
        return [
            self.encoder.encode(
                table,
                positions[agent],
                None if mates is None else np.delete(mates, agent, axis=0),
            )
            for agent, table in enumerate(self._slots)
        ]

    def _teammate_table(
        self, positions: np.ndarray, targets: np.ndarray | None, reached: np.ndarray | None
    ) -> np.ndarray | None:
        """(N, 2) positions, or (N, 4) positions and current targets (zeros where a robot has
        none: before its first decision, idle, or on its target); None if not observed."""
        layout = self.cfg.observation.teammates
        if layout == "none":
            return None
        if layout == "positions":
            return positions.astype(np.float64)
        heading = np.zeros((len(positions), 2))
        if targets is not None:
            going = (targets[:, 0] >= 0) & ~reached
            heading[going] = targets[going]
        return np.concatenate([positions, heading], axis=1)
