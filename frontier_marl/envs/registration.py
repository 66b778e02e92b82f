"""Namespaced, versioned ids for Gymnasium and PettingZoo: one generic id (any preset through
``preset=``) and one id per preset, as Minigrid registers its variants. Bump the version when
behaviour changes (v1: numeric fixed-shape infos, the classic mask layout, ``TypeError`` for
unknown keywords; the v0 ids are gone, and Gymnasium names v1 when asked for them).

    gymnasium.make("frontier_marl/FrontierExplore-Thesis30x30-v1")
    gymnasium.make_vec("frontier_marl/FrontierExplore-v1", num_envs=64,
                       vectorization_mode="vector_entry_point")   # the batched vector env
    pettingzoo.make("parallel", "frontier_marl/FrontierExplore-Rooms32-v1", n_agents=4)
"""

from __future__ import annotations

import gymnasium
import pettingzoo

from frontier_marl.config import PRESETS

VERSION = 1
GYM_ID = f"frontier_marl/FrontierExplore-v{VERSION}"
PETTINGZOO_ID = GYM_ID


def variant_id(preset: str) -> str:
    """The id of a preset's variant, e.g. ``thesis-30x30`` -> ``...-Thesis30x30-v1``."""
    name = "".join(part.capitalize() for part in preset.split("-"))
    return f"frontier_marl/FrontierExplore-{name}-v{VERSION}"


#: Every registered id -> the env kwargs it stands for (the generic id: the default preset).
VARIANTS: dict[str, dict[str, str]] = {
    GYM_ID: {},
    **{variant_id(preset): {"preset": preset} for preset in PRESETS},
}


def register_envs() -> None:
    """Register every id with Gymnasium and PettingZoo (Parallel and AEC); idempotent."""
    for env_id, kwargs in VARIANTS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point="frontier_marl.envs.gym_env:FrontierExploreEnv",
                vector_entry_point="frontier_marl.envs.vector:FrontierVectorEnv",
                kwargs=dict(kwargs),
                disable_env_checker=False,
            )
        if env_id not in pettingzoo.parallel_registry:
            pettingzoo.register(
                "parallel", env_id, entry_point="frontier_marl:parallel_env", kwargs=dict(kwargs)
            )
        if env_id not in pettingzoo.aec_registry:
            pettingzoo.register("aec", env_id, entry_point="frontier_marl:env", kwargs=dict(kwargs))
