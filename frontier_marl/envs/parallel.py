"""PettingZoo ParallelEnv adapter over :class:`~frontier_marl.sim.engine.ExplorationMDP`."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from frontier_marl.config import EnvConfig
from frontier_marl.core.world import World
from frontier_marl.envs.infos import build_infos, check_info_level
from frontier_marl.envs.keywords import adapter_config
from frontier_marl.envs.layout import ObservationLayout
from frontier_marl.render.renderer import RENDER_MODES, Renderer
from frontier_marl.sim.engine import ExplorationMDP
from frontier_marl.utils.checks import check_seed


class FrontierParallelEnv(ParallelEnv):
    """Frontier-based exploration by N robots sharing one belief grid (frontier_explore_v1).

    **Description.** A team of robots explores an unknown 2D grid. At each decision step every
    robot picks one *slot*: a frontier cluster (contiguous known-free cells next to unknown
    ones). A* plans a path to the cluster's target cell over known-free cells; the robot walks
    ``cells_per_step`` cells of it (or all of it) and senses at every cell it enters. All robots
    write into one shared belief grid. With one robot this is exactly the thesis's MDP.

    **Agents.** ``robot_0`` ... ``robot_{N-1}``; all act every step; all leave together.

    **Action space.** ``Discrete(n_slots)``: the slot index. Slots beyond the live clusters are
    padding: choosing one is legal and is handled by the reward table. The valid slots are in
    ``info[agent]["action_mask"]`` (and in the observation when ``action_mask=True``).

    **Observation space.** A flat ``Box`` of ``n_slots x F`` slot features, or a ``Dict`` with
    ``clusters`` and ``agent_position`` keys; see :mod:`frontier_marl.sim.observations`. With
    ``action_mask=True`` (and in the explorer layout), PettingZoo's classic
    ``{"observation": ..., "action_mask": ...}`` (``obs_layout="classic"``, the default) or
    the mask beside the other keys (``obs_layout="flat"``, what SB3 routes and saved models
    use); see :mod:`frontier_marl.envs.layout`.

    **Rewards.** Reward 1 or Reward 2 of the thesis (:mod:`frontier_marl.sim.rewards`).

    **Starting state.** The static layout (``map_seed``) or a fresh random layout (dynamic);
    robots start on distinct random cells of the largest free component and sense there.

    **Episode end.** Terminated when the explored fraction reaches ``explore_threshold`` or no
    robot has a reachable frontier left; truncated by the step limit, by ``no_progress_limit``
    steps without a new cell, or (Reward 1) by a padding action.

    **Arguments.** ``preset`` (``thesis-20x20``, ``thesis-30x30``, ``rooms-32``),
    ``render_mode``, ``info`` (``mask``, ``minimal``, ``full``, ``debug``), ``obs_layout``
    (``classic`` or ``flat``), and any field of :class:`~frontier_marl.config.EnvConfig` /
    ``ObservationConfig`` / ``RewardConfig`` as a flat keyword (``config=EnvConfig(...)`` also
    works; ``max_cycles`` is PettingZoo's name for ``max_steps``). Every value is validated at
    construction; an unknown keyword raises ``TypeError``.

    **Info.** Per agent, numbers and fixed-shape arrays only (:mod:`frontier_marl.envs.infos`):
    ``explored_fraction``, ``coverage`` (of the reachable free region), ``new_cells``,
    ``action_mask``, ``slots`` (the robot's slot table, packed), ``target`` (-1: none),
    ``position``, ``travelled``, ``padding``, ``oscillation``, ``step``, ``end_reason`` (a
    code); ``info="minimal"`` keeps only the scalars training needs and the mask, ``"mask"``
    the mask, ``"debug"`` adds ``path``. A ``StepInfo`` dict whose deep copy is shallow (treat
    it as read-only).

    **Version history.** v1: numeric fixed-shape infos, the classic mask layout, ``TypeError``
    for unknown keywords, ``max_cycles``. v0: first release.
    """

    metadata = {
        "name": "frontier_explore_v1",
        "render_modes": RENDER_MODES,
        "render_fps": 4,
        "is_parallelizable": True,
    }

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
        self.config: EnvConfig = adapter_config(type(self).__name__, preset, kwargs)
        self.render_mode = render_mode
        self._mdp = ExplorationMDP(self.config)
        self.possible_agents = [f"robot_{i}" for i in range(self.config.n_agents)]
        self.agents: list[str] = []
        self.layout = ObservationLayout(self._mdp.encoder.space, obs_layout)
        self._obs_space = self.layout.space
        self._act_space = spaces.Discrete(self.config.n_slots)
        self.observation_spaces = dict.fromkeys(self.possible_agents, self._obs_space)
        self.action_spaces = dict.fromkeys(self.possible_agents, self._act_space)
        self.state_space = spaces.Box(-1, 1, self.config.shape, dtype=np.int8)
        self._rng: np.random.Generator | None = None
        self._agents_seen: list[str] | None = None  # the agents list _agents_frozen holds
        self._agents_frozen: frozenset[str] = frozenset()

    def observation_space(self, agent: str) -> spaces.Space[Any]:
        return self._obs_space

    def action_space(self, agent: str) -> spaces.Space[Any]:
        return self._act_space

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
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
        seed = check_seed(seed, "reset(seed=...)")
        if seed is not None or self._rng is None:
            self._rng = np.random.default_rng(seed)
            self._act_space.seed(None if seed is None else seed + 1)
        observations = map(self.layout.wrap, self._mdp.reset(self._rng))
        infos = build_infos(self._mdp, None, self._info_level)
        self.agents = list(self.possible_agents)
        if self.render_mode == "human":
            self.render()
        return dict(zip(self.agents, observations, strict=True)), dict(
            zip(self.agents, infos, strict=True)
        )

    def step(
        self, actions: dict[str, Any]
    ) -> tuple[
        dict[str, Any],
        dict[str, float],
        dict[str, bool],
        dict[str, bool],
        dict[str, dict[str, Any]],
    ]:
        if not self.agents:
            raise RuntimeError("step() called with no live agents: call reset() first")
        agents = self.agents
        if actions.keys() != self._agent_set(agents):
            missing = [agent for agent in agents if agent not in actions]
            extra = [agent for agent in actions if agent not in agents]
            raise ValueError(
                f"actions must have one entry per live agent {agents}; "
                f"missing {missing}, unexpected {extra}"
            )
        result = self._mdp.step([actions[agent] for agent in agents])
        observed = result.observations
        if self.layout.classic:  # the flat layout is the engine's own
            observed = list(map(self.layout.wrap, observed))
        observations = dict(zip(agents, observed, strict=True))
        rewards = dict(zip(agents, result.rewards.tolist(), strict=True))
        terminations = dict.fromkeys(agents, result.terminated)
        truncations = dict.fromkeys(agents, result.truncated)
        infos = dict(zip(agents, build_infos(self._mdp, result, self._info_level), strict=True))
        if result.terminated or result.truncated:
            self.agents = []
        if self.render_mode == "human":
            self.render()
        return observations, rewards, terminations, truncations, infos

    def _agent_set(self, agents: list[str]) -> frozenset[str]:
        """The names in ``agents`` as a set, kept while the list is the same object."""
        if self._agents_seen is not agents:
            self._agents_seen, self._agents_frozen = agents, frozenset(agents)
        return self._agents_frozen

    def render(self) -> Any:
        return self._renderer.render(self._mdp)

    def close(self) -> None:
        self._renderer.close()

    def state(self) -> np.ndarray:
        """The shared belief grid (int8, -1 unknown / 0 free / 1 occupied)."""
        return np.array(self.world.belief)
