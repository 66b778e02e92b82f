"""Environment configuration: frozen dataclasses, presets, and validation.

Every parameter of the simulator lives here, is validated once when the config is built, and
produces a ``ValueError`` that names the parameter and its allowed range. Presets reproduce the
thesis's two geometries; any keyword overrides the preset::

    cfg = make_config(preset="thesis-20x20", n_agents=2, centroid="relative")

Options that the thesis left open are marked "open choice" below; ``docs/thesis-mapping.md``
lists them with the reason for each default.
"""

from frontier_marl.config.env_config import (
    ALIASES,
    EnvConfig,
    UnknownKeywordError,
    config_keys,
    reject_unknown,
)
from frontier_marl.config.options import (
    FULL_PATH,
    CentroidEncoding,
    CommitRule,
    FeatureLayout,
    GainModel,
    MapGenerator,
    MapMode,
    ObservationConfig,
    RewardConfig,
    RewardKind,
    SensorModel,
    StartCells,
    TeammateEncoding,
    ThresholdBasis,
)
from frontier_marl.config.presets import PRESETS, config_to_dict, make_config

__all__ = [
    "ALIASES",
    "FULL_PATH",
    "PRESETS",
    "CentroidEncoding",
    "CommitRule",
    "EnvConfig",
    "FeatureLayout",
    "GainModel",
    "MapGenerator",
    "MapMode",
    "ObservationConfig",
    "RewardConfig",
    "RewardKind",
    "SensorModel",
    "StartCells",
    "TeammateEncoding",
    "ThresholdBasis",
    "UnknownKeywordError",
    "config_keys",
    "config_to_dict",
    "make_config",
    "reject_unknown",
]
