"""Stable-Baselines3 ``VecEnv`` over the batched vector env (:mod:`frontier_marl.envs.vector`).

It gives SB3 what the SuperSuit pipeline of :mod:`frontier_marl.training.vec_env` gives, step
for step: one vector slot per robot of each of ``n_envs`` worlds, same-step autoreset with
``info["terminal_observation"]``, ``info["TimeLimit.truncated"]`` on truncations (unless
``bootstrap_truncations=False``) and ``info["episode_end_reason"]`` at each episode's end, and
world ``i`` seeded like SuperSuit copy ``i`` (:func:`~frontier_marl.training.vec_env.copy_seeds`),
so both pipelines produce the same transitions. ``action_masks()`` (through ``env_method``)
serves sb3-contrib's ``MaskablePPO``.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import VecEnv, VecMonitor

from frontier_marl.envs.vector import FrontierVectorEnv
from frontier_marl.sim.rewards import REASONS
from frontier_marl.training.vec_env import END_REASON_KEY, TRUNCATED_KEY, copy_seeds


class MaskedVecEnv(VecEnv):
    """An SB3 ``VecEnv`` whose only env method is ``action_masks`` (what sb3-contrib's
    MaskablePPO calls) and whose envs have no attributes to set."""

    def action_masks(self) -> np.ndarray:
        raise NotImplementedError

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        raise AttributeError(f"{type(self).__name__} has no per-env attributes to set")

    def env_method(
        self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any
    ) -> list[Any]:
        if method_name != "action_masks":
            raise AttributeError(f"{type(self).__name__} has no env method {method_name!r}")
        return list(self.action_masks()[env_indices(indices, self.num_envs)])

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False] * len(env_indices(indices, self.num_envs))


class BatchedVecEnv(MaskedVecEnv):
    """``n_envs`` worlds of K robots as an SB3 ``VecEnv`` of ``n_envs x K`` slots."""

    def __init__(
        self,
        env_kwargs: dict[str, Any],
        n_envs: int = 1,
        bootstrap_truncations: bool = True,
    ) -> None:
        self.env = FrontierVectorEnv(
            num_envs=n_envs,
            autoreset_mode="same-step",
            info="mask",
            obs_layout="flat",  # SB3 takes no nested Dict; saved models record this layout
            **env_kwargs,
        )
        self.mark_truncations = bootstrap_truncations
        super().__init__(
            self.env.num_envs, self.env.single_observation_space, self.env.single_action_space
        )
        self._actions: np.ndarray | None = None
        self._world_seeds: list[int | None] | None = None

    # ------------------------------------------------------------------ VecEnv
    def seed(self, seed: int | None = None) -> Sequence[None | int]:
        """Seed world ``i`` with ``seed + i`` at the next reset."""
        if seed is not None:
            self._world_seeds = [seed + i for i in range(self.env.n_worlds)]
        return [None] * self.num_envs

    def seed_worlds(self, seeds: list[int]) -> None:
        """Reset world ``i`` with ``seeds[i]`` now (the next resets continue its generator)."""
        self.env.reset(seed=list(seeds))

    def reset(self) -> Any:
        seeds, self._world_seeds = self._world_seeds, None
        observations, _ = self.env.reset(seed=seeds)
        self.reset_infos = [{} for _ in range(self.num_envs)]
        return observations

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[Any, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        observations, rewards, terminations, truncations, infos = self.env.step(self._actions)
        dones = terminations | truncations
        step_infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        if dones.any():
            reasons = self.env.mdp.outcome.reason
            final_obs = infos["final_obs"]
            for j in np.flatnonzero(dones).tolist():
                info = step_infos[j]
                info["terminal_observation"] = final_obs[j]
                info[END_REASON_KEY] = REASONS[int(reasons[j // self.env.n_agents])]
                if self.mark_truncations and truncations[j] and not terminations[j]:
                    info[TRUNCATED_KEY] = True
        return observations, rewards.astype(np.float32), dones, step_infos

    def action_masks(self) -> np.ndarray:
        """(num_envs, n_slots) bool: the valid slots of every vector slot."""
        return self.env.mdp.slots.mask.reshape(self.num_envs, -1).astype(bool)

    def close(self) -> None:
        self.env.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(self.env, attr_name, None)] * len(env_indices(indices, self.num_envs))


def env_indices(indices: Any, num_envs: int) -> list[int]:
    """SB3's ``indices`` argument (None, an int or an iterable) as a list."""
    if indices is None:
        return list(range(num_envs))
    if isinstance(indices, int):
        return [indices]
    assert isinstance(indices, Iterable)
    return list(indices)


