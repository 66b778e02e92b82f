"""The permutation-equivariant, masked slot scorer as an actor-critic policy (SB3's ``PPO`` and
sb3-contrib's ``MaskablePPO``).

The actor is a slot scorer of :mod:`frontier_marl.policies.networks.slot_dqn` (``scorer = "mlp"``:
:class:`~frontier_marl.policies.networks.slot_dqn.SlotScorer`; ``"linear"``:
:class:`~frontier_marl.policies.networks.slot_dqn.LinearSlotScorer`): its per-slot scores are the
action logits, one shared network for every slot, so reordering the slots reorders the action
probabilities the same way. Masked slots score
:data:`~frontier_marl.policies.networks.slot_dqn.MASKED_Q` (-1e9), so they have probability 0
under plain ``PPO`` too; ``MaskablePPO`` masks them once more from the env's
``action_masks()``. The critic is its own network: a shared per-slot encoder, mean and max
pooling over the live slots, and an MLP to the state value (it does not depend on the slot
order either).

    from stable_baselines3 import PPO
    from frontier_marl.policies.networks.slot_actor_critic import SlotActorCriticPolicy
    model = PPO(SlotActorCriticPolicy, vec_env, policy_kwargs={"net_arch": [64, 64]})

    from sb3_contrib import MaskablePPO
    from frontier_marl.policies.networks.slot_actor_critic import MaskableSlotActorCriticPolicy
    model = MaskablePPO(MaskableSlotActorCriticPolicy, vec_env)

``frontier-marl train`` builds them with ``train.algorithm = "ppo"`` or ``"maskable-ppo"`` and
``train.policy = "slot-scorer"``.
"""

from __future__ import annotations

from typing import Any

import torch as th
from sb3_contrib.common.maskable.policies import MaskableActorCriticPolicy
from stable_baselines3.common.policies import ActorCriticPolicy
from torch import nn

from frontier_marl.policies.networks.slot_dqn import (
    LinearSlotScorer,
    SlotExtractor,
    make_scorer,
    mlp_layers,
    pool_live,
    split_slots,
)

DEFAULT_HIDDEN = (64, 64)


class SlotValue(nn.Module):
    """The state value from ``(B, S * F + S)``: a shared per-slot encoder, mean and max pooling
    over the live slots, and an MLP to one number (``(B, 1)``)."""

    def __init__(
        self, n_slots: int, n_features: int, hidden: list[int], activation: type[nn.Module]
    ) -> None:
        super().__init__()
        self.n_slots, self.n_features = n_slots, n_features
        self.encode = mlp_layers([n_features, *hidden], activation)
        width = hidden[-1]
        self.value = nn.Sequential(mlp_layers([2 * width, width], activation), nn.Linear(width, 1))

    def forward(self, flat: th.Tensor) -> th.Tensor:
        slots, mask = split_slots(flat, self.n_slots, self.n_features)
        pooled, _, _ = pool_live(self.encode(slots), mask)
        return self.value(pooled)


class SlotActorCritic(nn.Module):
    """SB3's ``mlp_extractor`` role: ``forward`` gives the actor's masked slot logits ``(B, S)``
    and the critic's value ``(B, 1)``; the policy's ``action_net`` and ``value_net`` are
    identities.

    ``prior`` (one weight per slot feature) starts the actor at the linear scorer with those
    weights: the linear scorer's weights themselves (``scorer = "linear"``), or a trainable
    linear scorer plus the MLP scorer, whose output layer starts at zero (``"mlp"``), so that
    the MLP learns a correction to the prior. ``logit_scale`` multiplies the actor's scores
    into logits: with a prior in the linear scorer's own units (a path weight of -1 per 32
    cells), 32 makes one cell of path one unit of logit, while the weights the optimizer
    moves stay of order 1."""

    def __init__(
        self,
        extractor: SlotExtractor,
        hidden: list[int],
        activation: type[nn.Module],
        scorer: str,
        attention_heads: int,
        prior: list[float] | None = None,
        logit_scale: float = 1.0,
    ) -> None:
        super().__init__()
        number = isinstance(logit_scale, int | float) and not isinstance(logit_scale, bool)
        if not number or not 0 < logit_scale < 1e4:
            raise ValueError(f"logit_scale must be a number in (0, 1e4), got {logit_scale!r}")
        self.logit_scale = float(logit_scale)
        self.actor = make_scorer(scorer, extractor, hidden, activation, attention_heads)
        self.critic = SlotValue(extractor.n_slots, extractor.n_features, hidden, activation)
        self.latent_dim_pi, self.latent_dim_vf = extractor.n_slots, 1
        self.prior: LinearSlotScorer | None = None
        if prior is None:
            return
        if len(prior) != extractor.n_features:
            raise ValueError(
                f"prior has {len(prior)} weights; the observation has {extractor.n_features} "
                "slot features"
            )
        weights = th.as_tensor(prior, dtype=th.float32)
        with th.no_grad():
            if isinstance(self.actor, LinearSlotScorer):
                self.actor.weight.copy_(weights)
                return
            self.prior = LinearSlotScorer(extractor.n_slots, extractor.n_features)
            self.prior.weight.copy_(weights)
            output = self.actor.score[-1]
            output.weight.zero_()
            output.bias.zero_()

    def forward(self, features: th.Tensor) -> tuple[th.Tensor, th.Tensor]:
        return self.forward_actor(features), self.forward_critic(features)

    def forward_actor(self, features: th.Tensor) -> th.Tensor:
        logits = self.actor(features)
        if self.prior is not None:
            logits = logits + self.prior(features)  # masked slots: -2e9
        return logits * self.logit_scale

    def forward_critic(self, features: th.Tensor) -> th.Tensor:
        return self.critic(features)


