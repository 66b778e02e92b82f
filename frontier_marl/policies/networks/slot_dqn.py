"""A permutation-equivariant, masked Q-network over cluster slots, and the DQN that uses it.

For the ``explorer`` observation (``{"slots": (S, F), "action_mask": (S,)}``,
:mod:`frontier_marl.sim.features`): one shared network encodes every slot from its own
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
from torch.nn import functional as F

MASKED_Q = -1e9  # the Q-value of a masked slot: below any return


def mlp_layers(sizes: list[int], activation: type[nn.Module]) -> nn.Sequential:
    layers: list[nn.Module] = []
    for size_in, size_out in zip(sizes[:-1], sizes[1:], strict=True):
        layers += [nn.Linear(size_in, size_out), activation()]
    return nn.Sequential(*layers)


class SlotExtractor(BaseFeaturesExtractor):
    """Passes the slot features and the mask through, flattened: ``(B, S * F + S)``."""

    def __init__(self, observation_space: spaces.Dict) -> None:
        slots = (
            observation_space.spaces.get("slots")
            if isinstance(observation_space, spaces.Dict)
            else None
        )
        if not isinstance(slots, spaces.Box) or len(slots.shape) != 2:
            raise ValueError("the slot scorer needs the explorer observation (features='explorer')")
        self.n_slots, self.n_features = slots.shape
        super().__init__(observation_space, self.n_slots * (self.n_features + 1))

    def forward(self, observations: dict[str, th.Tensor]) -> th.Tensor:
        slots = observations["slots"].flatten(start_dim=1)
        return th.cat([slots, observations["action_mask"].float()], dim=1)


def split_slots(flat: th.Tensor, n_slots: int, n_features: int) -> tuple[th.Tensor, th.Tensor]:
    """``(B, S * F + S)`` (features, then mask) -> features ``(B, S, F)`` and mask ``(B, S)``."""
    slots = flat[:, : n_slots * n_features].reshape(-1, n_slots, n_features)
    return slots, flat[:, n_slots * n_features :] > 0.5


def pool_live(encoded: th.Tensor, mask: th.Tensor) -> tuple[th.Tensor, th.Tensor, th.Tensor]:
    """Mean and max of the live slots' encodings ``(B, S, H)`` -> pooled ``(B, 2H)`` (zeros
    for a row without a live slot), the live mask ``(B, S, 1)`` and the live count ``(B, 1)``."""
    live = mask.unsqueeze(-1)
    count = live.sum(dim=1).clamp(min=1)
    mean = (encoded * live).sum(dim=1) / count
    top = encoded.masked_fill(~live, -th.inf).max(dim=1).values
    top = th.where(th.isfinite(top), top, th.zeros_like(top))
    return th.cat([mean, top], dim=1), live, count


class SlotScorer(nn.Module):
    """Q-values of S slots from ``(B, S * F + S)`` (features, then mask): a shared encoder
    per slot, optionally one layer of self-attention among the live slots (``attention_heads``
    > 0: each slot sees the others pairwise, not only through the pooled context), mean and
    max pooling over the live slots, a shared advantage scorer per slot and a state value
    from the pooled context (a dueling head)."""

    def __init__(
        self,
        n_slots: int,
        n_features: int,
        hidden: list[int],
        activation: type[nn.Module],
        attention_heads: int = 0,
    ) -> None:
        super().__init__()
        self.n_slots, self.n_features = n_slots, n_features
        width = hidden[-1]
        if isinstance(attention_heads, bool) or not isinstance(attention_heads, int):
            raise ValueError(f"attention_heads must be an integer >= 0, got {attention_heads!r}")
        if attention_heads < 0 or (attention_heads and width % attention_heads):
            raise ValueError(
                f"attention_heads must be >= 0 and divide the last hidden size {width}, "
                f"got {attention_heads}"
            )
        self.encode = mlp_layers([n_features, *hidden], activation)
        self.attend = (
            nn.MultiheadAttention(width, attention_heads, batch_first=True)
            if attention_heads
            else None
        )
        self.score = nn.Sequential(
            mlp_layers([3 * width, *hidden], activation), nn.Linear(width, 1)
        )
        self.value = nn.Sequential(mlp_layers([2 * width, width], activation), nn.Linear(width, 1))

    def forward(self, flat: th.Tensor) -> th.Tensor:
        s = self.n_slots
        slots, mask = split_slots(flat, s, self.n_features)
        encoded = self.encode(slots)  # (B, S, H)
        if self.attend is not None:
            # rows without a live slot (never chosen from) attend to every slot, not to none
            ignored = ~mask & mask.any(dim=1, keepdim=True)
            attended, _ = self.attend(encoded, encoded, encoded, key_padding_mask=ignored)
            encoded = encoded + attended
        pooled, live, count = pool_live(encoded, mask)
        context = pooled.unsqueeze(1).expand(-1, s, -1)
        advantage = self.score(th.cat([encoded, context], dim=2)).squeeze(-1)
        # dueling: a state value from the pooled context plus each slot's advantage, centred
        # on the live slots' mean advantage
        centre = (advantage * live.squeeze(-1)).sum(dim=1, keepdim=True) / count
        q_values = self.value(pooled) + advantage - centre
        return q_values.masked_fill(~mask, MASKED_Q)


class LinearSlotScorer(nn.Module):
    """Q-values of S slots from ``(B, S * F + S)``: one weight per feature, shared by every
    slot (``weight`` (F,)), so a slot's score is the dot product of its features with it.
    Permutation-equivariant like :class:`SlotScorer`; what the cross-entropy method
    (:mod:`frontier_marl.training.cem`) trains."""

    def __init__(self, n_slots: int, n_features: int) -> None:
        super().__init__()
        self.n_slots, self.n_features = n_slots, n_features
        self.weight = nn.Parameter(th.zeros(n_features))

    def forward(self, flat: th.Tensor) -> th.Tensor:
        slots, mask = split_slots(flat, self.n_slots, self.n_features)
        return (slots @ self.weight).masked_fill(~mask, MASKED_Q)


SCORERS = ("mlp", "linear")


def make_scorer(
    scorer: str,
    extractor: SlotExtractor,
    hidden: list[int],
    activation: type[nn.Module],
    attention_heads: int = 0,
) -> nn.Module:
    """The slot scorer named ``scorer`` (:data:`SCORERS`) for ``extractor``'s slots; a
    ValueError names a bad choice."""
    if scorer not in SCORERS:
        raise ValueError(f"scorer must be one of {list(SCORERS)}, got {scorer!r}")
    if scorer == "linear":
        if attention_heads:
            raise ValueError("attention_heads needs scorer='mlp'")
        return LinearSlotScorer(extractor.n_slots, extractor.n_features)
    return SlotScorer(extractor.n_slots, extractor.n_features, hidden, activation, attention_heads)


class SlotQNetwork(QNetwork):
    """SB3's ``QNetwork`` with a slot scorer as its head: :class:`SlotScorer` (``scorer =
    "mlp"``; ``net_arch``: hidden sizes) or :class:`LinearSlotScorer` (``"linear"``)."""

    def __init__(
        self, *args: Any, attention_heads: int = 0, scorer: str = "mlp", **kwargs: Any
    ) -> None:
        super().__init__(*args, **kwargs)
        extractor = self.features_extractor
        assert isinstance(extractor, SlotExtractor)
        self.q_net = make_scorer(
            scorer, extractor, list(self.net_arch), self.activation_fn, attention_heads
        )


class SlotDQNPolicy(DQNPolicy):
    """DQN policy with :class:`SlotQNetwork` (online and target)."""

    masks_invalid_slots = True  # its greedy action is always a valid slot

    def __init__(
        self, *args: Any, attention_heads: int = 0, scorer: str = "mlp", **kwargs: Any
    ) -> None:
        kwargs.setdefault("features_extractor_class", SlotExtractor)
        # read by make_q_net during super().__init__
        self.attention_heads, self.scorer = attention_heads, scorer
        super().__init__(*args, **kwargs)

    def make_q_net(self) -> SlotQNetwork:
        net_args = self._update_features_extractor(self.net_args, features_extractor=None)
        head = {"attention_heads": self.attention_heads, "scorer": self.scorer}
        return SlotQNetwork(**net_args, **head).to(self.device)

    def _get_constructor_parameters(self) -> dict[str, Any]:
        return {
            **super()._get_constructor_parameters(),
            "attention_heads": self.attention_heads,
            "scorer": self.scorer,
        }


class MaskedDQN(DQN):
    """DQN whose epsilon-random actions are drawn among the valid slots (the observation's
    ``action_mask``); with :class:`SlotDQNPolicy` its greedy and target actions are masked
    too. Its TD target is Double DQN's: the online network picks the next action, the target
    network values it (less overestimation of the max over many slots)."""

    policy_aliases = {**DQN.policy_aliases, "SlotPolicy": SlotDQNPolicy}  # noqa: RUF012

    def train(self, gradient_steps: int, batch_size: int = 100) -> None:
        self.policy.set_training_mode(True)
        self._update_learning_rate(self.policy.optimizer)
        losses = []
        for _ in range(gradient_steps):
            data = self.replay_buffer.sample(batch_size, env=self._vec_normalize_env)  # type: ignore[union-attr]
            discounts = data.discounts if data.discounts is not None else self.gamma
            with th.no_grad():
                next_actions = self.q_net(data.next_observations).argmax(dim=1, keepdim=True)
                next_q = th.gather(self.q_net_target(data.next_observations), 1, next_actions)
                target = data.rewards + (1 - data.dones) * discounts * next_q
            current = th.gather(self.q_net(data.observations), 1, data.actions.long())
            loss = F.smooth_l1_loss(current, target)
            losses.append(loss.item())
            self.policy.optimizer.zero_grad()
            loss.backward()
            th.nn.utils.clip_grad_norm_(self.policy.parameters(), self.max_grad_norm)
            self.policy.optimizer.step()
        self._n_updates += gradient_steps
        self.logger.record("train/n_updates", self._n_updates, exclude="tensorboard")
        self.logger.record("train/loss", np.mean(losses))

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
