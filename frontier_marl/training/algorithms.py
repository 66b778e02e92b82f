"""The learning algorithms of ``train.algorithm`` that SB3 runs: their classes, the policy
class that ``train.policy`` selects, the config section of their keywords, and the class that
loads a saved model by the name its metadata records.

==================  ==========================  ==================================  =========
``algorithm``       SB3 class                   ``policy = "slot-scorer"``          section
==================  ==========================  ==================================  =========
``dqn``             ``DQN`` (``MaskedDQN``)     ``SlotDQNPolicy``                   ``[dqn]``
``ppo``             ``PPO``                     ``SlotActorCriticPolicy``           ``[ppo]``
``maskable-ppo``    sb3-contrib ``MaskablePPO``  ``MaskableSlotActorCriticPolicy``   ``[ppo]``
==================  ==========================  ==================================  =========

(``cem``, the cross-entropy method, is not an SB3 algorithm: :mod:`frontier_marl.training.cem`.)
"""

from __future__ import annotations

import inspect
from typing import Any

#: train.algorithm -> the config section of its keyword arguments
SECTION = {"dqn": "dqn", "ppo": "ppo", "maskable-ppo": "ppo"}
#: train.algorithm -> the name recorded in a model's metadata ("algorithm")
LABEL = {"dqn": "DQN", "ppo": "PPO", "maskable-ppo": "MaskablePPO"}

#: keywords the pipeline sets itself (seeding goes through set_random_seed: SuperSuit's vector
#: env cannot be seeded by SB3, see frontier_marl.training.vec_env)
RESERVED = {"policy", "env", "seed", "device", "tensorboard_log", "verbose", "_init_setup_model"}


def algorithm_class(algorithm: str) -> Any:
    """The SB3 class of ``algorithm`` (plain ``DQN`` for ``dqn``)."""
    if algorithm == "dqn":
        from stable_baselines3 import DQN

        return DQN
    if algorithm == "ppo":
        from stable_baselines3 import PPO

        return PPO
    if algorithm == "maskable-ppo":
        from sb3_contrib import MaskablePPO

        return MaskablePPO
    raise ValueError(f"train.algorithm must be one of {sorted(SECTION)} here, got {algorithm!r}")


def learner(algorithm: str, policy: str) -> tuple[Any, Any]:
    """The SB3 algorithm class and policy class (None: SB3's, by observation) of
    ``train.algorithm`` and ``train.policy``."""
    if policy != "slot-scorer":
        return algorithm_class(algorithm), None
    if algorithm == "dqn":
        from frontier_marl.policies.networks.slot_dqn import MaskedDQN, SlotDQNPolicy

        return MaskedDQN, SlotDQNPolicy
    from frontier_marl.policies.networks import slot_actor_critic

    if algorithm == "ppo":
        return algorithm_class(algorithm), slot_actor_critic.SlotActorCriticPolicy
    return algorithm_class(algorithm), slot_actor_critic.MaskableSlotActorCriticPolicy


def keyword_names(algorithm: str) -> set[str]:
    """The keyword arguments of ``algorithm``'s SB3 class that a config may set."""
    signature = inspect.signature(algorithm_class(algorithm).__init__)
    return set(signature.parameters) - {"self"} - RESERVED
