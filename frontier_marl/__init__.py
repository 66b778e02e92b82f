"""frontier_marl: learned frontier selection for autonomous grid exploration.

Entry points::

    import frontier_marl
    par = frontier_marl.parallel_env(preset="thesis-20x20", n_agents=2)   # PettingZoo Parallel
    aec = frontier_marl.env(preset="thesis-20x20")                        # PettingZoo AEC
    import gymnasium as gym
    single = gym.make("frontier_marl/FrontierExplore-v1", preset="thesis-20x20")
    batch = frontier_marl.vector_env(num_envs=64, preset="thesis-20x20")  # Gymnasium VectorEnv
"""

from __future__ import annotations

from typing import Any

from pettingzoo.utils.conversions import parallel_to_aec_wrapper
from pettingzoo.utils.wrappers import OrderEnforcingWrapper

from frontier_marl.config import EnvConfig, ObservationConfig, RewardConfig, make_config
from frontier_marl.envs import FrontierExploreEnv, FrontierParallelEnv
from frontier_marl.envs.infos import END_REASONS, SLOT_COLUMNS, reason_name, slot_table
from frontier_marl.envs.registration import GYM_ID, PETTINGZOO_ID, register_envs
from frontier_marl.envs.vector import FrontierVectorEnv, vector_env

__version__ = "0.1.0"


def parallel_env(**kwargs: Any) -> FrontierParallelEnv:
    """The PettingZoo ParallelEnv (see :class:`FrontierParallelEnv` for the arguments)."""
    return FrontierParallelEnv(**kwargs)


def raw_env(**kwargs: Any) -> Any:
    """The AEC form of :func:`parallel_env`, unwrapped (PettingZoo's ``raw_env`` convention)."""
    return parallel_to_aec_wrapper(parallel_env(**kwargs))


def env(**kwargs: Any) -> Any:
    """The PettingZoo AEC env: :func:`raw_env` in PettingZoo's ``OrderEnforcingWrapper``
    (an error for stepping before ``reset``, or reading a dead agent's data)."""
    return OrderEnforcingWrapper(raw_env(**kwargs))


register_envs()

__all__ = [
    "END_REASONS",
    "SLOT_COLUMNS",
    "GYM_ID",
    "PETTINGZOO_ID",
    "EnvConfig",
    "FrontierExploreEnv",
    "FrontierParallelEnv",
    "FrontierVectorEnv",
    "ObservationConfig",
    "RewardConfig",
    "env",
    "make_config",
    "parallel_env",
    "raw_env",
    "reason_name",
    "slot_table",
    "vector_env",
]
