"""Presets and the flat-keyword constructor: :func:`make_config` builds a validated
:class:`EnvConfig` from a preset and overrides; :func:`config_to_dict` reverses it."""

from __future__ import annotations

from typing import Any

from frontier_marl.config.env_config import (
    ENV_KEYS,
    OBS_KEYS,
    REWARD_KEYS,
    EnvConfig,
    apply_overrides,
)

#: Presets. ``thesis-20x20`` is the calibrated default (docs/calibration.md). The others are
#: derived from it by rule, not by fitting: ``thesis-30x30`` has size 30x30 and perception
#: range 5 (the thesis's second geometry), ``max_steps`` proportional to the number of cells
#: (400 * 900 / 400) and ``max_cluster_cells`` = 2r + 2 (the edge of a sensor window plus one,
#: 8 at r = 3); ``rooms-32`` is a 32x32 rooms-and-corridors map at the thesis's range (r = 3,
#: ``max_steps`` 400 * 1024 / 400). Every other parameter is unchanged.
PRESETS: dict[str, dict[str, Any]] = {
    "thesis-20x20": {},
    "thesis-30x30": {
        "height": 30,
        "width": 30,
        "perception_range": 5,
        "max_steps": 900,
        "max_cluster_cells": 12,
    },
    "rooms-32": {
        "map_generator": "rooms",
        "height": 32,
        "width": 32,
        "max_steps": 1024,
    },
}


def make_config(preset: str | None = "thesis-20x20", **overrides: Any) -> EnvConfig:
    """Build a validated :class:`EnvConfig` from a preset plus flat keyword overrides.

    Keys are the fields of :class:`EnvConfig`, :class:`ObservationConfig` and
    :class:`RewardConfig` (``reward`` takes the reward kind, ``reward1`` or ``reward2``).
    A ready ``EnvConfig`` may be passed as ``config=`` instead of a preset.
    """
    base = overrides.pop("config", None)
    if base is None:
        if preset is None:
            preset = "thesis-20x20"
        if preset not in PRESETS:
            raise ValueError(f"preset must be one of {sorted(PRESETS)}, got {preset!r}")
        base = apply_overrides(EnvConfig(), dict(PRESETS[preset]))
    elif not isinstance(base, EnvConfig):
        raise ValueError(f"config must be an EnvConfig, got {type(base).__name__}")
    return apply_overrides(base, overrides)


def config_to_dict(cfg: EnvConfig) -> dict[str, Any]:
    """A flat dictionary that :func:`make_config` turns back into ``cfg``."""
    flat: dict[str, Any] = {k: getattr(cfg, k) for k in sorted(ENV_KEYS)}
    flat.update({k: getattr(cfg.observation, k) for k in sorted(OBS_KEYS)})
    flat.update({k: getattr(cfg.reward, k) for k in sorted(REWARD_KEYS)})
    flat["reward"] = cfg.reward.kind
    return flat
