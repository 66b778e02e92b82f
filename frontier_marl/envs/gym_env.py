"""Single-robot Gymnasium adapter (``frontier_marl/FrontierExplore-v1``): the thesis's MDP."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from frontier_marl.config import EnvConfig
from frontier_marl.core.world import World
from frontier_marl.envs.infos import build_infos, check_info_level
from frontier_marl.envs.keywords import adapter_config
from frontier_marl.envs.layout import ObservationLayout
from frontier_marl.render.renderer import RENDER_MODES, Renderer
from frontier_marl.sim.engine import ExplorationMDP
from frontier_marl.utils.checks import check_seed


class FrontierExploreEnv(gym.Env):
    """One robot explores an unknown grid by choosing frontier clusters (the thesis's MDP).

    Same dynamics, spaces, rewards and keyword arguments as
    :class:`~frontier_marl.envs.parallel.FrontierParallelEnv` with ``n_agents=1``; the info
    dict has the same keys, and ``obs_layout`` places the mask alike. See that class's
    docstring for the full description.

    **Version history.** v1: numeric fixed-shape infos, the classic mask layout, ``TypeError``
    for unknown keywords. v0: first release.
    """

    metadata = {"render_modes": RENDER_MODES, "render_fps": 4}

    def __init__(
        self,
        preset: str | None = "thesis-20x20",
        render_mode: str | None = None,
        info: str = "full",
        obs_layout: str = "classic",
        **kwargs: Any,
    ) -> None:
        self._renderer = Renderer(render_mode, self.metadata["render_fps"])
        self._info_level = check_info_level(info)
        config = adapter_config(type(self).__name__, preset, kwargs)
        if config.n_agents != 1:
            raise ValueError(
                f"n_agents must be 1 for the single-agent Gymnasium env, got {config.n_agents}; "
                "use frontier_marl.parallel_env for teams"
            )
        self.config: EnvConfig = config
        self.render_mode = render_mode
        self._mdp = ExplorationMDP(config)
        self.layout = ObservationLayout(self._mdp.encoder.space, obs_layout)
        self.observation_space = self.layout.space
        self.action_space = spaces.Discrete(config.n_slots)

    @property
    def world(self) -> World:
        """The current world (read-only arrays: ``true_grid``, ``belief``, ``positions``...)."""
        if self._mdp.world is None:
            raise RuntimeError("the world exists after reset()")
        return self._mdp.world

    @property
    def mdp(self) -> ExplorationMDP:
        return self._mdp

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        super().reset(seed=check_seed(seed, "reset(seed=...)"))
        observations = self._mdp.reset(self.np_random)
        if self.render_mode == "human":
            self.render()
        return self.layout.wrap(observations[0]), build_infos(self._mdp, None, self._info_level)[0]

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        result = self._mdp.step([action])
        if self.render_mode == "human":
            self.render()
        return (
            self.layout.wrap(result.observations[0]),
            float(result.rewards[0]),
            result.terminated,
            result.truncated,
            build_infos(self._mdp, result, self._info_level)[0],
        )

    def action_masks(self) -> np.ndarray:
        """Valid slots as bools (the sb3-contrib ``MaskablePPO`` convention)."""
        return self._mdp.action_masks()[0].astype(bool)

    def render(self) -> Any:
        return self._renderer.render(self._mdp)

    def close(self) -> None:
        self._renderer.close()
