"""A linear slot scorer's vocabulary: the names of the explorer layout's per-slot features and
weights given by feature name.

A linear scorer scores every valid slot by the dot product of its features with one weight
vector and takes the best slot (the ``explorer`` trained by CEM,
:mod:`frontier_marl.training.cem`; the prior of a PPO actor).
"""

from __future__ import annotations

from collections.abc import Mapping

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
