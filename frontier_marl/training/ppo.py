"""PPO (SB3) and MaskablePPO (sb3-contrib: the env's action masks applied to the policy), with
the ``[ppo]`` section; the slot scorer's actor may start at a linear prior given by feature
name. Their training loop is SB3's, run by :mod:`~frontier_marl.training.sb3_session`."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from frontier_marl.config import EnvConfig
from frontier_marl.policies.linear_scorer import feature_names, weight_vector
from frontier_marl.training.sb3_algorithm import SHARED_RANGES, SB3Algorithm

RANGES = {
    **SHARED_RANGES,
    "n_epochs": ("int", 1, math.inf),
    "gae_lambda": ("float", 0.0, 1.0),
    "clip_range": ("float", 0.0, math.inf),
    "ent_coef": ("float", 0.0, math.inf),
    "vf_coef": ("float", 0.0, math.inf),
}


def _ppo() -> type:
    from stable_baselines3 import PPO as SB3PPO

    return SB3PPO


def _maskable_ppo() -> type:
    from sb3_contrib import MaskablePPO

    return MaskablePPO


def _slot_ppo() -> tuple[type, type]:
    from frontier_marl.policies.networks.slot_actor_critic import SlotActorCriticPolicy

    return _ppo(), SlotActorCriticPolicy


def _slot_maskable_ppo() -> tuple[type, type]:
    from frontier_marl.policies.networks.slot_actor_critic import (
        MaskableSlotActorCriticPolicy,
    )

    return _maskable_ppo(), MaskableSlotActorCriticPolicy


PPO = SB3Algorithm("ppo", "ppo", "PPO", _ppo, _slot_ppo, RANGES)
MASKABLE_PPO = SB3Algorithm(
    "maskable-ppo", "ppo", "MaskablePPO", _maskable_ppo, _slot_maskable_ppo, RANGES
)


def with_prior_vector(ppo: dict[str, Any], cfg: EnvConfig) -> dict[str, Any]:
    """``[ppo]`` with a ``policy_kwargs.prior`` given by feature name turned into the vector
    over ``cfg``'s slot features (ValueError for a name that is not one)."""
    policy_kwargs = ppo.get("policy_kwargs", {})
    prior = policy_kwargs.get("prior") if isinstance(policy_kwargs, Mapping) else None
    if not isinstance(prior, Mapping):
        return ppo
    vector = weight_vector(prior, feature_names(cfg), "ppo.policy_kwargs.prior").tolist()
    return {**ppo, "policy_kwargs": {**policy_kwargs, "prior": vector}}
