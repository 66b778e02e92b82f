"""The decision process shared by the PettingZoo and Gymnasium adapters.

:class:`ExplorationMDP` owns a :class:`~frontier_marl.core.world.World` and turns one action per
robot (a cluster slot index) into targets, moves the robots, applies the reward table, and
encodes the next observations. It holds no RNG of its own: ``reset`` takes a
``numpy.random.Generator`` from the adapter, so one seed fixes the whole episode.
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
from frontier_marl.core.world import FULL_PATH, World, WorldParams
from frontier_marl.observations import ObservationEncoder
from frontier_marl.rewards import OscillationDetector, StepEvents, step_outcome

Observation = np.ndarray | dict[str, np.ndarray]


class StepInfo(dict):  # type: ignore[type-arg]
    """One robot's info dict. ``copy.deepcopy`` of it is a shallow copy.

    SB3's ``DummyVecEnv`` deep-copies every info on every step, in case an env reuses and
    mutates them. This env never does: each step builds fresh values (arrays, tuples, lists of
    fresh dicts) and never touches them again, so a shallow copy is as safe. It costs ~1 µs
    where a real deep copy of this info costs ~28 µs (warm; more inside training).
    Treat the values as read-only.
    """

    __slots__ = ()

    def __deepcopy__(self, memo: dict[int, Any]) -> StepInfo:
        return StepInfo(self)


@dataclass(frozen=True)
class Transition:
    """Result of one decision step for all robots (lists are indexed by robot)."""

    observations: list[Observation]
    rewards: np.ndarray
    terminated: bool
    truncated: bool
    infos: list[dict[str, Any]]


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
        self._targets: list[tuple[int, int] | None] = []
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
        return random_obstacle_map(cfg.height, cfg.width, cfg.obstacle_prob, rng)

    def reset(self, rng: np.random.Generator) -> tuple[list[Observation], list[dict[str, Any]]]:
        """Start an episode: map, start cells in the largest free component, first sensing."""
        cfg = self.cfg
        true_grid = self.true_grid_for_episode(rng)
        if true_grid is not self._region_grid:  # a static map keeps its start region
            self._region_grid = true_grid
            self._start_region = largest_free_component(true_grid)
            self._start_region.setflags(write=False)
        starts = sample_start_cells(self._start_region, cfg.n_agents, rng)
        # Starts lie in one 4-connected component, so it is the region reachable from them.
        self.world = World(true_grid, starts, self.params, self._start_region)
        self._oscillation = [
            OscillationDetector(cfg.reward.oscillation_window) for _ in range(cfg.n_agents)
        ]
        self.steps = 0
        self.steps_without_progress = 0
        self.done = False
        self._targets = [None] * cfg.n_agents
        self._refresh_slots()
        n = cfg.n_agents
        empty_paths = [self.world.positions[i][None, :].copy() for i in range(n)]
        infos = self._infos([0] * n, empty_paths, [None] * n, [False] * n, [False] * n, "")
        return self._observations(), infos

    def step(self, actions: list[Any]) -> Transition:
        """One decision per robot: ``actions[i]`` is robot i's slot index."""
        if self.world is None or self.done:
            raise RuntimeError("step() called before reset() or after the episode ended")
        cfg = self.cfg
        n = cfg.n_agents
        if len(actions) != n:
            raise ValueError(f"expected {n} actions (one per robot), got {len(actions)}")
        targets: list[tuple[int, int] | None] = []
        padding: list[bool] = []
        for agent, action in enumerate(actions):
            slot = self._check_action(action, agent)
            table = self._slots[agent]
            if slot < table.live:  # live slots come first
                row, col = table.target[slot].tolist()
                targets.append((row, col))
                padding.append(False)
            else:
                targets.append(None)
                padding.append(table.live > 0)
        oscillation = [
            detector.update(t) for detector, t in zip(self._oscillation, targets, strict=True)
        ]
        world = self.world
        moved = world.move(targets)
        self._targets = [
            None if target is None or reached else target
            for target, reached in zip(targets, moved.reached.tolist(), strict=True)
        ]
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
        infos = self._infos(new_cells, moved.paths, targets, padding, oscillation, outcome.reason)
        return Transition(
            self._observations(), outcome.rewards, outcome.terminated, outcome.truncated, infos
        )

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
        return [table.action_mask() for table in self._slots]

    def _observations(self) -> list[Observation]:
        assert self.world is not None
        positions = self.world.positions
        mates = self._teammate_table(positions)
        return [
            self.encoder.encode(
                table,
                positions[agent],
                None if mates is None else np.delete(mates, agent, axis=0),
            )
            for agent, table in enumerate(self._slots)
        ]

    def _teammate_table(self, positions: np.ndarray) -> np.ndarray | None:
        """(N, 2) positions, or (N, 4) positions and current targets; None if not observed."""
        layout = self.cfg.observation.teammates
        if layout == "none":
            return None
        if layout == "positions":
            return positions.astype(np.float64)
        targets = np.zeros((len(positions), 2))
        for agent, target in enumerate(self._targets):
            if target is not None:
                targets[agent] = target
        return np.concatenate([positions, targets], axis=1)

    def _infos(
        self,
        new_cells: list[int],
        paths: list[np.ndarray],
        targets: list[tuple[int, int] | None],
        padding: list[bool],
        oscillation: list[bool],
        reason: str,
    ) -> list[dict[str, Any]]:
        assert self.world is not None
        world = self.world
        fraction = world.explored_fraction(self.cfg.reward.threshold_basis)
        coverage = world.explored_fraction("reachable")
        positions = world.positions.tolist()
        travelled = world.travelled.tolist()
        infos = []
        for agent, table in enumerate(self._slots):
            clusters = [
                {
                    "slot": slot,
                    "cluster": cluster,
                    "centroid": tuple(centroid),
                    "target": tuple(target),
                    "size": size,
                    "gain": gain,
                    "distance": distance,
                }
                for slot, cluster, centroid, target, size, gain, distance in zip(  # noqa: B905
                    range(table.live),  # the shortest: zip stops after the live slots
                    table.cluster.tolist(),
                    table.centroid.tolist(),
                    table.target.tolist(),
                    table.size.tolist(),
                    table.gain.tolist(),
                    table.distance.tolist(),
                )
            ]
            infos.append(
                StepInfo(
                    explored_fraction=fraction,
                    coverage=coverage,
                    new_cells=new_cells[agent],
                    action_mask=table.action_mask(),
                    clusters=clusters,
                    path=paths[agent],
                    target=targets[agent],
                    position=tuple(positions[agent]),
                    travelled=travelled[agent],
                    padding=padding[agent],
                    oscillation=oscillation[agent],
                    step=self.steps,
                    end_reason=reason,
                )
            )
        return infos
