"""Fitting the map-aware scorer to the privileged costs (:mod:`~frontier_marl.training.cost_to_go`).

The samples are grouped by decision (at most ``n_slots`` candidates, a mask for the rest;
the crops stored once per candidate, unpadded). The target of each candidate is its relative regret
(:func:`~frontier_marl.training.cost_to_go.relative_regret`). The shipped fit's loss is the
mean squared error over the valid candidates (``"regret"`` of :data:`LOSSES`). The ablation
(:mod:`~frontier_marl.experiments.explorer_studies.map_scorer_ablation`) also fits a listwise
``"ranking"`` loss, ``"argmax"`` imitation of the cheapest candidate, and the regret in cells
over the map's side. Each batch is seen in one of the eight symmetries of the square (the
crops rotated or mirrored, the target's row and column offsets turned alike), so the scorer
learns that a corridor going north is a corridor going east. A scorer of several members
(:class:`~frontier_marl.policies.networks.map_scorer.MapScorer`) fits each member on its own
loss (:func:`members_loss`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

from frontier_marl.policies.networks.map_scorer import MapScorer
from frontier_marl.training.cost_to_go import Samples, cells_regret, relative_regret
from frontier_marl.training.settings import SCHEDULES

#: Columns of the explorer features that are offsets on the grid: (row, col).
OFFSET_COLUMNS = (2, 3)
#: The fit's losses: squared error on the regret; cross entropy between the scorer's softmax
#: over the candidates (of minus the predicted regret) and the softmax of minus the true regret
#: over :data:`RANKING_TEMPERATURE` (``"ranking"``) or the cheapest candidate (``"argmax"``).
LOSSES = ("regret", "ranking", "argmax")
RANKING_TEMPERATURE = 0.05  # a regret 0.05 dearer than another: e times less likely


@dataclass
class Decisions:
    """Samples grouped by decision: ``features`` float32 (D, M, F), ``regret`` float32
    (D, M) the fit's target, ``mask`` bool (D, M), ``extra`` float32 (D, M) each candidate's
    cells beyond its decision's cheapest (uncapped). The crops are stored once per candidate,
    unpadded: ``crops`` uint8 (N, C, S, S), and ``rows`` int64 (D, M) the row of each valid
    candidate's crops (0 on padding)."""

    crops: torch.Tensor
    rows: torch.Tensor
    features: torch.Tensor
    regret: torch.Tensor
    mask: torch.Tensor
    extra: torch.Tensor

    def __len__(self) -> int:
        return len(self.mask)

    def subset(self, rows: np.ndarray | torch.Tensor) -> Decisions:
        """The decisions ``rows`` (their crops are shared, not copied)."""
        index = torch.as_tensor(rows)
        return Decisions(
            self.crops,
            self.rows[index],
            self.features[index],
            self.regret[index],
            self.mask[index],
            self.extra[index],
        )

    def valid_crops(self) -> torch.Tensor:
        """(n, C, S, S) float crops in [0, 1] of the valid candidates, in ``mask`` order: the
        scorer's input."""
        return self.crops[self.rows[self.mask]].float() / 255.0


def group(samples: Samples, n_slots: int, scale: np.ndarray | None = None) -> Decisions:
    """The decisions of ``samples``: features, targets and mask padded to ``n_slots``
    candidates, the crops kept once per candidate (:class:`Decisions`). The target is the
    relative regret, or with ``scale`` (cells, per sample) the regret in cells over it
    (:func:`~frontier_marl.training.cost_to_go.cells_regret`)."""
    _, order, counts = np.unique(samples.decision, return_inverse=True, return_counts=True)
    if counts.max() > n_slots:
        raise ValueError(f"a decision has {counts.max()} candidates, more than {n_slots}")
    rank = np.empty(len(samples), dtype=np.int64)  # candidates keep their order in a decision
    by_decision = np.argsort(order, kind="stable")
    rank[by_decision] = np.arange(len(samples)) - np.repeat(np.cumsum(counts) - counts, counts)
    shape = (len(counts), n_slots)
    rows = np.zeros(shape, dtype=np.int64)
    features = np.zeros((*shape, samples.features.shape[1]), dtype=np.float32)
    regret = np.zeros(shape, dtype=np.float32)
    mask = np.zeros(shape, dtype=bool)
    rows[order, rank] = np.arange(len(samples))
    features[order, rank] = samples.features
    regret[order, rank] = (
        relative_regret(samples.cost, order)
        if scale is None
        else cells_regret(samples.cost, order, scale)
    )
    mask[order, rank] = True
    extra = np.zeros(shape, dtype=np.float32)
    extra[order, rank] = cells_regret(samples.cost, order, np.ones(len(samples)), np.inf)
    arrays = (samples.crops, rows, features, regret, mask, extra)
    return Decisions(*(torch.as_tensor(a) for a in arrays))


def family_weights(samples: Samples, balance: float = 1.0) -> torch.Tensor:
    """One weight per decision (in :func:`group`'s order): its family's number of decisions
    to the power ``-balance``, so that a family's total grows as its decisions to the power
    ``1 - balance`` (1: every family of ``samples`` the same total; 0: every decision the
    same weight)."""
    _, first = np.unique(samples.decision, return_index=True)
    families = samples.family[first]
    _, which, counts = np.unique(families, return_inverse=True, return_counts=True)
    return torch.as_tensor(counts[which].astype(np.float64) ** -balance, dtype=torch.float64)


