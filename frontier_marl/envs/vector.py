"""Gymnasium ``VectorEnv`` over :class:`~frontier_marl.sim.batch_engine.BatchMDP`: N worlds in one
call.

Sub-environment ``j`` of the vector is robot ``j % K`` of world ``j // K`` (K robots per world
share one belief, as SuperSuit's concatenated vector env lays out a ParallelEnv's agents), so a
team trains with parameter sharing. World ``i`` of a vector reset with seed ``s`` plays exactly
the episodes of ``FrontierParallelEnv`` reset with seed ``s + i`` (and, like it, continues its
own generator at later unseeded resets and autoresets).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from frontier_marl.config import EnvConfig
from frontier_marl.envs.infos import check_info_level
from frontier_marl.envs.keywords import adapter_config
from frontier_marl.envs.layout import ObservationLayout
from frontier_marl.sim.batch_engine import BatchMDP
from frontier_marl.utils.checks import check_seed

VECTOR_INFO_LEVELS = ("mask", "minimal", "full")
#: The vector env's keywords beside the config's.
VECTOR_KEYWORDS = (
    "num_envs",
    "preset",
    "info",
    "obs_layout",
    "autoreset_mode",
    "skip_forced_steps",
)


class FrontierVectorEnv(VectorEnv):
    """N frontier-exploration worlds of K robots, stepped together (``num_envs`` = N x K).

    **Actions.** An integer array of N x K slot indices, each in ``[0, n_slots)``.

    **Observations.** The single env's layout (``obs_layout``, classic by default) with a
    leading N x K axis (a dict of such arrays for ``Dict`` layouts); fresh arrays every step.

    **Autoreset.** Gymnasium's modes: ``next-step`` (the default; the step after an episode's
    end resets that world, with reward 0 and no end flags) or ``same-step`` (the world resets
    at once; ``infos["final_obs"]`` and ``infos["final_info"]`` hold the last step's).

    **Infos** (arrays with a leading N x K axis and Gymnasium's ``_key`` masks), by ``info``
    level: ``mask``: ``action_mask`` (N x K, n_slots) only; ``minimal`` (the default) adds
    ``explored_fraction``, ``coverage``, ``new_cells``, ``travelled``, ``step`` and
    ``end_reason`` (int codes, :data:`~frontier_marl.envs.infos.END_REASONS`); ``full`` adds
    ``position``, ``target`` (row -1: none), ``padding`` and ``oscillation``.

    **Forced steps.** With ``skip_forced_steps=True`` a step returns only when a decision is
    due: after the actions are applied, every world whose robots each have a single valid slot
    (held by a commitment, or one cluster left) walks on with it until its robots have a choice
    again or its episode ends. Rewards are summed over the steps played; infos describe the
    last one. The robots walk exactly as a policy choosing the only valid slot would (a
    semi-MDP view of the same episodes, for training).

    **Arguments.** ``num_envs`` (worlds, >= 1), ``preset``, ``info``, ``obs_layout``,
    ``autoreset_mode``, ``skip_forced_steps``, and every keyword of
    :class:`~frontier_marl.envs.parallel.FrontierParallelEnv`.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        num_envs: int = 1,
        preset: str | None = "thesis-20x20",
        info: str = "minimal",
        autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP,
        skip_forced_steps: bool = False,
        obs_layout: str = "classic",
        **kwargs: Any,
    ) -> None:
        if not isinstance(skip_forced_steps, bool):
            raise ValueError(f"skip_forced_steps must be true or false, got {skip_forced_steps!r}")
        check_info_level(info, VECTOR_INFO_LEVELS)
        modes = {mode.value: mode for mode in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP)}
        mode = autoreset_mode if isinstance(autoreset_mode, AutoresetMode) else None
        if mode is None and isinstance(autoreset_mode, str):
            mode = modes.get(autoreset_mode) or modes.get(
                {"next-step": "NextStep", "same-step": "SameStep"}.get(autoreset_mode, "")
            )
        if mode not in modes.values():
            raise ValueError(
                "autoreset_mode must be 'next-step' or 'same-step' (AutoresetMode.NEXT_STEP or "
                f"SAME_STEP), got {autoreset_mode!r}"
            )
        owner = type(self).__name__
        self.config: EnvConfig = adapter_config(owner, preset, kwargs, VECTOR_KEYWORDS)
        self.mdp = BatchMDP(self.config, num_envs)
        self.autoreset_mode = mode
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        self.info_level = info
        self.skip_forced_steps = skip_forced_steps
        self.n_worlds, self.n_agents = self.mdp.n_worlds, self.mdp.n_agents
        self.num_envs = self.n_worlds * self.n_agents
        self.layout = ObservationLayout(self.mdp.encoder.space, obs_layout)
        self.single_observation_space = self.layout.space
        self.single_action_space = spaces.Discrete(self.config.n_slots)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = None
        self._seeded = np.zeros(self.n_worlds, dtype=bool)
        self._started = False  # reset() was called
        self._valid = np.ones(self.num_envs, dtype=bool)  # the `_key` mask of every info key

    # ------------------------------------------------------------------ API
    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Reset every world: ``seed`` s seeds world i with s + i; a list gives one seed (or
        ``None``) per world."""
        seeds = self._world_seeds(seed)
        for i, world_seed in enumerate(seeds):
            if world_seed is not None or not self._seeded[i]:
                self.mdp.rngs[i] = np.random.default_rng(world_seed)
                self._seeded[i] = True
        if isinstance(seed, int):
            self.action_space.seed(seed)
        self.mdp.reset_worlds(np.arange(self.n_worlds))
        self._started = True
        return self._observations(), self._infos(reset=True)

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise RuntimeError("step() called before reset(): call reset() first")
        mdp = self.mdp
        chosen = self._check_actions(actions)
        infos: dict[str, Any] = {}
        if self.autoreset_mode == AutoresetMode.NEXT_STEP:
            restart = np.flatnonzero(mdp.done)
            self._step_worlds(chosen, ~mdp.done)
            if len(restart):
                mdp.reset_worlds(restart)
            observations = self._observations()
        else:
            self._step_worlds(chosen, ~mdp.done)
            ended = np.flatnonzero(mdp.done)
            observations = self._observations()
            if len(ended):
                infos.update(self._final(observations, ended))
                mdp.reset_worlds(ended)
                observations = self._observations()
        outcome = mdp.outcome
        rewards = outcome.rewards.reshape(-1)
        terminations = self._per_robot(outcome.terminated)
        truncations = self._per_robot(outcome.truncated)
        infos.update(self._infos(reset=False))
        return observations, rewards, terminations, truncations, infos

    def close_extras(self, **kwargs: Any) -> None:
        pass

    # ------------------------------------------------------------------ helpers
    def _step_worlds(self, actions: np.ndarray, active: np.ndarray) -> None:
        self.mdp.step(actions, active)
        if self.skip_forced_steps:
            self.mdp.play_forced()

    def _world_seeds(self, seed: int | list[int | None] | None) -> list[int | None]:
        n = self.n_worlds
        if seed is None:
            return [None] * n
        if isinstance(seed, int | np.integer) and not isinstance(seed, bool):
            first = check_seed(seed, "reset(seed=...)")
            return [first + i for i in range(n)]
        if isinstance(seed, list | tuple) and len(seed) == n:
            return [check_seed(s, f"reset(seed=...)[{i}]") for i, s in enumerate(seed)]
        raise ValueError(
            f"seed must be an int, None, or a list of {n} seeds (one per world), got {seed!r}"
        )

    def _check_actions(self, actions: Any) -> np.ndarray:
        array = np.asarray(actions)
        if array.dtype.kind not in "iu":
            raise TypeError(
                f"actions must be integer slot indices, got an array of dtype {array.dtype}"
            )
        if array.shape != (self.num_envs,):
            raise ValueError(
                f"actions must have shape ({self.num_envs},) (num_envs x n_agents = "
                f"{self.n_worlds} x {self.n_agents}), got {array.shape}"
            )
        n_slots = self.config.n_slots
        wide = array.astype(np.int64, copy=False)
        if (wide.view(np.uint64) >= n_slots).any():  # one test: negatives read as huge
            j = int(np.flatnonzero((array < 0) | (array >= n_slots))[0])
            raise ValueError(
                f"actions must be in [0, {n_slots - 1}] (n_slots={n_slots}); "
                f"actions[{j}] = {array[j]}"
            )
        return wide.reshape(self.n_worlds, self.n_agents)

    def _per_robot(self, flags: np.ndarray) -> np.ndarray:
        """A per-world array as one entry per robot (a fresh array)."""
        return flags.copy() if self.n_agents == 1 else np.repeat(flags, self.n_agents)

    def _observations(self) -> Any:
        batch = self.mdp.robot_observations()  # (num_envs, ...): robots world after world
        return self.layout.wrap(batch) if isinstance(batch, dict) else batch

    def _final(self, observations: Any, ended: np.ndarray) -> dict[str, Any]:
        """``final_obs`` and ``final_info`` of the worlds that just ended (same-step mode)."""
        envs = (ended[:, None] * self.n_agents + np.arange(self.n_agents)).reshape(-1)
        final_obs = np.full(self.num_envs, None, dtype=object)
        final_info = np.full(self.num_envs, None, dtype=object)
        infos = self._infos(reset=False)
        for j in envs.tolist():
            if isinstance(observations, dict):
                final_obs[j] = {key: value[j] for key, value in observations.items()}
            else:
                final_obs[j] = observations[j]
            final_info[j] = {key: value[j] for key, value in infos.items() if key[0] != "_"}
        mask = np.zeros(self.num_envs, dtype=bool)
        mask[envs] = True
        return {
            "final_obs": final_obs,
            "_final_obs": mask,
            "final_info": final_info,
            "_final_info": mask,
        }

    def _infos(self, reset: bool) -> dict[str, Any]:
        mdp, k = self.mdp, self.n_agents
        infos: dict[str, Any] = {"action_mask": mdp.slots.mask.reshape(self.num_envs, -1).copy()}
        if self.info_level != "mask":
            fraction = mdp.explored_fraction(self.config.reward.threshold_basis)
            coverage = (
                fraction
                if self.config.reward.threshold_basis == "reachable"
                else mdp.explored_fraction("reachable")
            )
            reason = np.zeros(mdp.n_worlds, np.int64) if reset else mdp.outcome.reason
            infos.update(
                explored_fraction=np.repeat(fraction, k),
                coverage=np.repeat(coverage, k),
                new_cells=mdp.new_cells.reshape(-1).copy(),
                travelled=mdp.worlds.travelled.reshape(-1).copy(),
                step=np.repeat(mdp.steps, k),
                end_reason=np.repeat(reason.astype(np.int64), k),
            )
        if self.info_level == "full":
            infos.update(
                position=mdp.worlds.positions.reshape(-1, 2).copy(),
                target=mdp.targets.reshape(-1, 2).copy(),
                padding=mdp.padding.reshape(-1).copy(),
                oscillation=mdp.oscillation.reshape(-1).copy(),
            )
        for key in list(infos):
            infos[f"_{key}"] = self._valid
        return infos


def vector_env(num_envs: int = 1, **env_kwargs: Any) -> FrontierVectorEnv:
    """A :class:`FrontierVectorEnv` of ``num_envs`` worlds (every keyword of
    :class:`FrontierVectorEnv`)."""
    return FrontierVectorEnv(num_envs=num_envs, **env_kwargs)
