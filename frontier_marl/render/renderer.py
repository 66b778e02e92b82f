"""Rendering for the adapters: a frame of the MDP's current state in any render mode."""

from __future__ import annotations

from typing import Any

import numpy as np

from frontier_marl.render.frames import render_ansi, render_rgb
from frontier_marl.sim.engine import ExplorationMDP

RENDER_MODES = ["human", "rgb_array", "ansi"]


def check_render_mode(render_mode: str | None) -> None:
    if render_mode is not None and render_mode not in RENDER_MODES:
        raise ValueError(f"render_mode must be one of {RENDER_MODES} or None, got {render_mode!r}")


def frame(mdp: ExplorationMDP, mode: str, cell_px: int = 12) -> Any:
    """An RGB frame (``rgb_array``/``human``, ``cell_px`` pixels per cell) or a text map
    (``ansi``) of the current state, with the last step's paths and targets."""
    world = mdp.world
    if world is None:
        raise RuntimeError("render() called before reset()")
    clusters = world.clusters()
    labels = clusters.labels()
    if mode == "ansi":
        return render_ansi(world.belief, world.positions, labels)
    last = mdp.last
    if last is None:  # right after reset: no path, no target
        paths = [cell[None, :] for cell in world.positions]
        targets = np.full((world.n_agents, 2), -1, dtype=np.int64)
    else:
        paths, targets = last.move.paths, last.targets
    return render_rgb(
        world.true_grid,
        world.belief,
        world.positions,
        cluster_labels=labels,
        centroids=clusters.centroids,
        paths=paths,
        targets=targets,
        cell_px=cell_px,
    )


class Renderer:
    """Renders the MDP in one mode; owns the matplotlib window in ``human`` mode."""

    def __init__(self, render_mode: str | None, fps: float) -> None:
        check_render_mode(render_mode)
        self.mode = render_mode
        self.fps = fps
        self._viewer: Any = None

    def render(self, mdp: ExplorationMDP) -> Any:
        if self.mode is None:
            return None
        image = frame(mdp, self.mode)
        if self.mode != "human":
            return image
        if self._viewer is None:
            from frontier_marl.render.viewer import HumanViewer

            self._viewer = HumanViewer(fps=self.fps)
        self._viewer.show(image)
        return None

    def close(self) -> None:
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None
