"""DQN (SB3's ``DQN``; ``MaskedDQN`` with the slot scorer) with the thesis's hyperparameters by
default. Its training loop is SB3's, run by :mod:`~frontier_marl.training.sb3_session`."""

from __future__ import annotations

import math

from frontier_marl.config.thesis import DQN_HYPERPARAMETERS
from frontier_marl.training.sb3_algorithm import SHARED_RANGES, SB3Algorithm

#: The thesis's final DQN hyperparameters: the ``[dqn]`` defaults (everything else is SB3's).
THESIS_DQN = DQN_HYPERPARAMETERS


def _dqn() -> type:
    from stable_baselines3 import DQN as SB3DQN

    return SB3DQN


def _slot_dqn() -> tuple[type, type]:
    from frontier_marl.policies.networks.slot_dqn import MaskedDQN, SlotDQNPolicy

    return MaskedDQN, SlotDQNPolicy


DQN = SB3Algorithm(
    name="dqn",
    section="dqn",
    label="DQN",
    sb3_class=_dqn,
    slot_classes=_slot_dqn,
    ranges={
        **SHARED_RANGES,
        "exploration_fraction": ("float", 0.0, 1.0),
        "exploration_initial_eps": ("float", 0.0, 1.0),
        "exploration_final_eps": ("float", 0.0, 1.0),
        "tau": ("float", 0.0, 1.0),
        "buffer_size": ("int", 1, math.inf),
        "learning_starts": ("int", 0, math.inf),
        "target_update_interval": ("int", 1, math.inf),
        "train_freq": ("int", 1, math.inf),
        "gradient_steps": ("int", -1, math.inf),
    },
    resumes_replay_buffer=True,
)
