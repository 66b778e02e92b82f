"""The map-aware candidate scorer: a small CNN over each candidate's map crops, its slot
features, and a context pooled over all candidates; it predicts each candidate's relative
regret (cost-to-go over the cheapest candidate's, minus 1).

One network scores every candidate (permutation-equivariant: reordering the candidates
reorders the scores; the pooled context does not depend on the order), any number of
candidates, any map size (the crops of :mod:`frontier_marl.policies.map_crops`). Needs torch
only.
"""

from __future__ import annotations

import torch
from torch import nn


class MapScorer(nn.Module):
    """``forward(crops (n, C, S, S), features (B, M, F), mask (B, M) bool)`` -> predicted
    regret (B, M); masked candidates get ``+inf``. ``crops`` are the valid candidates' only,
    in the order of ``mask``'s true entries (``padded_crops[mask]``; one decision's M
    candidates, all valid, are simply its (M, C, S, S) crops), so the padding is never
    convolved. ``features`` are normalised inside with the stored
    ``feature_mean``/``feature_std``."""

    def __init__(self, channels: int, side: int, n_features: int, width: int = 32) -> None:
        super().__init__()
        reduced = (side + 3) // 4  # after two stride-2 convolutions
        self.conv = nn.Sequential(
            nn.Conv2d(channels, width, 3, padding=1),
            nn.ReLU(),
            nn.Conv2d(width, width, 3, stride=2, padding=1),
            nn.ReLU(),
            nn.Conv2d(width, width, 3, stride=2, padding=1),
            nn.ReLU(),
            nn.Flatten(),
            nn.Linear(width * reduced * reduced, width),
            nn.ReLU(),
        )
        self.embed = nn.Sequential(nn.Linear(width + n_features, 2 * width), nn.ReLU())
        self.head = nn.Sequential(
            nn.Linear(6 * width, 2 * width), nn.ReLU(), nn.Linear(2 * width, 1)
        )
        self.register_buffer("feature_mean", torch.zeros(n_features))
        self.register_buffer("feature_std", torch.ones(n_features))

    def forward(
        self, crops: torch.Tensor, features: torch.Tensor, mask: torch.Tensor
    ) -> torch.Tensor:
        batch, count = mask.shape
        if len(crops) != int(mask.sum()):
            raise ValueError(f"{len(crops)} crops for {int(mask.sum())} valid candidates")
        seen = crops.new_zeros(batch, count, self.conv[-2].out_features)
        seen[mask] = self.conv(crops)
        scaled = (features - self.feature_mean) / self.feature_std
        embedded = self.embed(torch.cat([seen, scaled], dim=-1))  # (B, M, E)
        weights = mask.unsqueeze(-1).to(embedded.dtype)
        mean = (embedded * weights).sum(1) / weights.sum(1).clamp(min=1.0)
        largest = embedded.masked_fill(~mask.unsqueeze(-1), -1e9).max(1).values
        context = torch.cat([mean, largest], dim=-1).unsqueeze(1).expand(-1, count, -1)
        regret = self.head(torch.cat([embedded, context], dim=-1)).squeeze(-1)
        return regret.masked_fill(~mask, float("inf"))
