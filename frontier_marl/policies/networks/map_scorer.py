"""The map-aware candidate scorer: a small CNN over each candidate's map crops, its slot
features, and a context pooled over all candidates; it predicts each candidate's relative
regret (cost-to-go over the cheapest candidate's, minus 1).

One network scores every candidate (permutation-equivariant: reordering the candidates
reorders the scores; the pooled context does not depend on the order), any number of
candidates, any map size (the crops of :mod:`frontier_marl.policies.map_crops`). Needs torch
only.

With ``members`` K > 1 it is K such scorers, each with its own weights, run as one batched
network (the first convolution has K times the channels, the later layers are grouped) and
averaged: an ensemble at the cost of one network call. Each member is fitted on its own
loss (:meth:`MapScorer.member_regrets`).
"""

from __future__ import annotations

import torch
from torch import nn
from torch.nn import functional


class GroupedLinear(nn.Linear):
    """``members`` independent linear layers of ``in_features -> out_features`` each, on an
    input laid out as ``(..., members * in_features)`` member after member; the output is
    laid out alike. Its weight is ``(members * out_features, in_features)``, so with one
    member it is exactly an ``nn.Linear`` (the same parameters, initialisation and result)."""

    def __init__(self, in_features: int, out_features: int, members: int = 1) -> None:
        super().__init__(in_features, members * out_features)
        self.members = members

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        if self.members == 1:
            return functional.linear(x, self.weight, self.bias)
        k, size = self.members, self.in_features
        out = self.out_features // k
        grouped = x.reshape(*x.shape[:-1], k, size)
        y = torch.einsum("...ki,koi->...ko", grouped, self.weight.view(k, out, size))
        return (y + self.bias.view(k, out)).reshape(*x.shape[:-1], k * out)


class MapScorer(nn.Module):
    """``forward(crops (n, C, S, S), features (B, M, F), mask (B, M) bool)`` -> predicted
    regret (B, M), the mean of the members'; masked candidates get ``+inf``. ``crops`` are
    the valid candidates' only, in the order of ``mask``'s true entries
    (``padded_crops[mask]``; one decision's M candidates, all valid, are simply its
    (M, C, S, S) crops), so the padding is never convolved. ``features`` are normalised
    inside with the stored ``feature_mean``/``feature_std``."""

    def __init__(
        self, channels: int, side: int, n_features: int, width: int = 32, members: int = 1
    ) -> None:
        super().__init__()
        if members < 1 or width < 1:
            raise ValueError(f"a scorer needs width >= 1 and members >= 1, got {width}, {members}")
        self.channels, self.width, self.members = channels, width, members
        reduced = (side + 3) // 4  # after two stride-2 convolutions
        wide = members * width
        self.conv = nn.Sequential(
            nn.Conv2d(channels, wide, 3, padding=1),
            nn.ReLU(),
            nn.Conv2d(wide, wide, 3, stride=2, padding=1, groups=members),
            nn.ReLU(),
            nn.Conv2d(wide, wide, 3, stride=2, padding=1, groups=members),
            nn.ReLU(),
            nn.Flatten(),
            GroupedLinear(width * reduced * reduced, width, members),
            nn.ReLU(),
        )
        self.embed = nn.Sequential(GroupedLinear(width + n_features, 2 * width, members), nn.ReLU())
        self.head = nn.Sequential(
            GroupedLinear(6 * width, 2 * width, members),
            nn.ReLU(),
            GroupedLinear(2 * width, 1, members),
        )
        self.register_buffer("feature_mean", torch.zeros(n_features))
        self.register_buffer("feature_std", torch.ones(n_features))

    def forward(
        self, crops: torch.Tensor, features: torch.Tensor, mask: torch.Tensor
    ) -> torch.Tensor:
        return self.member_regrets(crops, features, mask).mean(-1)

    def member_regrets(
        self, crops: torch.Tensor, features: torch.Tensor, mask: torch.Tensor
    ) -> torch.Tensor:
        """Each member's predicted regret, (B, M, members); ``+inf`` where masked."""
        batch, count = mask.shape
        k = self.members
        if len(crops) != int(mask.sum()):
            raise ValueError(f"{len(crops)} crops for {int(mask.sum())} valid candidates")
        seen = crops.new_zeros(batch, count, k * self.width)
        seen[mask] = self.conv(crops)
        scaled = (features - self.feature_mean) / self.feature_std
        inputs = torch.cat(
            [
                seen.view(batch, count, k, self.width),
                scaled.unsqueeze(2).expand(-1, -1, k, -1),
            ],
            dim=-1,
        )
        embedded = self.embed(inputs.reshape(batch, count, -1))  # (B, M, k * E)
        weights = mask.unsqueeze(-1).to(embedded.dtype)
        mean = (embedded * weights).sum(1) / weights.sum(1).clamp(min=1.0)
        largest = embedded.masked_fill(~mask.unsqueeze(-1), -1e9).max(1).values
        per_member = (batch, count, k, 2 * self.width)
        parts = [
            embedded.view(per_member),
            mean.view(batch, 1, k, -1).expand(per_member),
            largest.view(batch, 1, k, -1).expand(per_member),
        ]
        regret = self.head(torch.cat(parts, dim=-1).reshape(batch, count, -1))  # (B, M, k)
        return regret.masked_fill(~mask.unsqueeze(-1), float("inf"))
