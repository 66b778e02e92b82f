"""Thin adapters over :class:`frontier_marl.sim.engine.ExplorationMDP`."""

from frontier_marl.envs.gym_env import FrontierExploreEnv
from frontier_marl.envs.parallel import FrontierParallelEnv

__all__ = ["FrontierExploreEnv", "FrontierParallelEnv"]
