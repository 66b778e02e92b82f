"""Every value of ``train.algorithm``: the SB3 algorithms by name, and ``cem`` (the
cross-entropy method, :mod:`frontier_marl.training.cem`), which SB3 does not run.

==================  ==========================  ==================================  =========
``algorithm``       SB3 class                   ``policy = "slot-scorer"``          section
==================  ==========================  ==================================  =========
``dqn``             ``DQN`` (``MaskedDQN``)     ``SlotDQNPolicy``                   ``[dqn]``
``ppo``             ``PPO``                     ``SlotActorCriticPolicy``           ``[ppo]``
``maskable-ppo``    sb3-contrib ``MaskablePPO``  ``MaskableSlotActorCriticPolicy``   ``[ppo]``
``cem``             (none)                      the linear slot scorer              ``[cem]``
==================  ==========================  ==================================  =========
"""

from __future__ import annotations

from frontier_marl.training.dqn import DQN
from frontier_marl.training.ppo import MASKABLE_PPO, PPO
from frontier_marl.training.sb3_algorithm import SB3Algorithm

SB3_ALGORITHMS: dict[str, SB3Algorithm] = {a.name: a for a in (DQN, PPO, MASKABLE_PPO)}


def sb3_algorithm(name: str) -> SB3Algorithm:
    """The SB3 algorithm ``train.algorithm = name``; ValueError for another name."""
    if name not in SB3_ALGORITHMS:
        raise ValueError(
            f"train.algorithm must be one of {sorted(SB3_ALGORITHMS)} here, got {name!r}"
        )
    return SB3_ALGORITHMS[name]