class _SlotActorCriticMixin:
    """What both policy classes share: the slot extractor, :class:`SlotActorCritic` in place of
    SB3's MLP extractor, identity action and value heads, and the extra constructor keywords
    (``scorer``, ``attention_heads``, ``prior``, ``logit_scale``: :class:`SlotActorCritic`)
    saved with the model."""

    masks_invalid_slots = True  # masked slots have probability 0

    def __init__(
        self,
        *args: Any,
        scorer: str = "mlp",
        attention_heads: int = 0,
        prior: list[float] | None = None,
        logit_scale: float = 1.0,
        net_arch: list[int] | None = None,
        ortho_init: bool = False,
        **kwargs: Any,
    ) -> None:
        if ortho_init:
            raise ValueError("the slot actor-critic uses torch's default init: ortho_init=False")
        hidden = list(DEFAULT_HIDDEN if net_arch is None else net_arch)
        if not hidden or not all(isinstance(h, int) and h > 0 for h in hidden):
            raise ValueError(
                f"net_arch of the slot actor-critic must be a list of hidden sizes > 0 (one "
                f"network for actor and critic alike), got {net_arch!r}"
            )
        kwargs.setdefault("features_extractor_class", SlotExtractor)
        # read by _build_mlp_extractor during super().__init__
        self.scorer, self.attention_heads, self.hidden = scorer, attention_heads, hidden
        self.prior = None if prior is None else [float(w) for w in prior]
        self.logit_scale = logit_scale
        super().__init__(*args, net_arch=hidden, ortho_init=False, **kwargs)  # type: ignore[call-arg]

    def _build_mlp_extractor(self) -> None:
        extractor = self.features_extractor  # type: ignore[attr-defined]
        if not isinstance(extractor, SlotExtractor):
            raise ValueError("the slot actor-critic needs the SlotExtractor features extractor")
        self.mlp_extractor = SlotActorCritic(
            extractor,
            self.hidden,
            self.activation_fn,  # type: ignore[attr-defined]
            self.scorer,
            self.attention_heads,
            self.prior,
            self.logit_scale,
        )

    def _build(self, lr_schedule: Any) -> None:
        self._build_mlp_extractor()
        self.action_net = nn.Identity()
        self.value_net = nn.Identity()
        self.optimizer = self.optimizer_class(  # type: ignore[attr-defined]
            self.parameters(),  # type: ignore[attr-defined]
            lr=lr_schedule(1),
            **self.optimizer_kwargs,  # type: ignore[attr-defined]
        )

    def _get_constructor_parameters(self) -> dict[str, Any]:
        return {
            **super()._get_constructor_parameters(),  # type: ignore[misc]
            "scorer": self.scorer,
            "attention_heads": self.attention_heads,
            "prior": self.prior,
            "logit_scale": self.logit_scale,
            "net_arch": self.hidden,
        }


class SlotActorCriticPolicy(_SlotActorCriticMixin, ActorCriticPolicy):
    """SB3 ``PPO`` policy over the explorer observation: masked, equivariant."""


class MaskableSlotActorCriticPolicy(_SlotActorCriticMixin, MaskableActorCriticPolicy):
    """The same for sb3-contrib's ``MaskablePPO``."""
