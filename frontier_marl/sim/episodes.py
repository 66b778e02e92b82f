"""Where an episode starts: its true grid and the robots' start cells, drawn from one RNG.

Shared by the single-world engine and the batched one, so that the same seed gives the same
layout and starts in both.
"""

from __future__ import annotations

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.core.map_files import load_map
from frontier_marl.core.maps import (
    floorplan_map,
    largest_free_component,
    random_obstacle_map,
    rooms_map,
    sample_start_cells,
)
from frontier_marl.core.sensing import make_sensor
from frontier_marl.core.worlds import FULL_PATH, WorldParams


def world_params(cfg: EnvConfig) -> WorldParams:
    """The world transition's parameters of ``cfg``."""
    return WorldParams(
        sensor=make_sensor(cfg.sensor, cfg.perception_range),
        cells_per_step=FULL_PATH if cfg.walks_full_path else int(cfg.cells_per_step),
        connectivity=cfg.connectivity,
        max_cluster_cells=cfg.max_cluster_cells,
        gain=cfg.gain,
    )


class EpisodeSource:
    """Draws episode starts for ``cfg``: the layout from ``map_path``, the static one (from
    ``map_seed``) or a fresh dynamic one, and ``n_agents`` start cells (``start_cells``)."""

    def __init__(self, cfg: EnvConfig) -> None:
        self.cfg = cfg
        self._static_map: np.ndarray | None = None
        self._region_grid: np.ndarray | None = None  # the grid _start_region belongs to
        self._start_region = np.zeros((0, 0), dtype=bool)

    def true_grid(self, rng: np.random.Generator) -> np.ndarray:
        """The layout of the next episode (a static or loaded one is drawn once and kept)."""
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
        scale = cfg.map_scale
        height, width = cfg.height // scale, cfg.width // scale
        if cfg.map_generator == "rooms":
            layout = rooms_map(height, width, rng)
        elif cfg.map_generator == "floorplan":
            layout = floorplan_map(height, width, rng)
        else:
            density = cfg.obstacle_prob
            if cfg.obstacle_prob_spread > 0 and cfg.map_mode == "dynamic":
                low = max(0.0, density - cfg.obstacle_prob_spread)
                density = float(rng.uniform(low, min(0.9, density + cfg.obstacle_prob_spread)))
            layout = random_obstacle_map(height, width, density, rng)
        return layout.repeat(scale, axis=0).repeat(scale, axis=1) if scale > 1 else layout

    def draw(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """``(true_grid, starts, start_region)``: the start region is the free region
        reachable from the starts when it is known already (``None``: the world finds it)."""
        cfg = self.cfg
        true_grid = self.true_grid(rng)
        if true_grid is not self._region_grid:  # a static map keeps its start region
            self._region_grid = true_grid
            if cfg.start_cells == "any-free":
                self._start_region = ~true_grid
            else:
                self._start_region = largest_free_component(true_grid)
            self._start_region.setflags(write=False)
        starts = sample_start_cells(self._start_region, cfg.n_agents, rng)
        if cfg.start_cells == "any-free":  # the world finds the region reachable from them
            return true_grid, starts, None
        # starts in one 4-connected component: it is the region reachable from them
        return true_grid, starts, self._start_region
