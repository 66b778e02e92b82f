"""A permutation-equivariant, masked Q-network over cluster slots, and the DQN that uses it.

For the ``explorer`` observation (``{"slots": (S, F), "action_mask": (S,)}``,
:mod:`frontier_marl.slot_features`): one shared network encodes every slot from its own
features, a pooled context (mean and max over the live slots) is appended to each, and a second
shared network scores it. Reordering the slots reorders the Q-values the same way, so the order
of the slots carries no meaning (the thesis's sorted/unsorted pathology cannot arise), and the
network's size depends neither on the number of slots nor on the map.

Masking: the Q-values of masked slots are :data:`MASKED_Q`, so the greedy argmax and the
target's max over next actions only ever pick valid slots; :class:`MaskedDQN` draws its
epsilon-random actions among the valid slots too.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3 import DQN
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from stable_baselines3.dqn.policies import DQNPolicy, QNetwork
from torch import nn

MASKED_Q = -1e9  # the Q-value of a masked slot: below any return


def _mlp(sizes: list[int], activation: type[nn.Module]) -> nn.Sequential:
    layers: list[nn.Module] = []
    for size_in, size_out in zip(sizes[:-1], sizes[1:], strict=True):
        layers += [nn.Linear(size_in, size_out), activation()]
    return nn.Sequential(*layers)


class SlotExtractor(BaseFeaturesExtractor):
    """Passes the slot features and the mask through, flattened: ``(B, S * F + S)``."""

    def __init__(self, observation_space: spaces.Dict) -> None:
        slots = observation_space["slots"]
        if not isinstance(slots, spaces.Box) or len(slots.shape) != 2:
            raise ValueError("the slot scorer needs the explorer observation (features='explorer')")
        self.n_slots, self.n_features = slots.shape
        super().__init__(observation_space, self.n_slots * (self.n_features + 1))

    def forward(self, observations: dict[str, th.Tensor]) -> th.Tensor:
        slots = observations["slots"].flatten(start_dim=1)
        return th.cat([slots, observations["action_mask"].float()], dim=1)


class SlotScorer(nn.Module):
    """Q-values of S slots from ``(B, S * F + S)`` (features, then mask): a shared encoder
    per slot, mean and max pooling over the live slots, a shared scorer per slot."""

    def __init__(
        self, n_slots: int, n_features: int, hidden: list[int], activation: type[nn.Module]
    ) -> None:
        super().__init__()
        self.n_slots, self.n_features = n_slots, n_features
        width = hidden[-1]
        self.encode = _mlp([n_features, *hidden], activation)
        self.score = nn.Sequential(_mlp([3 * width, *hidden], activation), nn.Linear(width, 1))

    def forward(self, flat: th.Tensor) -> th.Tensor:
        batch, s, f = flat.shape[0], self.n_slots, self.n_features
        slots = flat[:, : s * f].reshape(batch, s, f)
        mask = flat[:, s * f :] > 0.5
        encoded = self.encode(slots)  # (B, S, H)
        live = mask.unsqueeze(-1)
        count = live.sum(dim=1).clamp(min=1)
        mean = (encoded * live).sum(dim=1) / count
        top = encoded.masked_fill(~live, -th.inf).max(dim=1).values
        top = th.where(th.isfinite(top), top, th.zeros_like(top))
        context = th.cat([mean, top], dim=1).unsqueeze(1).expand(-1, s, -1)
        q_values = self.score(th.cat([encoded, context], dim=2)).squeeze(-1)
        return q_values.masked_fill(~mask, MASKED_Q)


class SlotQNetwork(QNetwork):
    """SB3's ``QNetwork`` with :class:`SlotScorer` as its head (``net_arch``: hidden sizes)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        extractor = self.features_extractor
        assert isinstance(extractor, SlotExtractor)
        self.q_net = SlotScorer(
            extractor.n_slots, extractor.n_features, list(self.net_arch), self.activation_fn
        )


class SlotDQNPolicy(DQNPolicy):
    """DQN policy with :class:`SlotQNetwork` (online and target)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("features_extractor_class", SlotExtractor)
        super().__init__(*args, **kwargs)

    def make_q_net(self) -> SlotQNetwork:
        net_args = self._update_features_extractor(self.net_args, features_extractor=None)
        return SlotQNetwork(**net_args).to(self.device)


class MaskedDQN(DQN):
    """DQN whose epsilon-random actions are drawn among the valid slots (the observation's
    ``action_mask``); with :class:`SlotDQNPolicy` its greedy and target actions are masked
    too."""

    policy_aliases = {**DQN.policy_aliases, "SlotPolicy": SlotDQNPolicy}  # noqa: RUF012

    def predict(
        self,
        observation: np.ndarray | dict[str, np.ndarray],
        state: tuple[np.ndarray, ...] | None = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = False,
    ) -> tuple[np.ndarray, tuple[np.ndarray, ...] | None]:
        if deterministic or np.random.rand() >= self.exploration_rate:
            return self.policy.predict(observation, state, episode_start, deterministic)
        return self._random_valid(observation), state

    def _sample_action(
        self, learning_starts: int, action_noise: Any = None, n_envs: int = 1
    ) -> tuple[np.ndarray, np.ndarray]:
        if self.num_timesteps < learning_starts:  # SB3 would draw among every action here
            actions = self._random_valid(self._last_obs)
            return actions, actions
        return super()._sample_action(learning_starts, action_noise, n_envs)

    def _random_valid(self, observation: Any) -> np.ndarray:
        """One uniformly random valid slot per observation (the action space's generator)."""
        assert isinstance(observation, dict)
        mask = np.asarray(observation["action_mask"])
        masks = mask.reshape(-1, mask.shape[-1]).astype(bool)
        draws = self.action_space.np_random.random(masks.shape)
        actions = np.where(masks, draws, -1.0).argmax(axis=1)
        return actions[0] if mask.ndim == 1 else actions
