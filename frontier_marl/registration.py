"""Namespaced, versioned ids for Gymnasium and PettingZoo. Bump the version on behaviour change."""

from __future__ import annotations

GYM_ID = "frontier_marl/FrontierExplore-v0"
PETTINGZOO_ID = "frontier_marl/FrontierExplore-v0"


def register_envs() -> None:
    """Register the Gymnasium and PettingZoo ids (idempotent)."""
    import gymnasium
    import pettingzoo

    if GYM_ID not in gymnasium.registry:
        gymnasium.register(
            id=GYM_ID,
            entry_point="frontier_marl.envs.gym_env:FrontierExploreEnv",
            disable_env_checker=False,
        )
    if PETTINGZOO_ID not in pettingzoo.parallel_registry:
        pettingzoo.register("parallel", PETTINGZOO_ID, entry_point="frontier_marl:parallel_env")
    if PETTINGZOO_ID not in pettingzoo.aec_registry:
        pettingzoo.register("aec", PETTINGZOO_ID, entry_point="frontier_marl:env")
