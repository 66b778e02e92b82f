"""A linear slot scorer's vocabulary: the names of the explorer layout's per-slot features and
weights given by feature name.

A linear scorer scores every valid slot by the dot product of its features with one weight
vector and takes the best slot (the ``explorer`` trained by CEM,
:mod:`frontier_marl.training.cem`; the prior of a PPO actor).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.sim.features import slot_feature_names


def feature_names(cfg: EnvConfig) -> list[str]:
    """The names of the per-slot features of ``cfg``'s explorer layout, in order."""
    obs = cfg.observation
    if obs.features != "explorer":
        raise ValueError("the linear slot scorer needs features = 'explorer'")
    return slot_feature_names(obs)


def weight_vector(weights: Mapping[str, float], names: list[str], what: str) -> np.ndarray:
    """``weights`` by feature name as a vector over ``names`` (the others 0); ValueError, naming
    ``what``, for a name that is not a feature."""
    unknown = set(weights) - set(names)
    if unknown:
        raise ValueError(f"{what} names unknown feature(s) {sorted(unknown)}; features: {names}")
    return np.array([float(weights.get(name, 0.0)) for name in names])


def explorer_slots(obs: Any) -> tuple[np.ndarray, np.ndarray]:
    """The (n_slots, F) slot features and (n_slots,) action mask of one explorer observation,
    in either layout (``{"slots", "action_mask"}`` or the classic ``{"observation",
    "action_mask"}``); ValueError for any other observation."""
    if isinstance(obs, Mapping) and "action_mask" in obs:
        slots = obs.get("slots", obs.get("observation"))
        if slots is not None and np.ndim(slots) == 2:
            return np.asarray(slots), np.asarray(obs["action_mask"])
    raise ValueError(
        "expected the explorer observation (features='explorer'): the policy runs with the "
        "observation settings of frontier_marl.policies.frontier_rule.FRONTIER_RULE_SETTINGS"
    )
