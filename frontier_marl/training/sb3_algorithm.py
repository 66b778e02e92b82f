"""What the training pipeline needs to know of one Stable-Baselines3 algorithm: its classes,
the config section of its keywords, the ranges checked before SB3 sees them, and the name a
saved model's metadata records. Each algorithm declares one (:mod:`~frontier_marl.training.dqn`,
:mod:`~frontier_marl.training.ppo`); :mod:`~frontier_marl.training.sb3_session` runs any of them.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

#: (kind, low, high) of a checked keyword: kind is "int" or "float".
Range = tuple[str, float, float]

#: keywords the pipeline sets itself (seeding goes through set_random_seed: SuperSuit's vector
#: env cannot be seeded by SB3, see frontier_marl.training.vec_env)
RESERVED = {"policy", "env", "seed", "device", "tensorboard_log", "verbose", "_init_setup_model"}

#: ranges of the keywords DQN and PPO share
SHARED_RANGES: dict[str, Range] = {
    "learning_rate": ("float", 0.0, math.inf),
    "gamma": ("float", 0.0, 1.0),
    "max_grad_norm": ("float", 0.0, math.inf),
    "batch_size": ("int", 1, math.inf),
    "n_steps": ("int", 1, math.inf),
}


@dataclass(frozen=True)
class SB3Algorithm:
    """One SB3 algorithm as ``train.algorithm`` names it.

    Attributes:
        name: the ``train.algorithm`` value.
        section: the config section of its keyword arguments (``dqn`` or ``ppo``).
        label: the name a model's metadata records (``"algorithm"``).
        sb3_class: the SB3 class (imported on call: SB3 is the ``train`` extra).
        slot_classes: the (algorithm, policy) classes of ``train.policy = "slot-scorer"``.
        ranges: keyword -> (kind, low, high), checked before SB3 sees the config.
        resumes_replay_buffer: a checkpoint's replay buffer is loaded on resume.
    """

    name: str
    section: str
    label: str
    sb3_class: Callable[[], type]
    slot_classes: Callable[[], tuple[type, type]]
    ranges: Mapping[str, Range] = field(default_factory=dict)
    resumes_replay_buffer: bool = False

    def classes(self, policy: str) -> tuple[type, type | None]:
        """The algorithm class and the policy class (None: SB3's, by observation) of
        ``train.policy``."""
        if policy == "slot-scorer":
            return self.slot_classes()
        return self.sb3_class(), None

    def keyword_names(self) -> set[str]:
        """The keyword arguments of the SB3 class that a config may set."""
        signature = inspect.signature(self.sb3_class().__init__)
        return set(signature.parameters) - {"self"} - RESERVED

    def check_ranges(self, values: Mapping[str, Any], where: str) -> None:
        """ValueError naming the first keyword of ``values`` outside its range."""
        for key, (kind, low, high) in self.ranges.items():
            if key in values:
                check_range(f"{self.section}.{key}", values[key], kind, low, high, where)
        for key in ("learning_rate", "clip_range"):
            if values.get(key, 1.0) == 0:
                raise ValueError(f"{self.section}.{key} must be > 0{where}")
        if values.get("gradient_steps", 1) == 0:
            raise ValueError(f"{self.section}.gradient_steps must be >= 1 or -1, got 0{where}")


def check_range(name: str, value: Any, kind: str, low: float, high: float, where: str) -> None:
    """ValueError unless ``value`` is an integer (``kind`` "int") or a finite number in
    [low, high]; ``train_freq`` may also be SB3's ``(n, "step" | "episode")``."""
    shown = value
    if kind == "int":
        ok = isinstance(value, int) and not isinstance(value, bool)
        if name.endswith(".train_freq") and isinstance(value, list | tuple) and len(value) == 2:
            ok, value = isinstance(value[0], int) and value[1] in ("step", "episode"), value[0]
        what = "an integer"
    else:
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        ok = ok and math.isfinite(value)
        what = "a number"
    if not ok or not low <= value <= high:
        bounds = f">= {low}" if high == math.inf else f"in [{low}, {high}]"
        raise ValueError(f"{name} must be {what} {bounds}, got {shown!r}{where}")