def symmetry(crops: torch.Tensor, features: torch.Tensor, k: int) -> tuple[torch.Tensor, ...]:
    """The ``k``-th of the square's eight symmetries (``k // 2`` quarter turns, mirrored if
    ``k`` is odd) applied to the crops' last two axes and to the offset features."""
    row, col = OFFSET_COLUMNS
    crops = torch.rot90(crops, k // 2, dims=(-2, -1))
    features = features.clone()
    for _ in range(k // 2):  # a quarter turn takes (row, col) offsets to (-col, row)
        features[..., row], features[..., col] = -features[..., col], features[..., row].clone()
    if k % 2:
        crops = torch.flip(crops, dims=(-2,))
        features[..., row] = -features[..., row]
    return crops, features


def fit(
    model: MapScorer,
    train: Decisions,
    epochs: int,
    batch_size: int = 64,
    learning_rate: float = 1e-3,
    seed: int = 0,
    on_epoch: object = None,
    loss: str = "regret",
    weights: torch.Tensor | None = None,
    schedule: str = "constant",
) -> list[float]:
    """Adam on ``loss`` (:data:`LOSSES`); returns the mean training loss of each epoch.

    Each epoch sees every decision once in a random order, or with ``weights`` (one per
    decision) as many decisions drawn with replacement in proportion to them. The step size is
    ``learning_rate`` throughout (``schedule`` "constant") or falls from it to zero along a
    half cosine over the fit's steps ("cosine", :data:`SCHEDULES`)."""
    if loss not in LOSSES:
        raise ValueError(f"unknown loss {loss!r}; choose one of {', '.join(LOSSES)}")
    if schedule not in SCHEDULES:
        raise ValueError(f"unknown schedule {schedule!r}; choose one of {', '.join(SCHEDULES)}")
    if weights is not None and weights.shape != (len(train),):
        raise ValueError(
            f"weights must have one entry per decision ({len(train)}), "
            f"got shape {tuple(weights.shape)}"
        )
    generator = torch.Generator().manual_seed(seed)
    optimiser = torch.optim.Adam(model.parameters(), lr=learning_rate)
    steps = max(1, epochs * -(-len(train) // batch_size))
    rate = torch.optim.lr_scheduler.LambdaLR(
        optimiser, lambda step: step_size_factor(schedule, step, steps)
    )
    losses = []
    for epoch in range(epochs):
        if weights is None:
            order = torch.randperm(len(train), generator=generator)
        else:
            order = torch.multinomial(weights, len(train), True, generator=generator)
        total, batches = 0.0, 0
        model.train()
        for start in range(0, len(train), batch_size):
            batch = train.subset(order[start : start + batch_size])
            k = int(torch.randint(8, (1,), generator=generator))
            crops, features = symmetry(batch.valid_crops(), batch.features, k)
            value = members_loss(loss, model.member_regrets(crops, features, batch.mask), batch)
            optimiser.zero_grad()
            value.backward()
            optimiser.step()
            rate.step()
            total, batches = total + value.item(), batches + 1
        losses.append(total / max(batches, 1))
        if callable(on_epoch):
            on_epoch(epoch, losses[-1])
    return losses


def step_size_factor(schedule: str, step: int, steps: int) -> float:
    """The fraction of the initial step size at ``step`` of ``steps`` under ``schedule``
    (:data:`~frontier_marl.training.settings.SCHEDULES`)."""
    if schedule == "constant":
        return 1.0
    return 0.5 + 0.5 * math.cos(math.pi * min(step, steps) / steps)


def members_loss(kind: str, predicted: torch.Tensor, batch: Decisions) -> torch.Tensor:
    """The mean over the scorer's members of each one's ``kind`` loss on ``batch``, from their
    predictions (B, M, members): every member is fitted on its own."""
    batch_size, count, members = predicted.shape
    folded = predicted.permute(0, 2, 1).reshape(batch_size * members, count)
    regret = batch.regret.repeat_interleave(members, dim=0)
    return batch_loss(kind, folded, regret, batch.mask.repeat_interleave(members, dim=0))


def batch_loss(
    kind: str, predicted: torch.Tensor, regret: torch.Tensor, mask: torch.Tensor
) -> torch.Tensor:
    """The ``kind`` loss (:data:`LOSSES`) of one batch of decisions."""
    if kind == "regret":
        return ((predicted - regret)[mask] ** 2).mean()
    if kind == "ranking":
        target = torch.softmax((-regret / RANKING_TEMPERATURE).masked_fill(~mask, -1e9), dim=1)
    else:
        cheapest = regret.masked_fill(~mask, float("inf")).argmin(dim=1)
        target = torch.nn.functional.one_hot(cheapest, mask.shape[1]).to(predicted.dtype)
    chosen = torch.log_softmax((-predicted).masked_fill(~mask, -1e9), dim=1)
    return -(target * chosen).masked_fill(~mask, 0.0).sum(dim=1).mean()


@torch.no_grad()
def predict(model: MapScorer, data: Decisions, batch_size: int = 256) -> torch.Tensor:
    """(D, M) predicted regret (``inf`` on padding)."""
    model.eval()
    parts = []
    for start in range(0, len(data), batch_size):
        batch = data.subset(torch.arange(start, min(start + batch_size, len(data))))
        parts.append(model(batch.valid_crops(), batch.features, batch.mask))
    return torch.cat(parts)


def chosen_regret(scores: torch.Tensor, data: Decisions) -> float:
    """The mean true regret of the candidate of lowest ``scores`` in each decision."""
    best = scores.masked_fill(~data.mask, float("inf")).argmin(dim=1)
    return float(data.regret[torch.arange(len(data)), best].mean())