def make_batched_vec_env(
    env_kwargs: dict[str, Any],
    n_envs: int = 1,
    seed: int | None = None,
    bootstrap_truncations: bool = True,
    seed_range: range | None = None,
) -> VecMonitor:
    """An SB3 ``VecMonitor`` over :class:`BatchedVecEnv`; with ``seed`` world ``i`` is reset
    once with SuperSuit copy ``i``'s seed, as :func:`~frontier_marl.training.vec_env.make_vec_env`
    does, mapped into ``seed_range`` when given (e.g. a map family's training seeds)."""
    if isinstance(n_envs, bool) or not isinstance(n_envs, int) or n_envs < 1:
        raise ValueError(f"n_envs must be an integer >= 1, got {n_envs!r}")
    vec = BatchedVecEnv(env_kwargs, n_envs, bootstrap_truncations)
    if seed is not None:
        seeds = copy_seeds(seed, n_envs)
        if seed_range is not None:
            seeds = [seed_range[s % len(seed_range)] for s in seeds]
        vec.seed_worlds(seeds)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="The `render_mode` attribute is not defined")
        return VecMonitor(vec)


class MixedVecEnv(MaskedVecEnv):
    """Several SB3 vector envs of one observation space side by side (e.g. one batch per map
    family, whose grids differ in size): slots of the first, then of the second, ..."""

    def __init__(self, parts: Sequence[VecEnv]) -> None:
        first = parts[0]
        for part in parts[1:]:
            if part.observation_space != first.observation_space:
                raise ValueError(
                    "every part of a mixed vector env needs the same observation space, got "
                    f"{first.observation_space} and {part.observation_space}"
                )
        self.parts = list(parts)
        self._bounds = np.cumsum([0, *(part.num_envs for part in parts)])
        super().__init__(int(self._bounds[-1]), first.observation_space, first.action_space)

    def reset(self) -> Any:
        return self._join([part.reset() for part in self.parts])

    def step_async(self, actions: np.ndarray) -> None:
        for part, low, high in zip(self.parts, self._bounds[:-1], self._bounds[1:], strict=True):
            part.step_async(actions[low:high])

    def step_wait(self) -> tuple[Any, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        results = [part.step_wait() for part in self.parts]
        observations = self._join([result[0] for result in results])
        rewards = np.concatenate([result[1] for result in results])
        dones = np.concatenate([result[2] for result in results])
        infos = [info for result in results for info in result[3]]
        return observations, rewards, dones, infos

    def action_masks(self) -> np.ndarray:
        return np.concatenate([np.stack(part.env_method("action_masks")) for part in self.parts])

    def seed(self, seed: int | None = None) -> Sequence[None | int]:
        return [
            s
            for i, part in enumerate(self.parts)
            for s in part.seed(None if seed is None else seed + 1000 * i)
        ]

    def close(self) -> None:
        for part in self.parts:
            part.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        values = [value for part in self.parts for value in part.get_attr(attr_name)]
        return [values[i] for i in env_indices(indices, self.num_envs)]

    @staticmethod
    def _join(observations: list[Any]) -> Any:
        if isinstance(observations[0], dict):
            return {key: np.concatenate([o[key] for o in observations]) for key in observations[0]}
        return np.concatenate(observations)
