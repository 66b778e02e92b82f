"""Imitation of the lookahead teacher (DAgger) for the slot scorer.

Each round plays episodes of the training families, labels every real decision (more than one
valid slot) with the teacher's cost of each valid slot (:func:`~frontier_marl.training.
lookahead.lookahead_costs`: cells travelled until 99 % coverage after choosing it), and adds
them to one growing dataset. Round 0 follows the teacher; round ``i`` follows it with
probability ``beta ** i`` per decision and the student otherwise, so later rounds label the
states the student itself reaches (DAgger). After each round the student's Q-network is fitted
on the whole dataset: its Q-value of a slot regresses on minus the slot's extra cost over the
cheapest one, in :data:`~frontier_marl.sim.features.CELLS` units, so its greedy choice
approximates the teacher's from the robot's own observation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch as th

from frontier_marl.config import EnvConfig
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.evaluation.benchmark.families import COVERAGE
from frontier_marl.policies.lookahead import lookahead_costs
from frontier_marl.sim.features import CELLS

Actor = Callable[[dict[str, np.ndarray]], int]


@dataclass
class Dataset:
    """Labelled decisions: slot features (N, S, F), masks (N, S), costs (N, S) (NaN: invalid)."""

    slots: list[np.ndarray] = field(default_factory=list)
    masks: list[np.ndarray] = field(default_factory=list)
    costs: list[np.ndarray] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.slots)

    def add(self, obs: dict[str, np.ndarray], costs: np.ndarray) -> None:
        self.slots.append(np.array(obs["slots"], dtype=np.float32))
        self.masks.append(np.array(obs["action_mask"], dtype=np.int8))
        self.costs.append(costs.astype(np.float32))

    def extend(self, other: Dataset) -> None:
        self.slots += other.slots
        self.masks += other.masks
        self.costs += other.costs

    def tensors(self) -> tuple[th.Tensor, th.Tensor, th.Tensor, th.Tensor]:
        """Features, masks, targets (minus the extra cost in CELLS units) and validity."""
        costs = np.stack(self.costs)
        valid = ~np.isnan(costs)
        extra = (costs - np.nanmin(costs, axis=1, keepdims=True)) / CELLS
        targets = np.where(valid, -extra, 0.0).astype(np.float32)
        return (
            th.as_tensor(np.stack(self.slots)),
            th.as_tensor(np.stack(self.masks)),
            th.as_tensor(targets),
            th.as_tensor(valid),
        )


def play(
    env: Any,
    seed: int,
    data: Dataset,
    student: Actor | None,
    follow_teacher: float,
    rng: np.random.Generator,
) -> int:
    """One labelled episode of one robot in ``env`` (a FrontierParallelEnv with the explorer
    observation in the flat layout); returns the cells travelled. A decision follows the
    teacher with probability ``follow_teacher`` (always without a ``student``)."""
    observations, _ = env.reset(seed=seed)
    height, width = env.config.shape
    done = False
    while not done:
        obs = observations["robot_0"]
        valid = np.flatnonzero(obs["action_mask"])
        action = int(valid[0]) if len(valid) else 0
        if len(valid) > 1:
            world = env.world
            targets = env.mdp.slot_tables()[0].target[valid]
            valid_costs = lookahead_costs(
                world.batch, world.index, targets, COVERAGE, 4 * height * width
            )
            costs = np.full(len(obs["action_mask"]), np.nan)
            costs[valid] = valid_costs
            data.add(obs, costs)
            if student is None or rng.random() < follow_teacher:
                action = int(valid[np.argmin(valid_costs)])
            else:
                action = student(obs)
        observations, _, terminations, truncations, _ = env.step({"robot_0": action})
        done = terminations["robot_0"] or truncations["robot_0"]
    return int(env.world.travelled[0])


def collect(
    configs: Sequence[EnvConfig],
    seeds: Sequence[Sequence[int]],
    data: Dataset,
    student: Actor | None,
    follow_teacher: float,
    rng: np.random.Generator,
    on_episode: Callable[[], None] | None = None,
) -> None:
    """Episodes ``seeds[i]`` of config ``configs[i]`` into ``data`` (see :func:`play`)."""
    for cfg, family_seeds in zip(configs, seeds, strict=True):
        env = FrontierParallelEnv(config=cfg, obs_layout="flat")
        try:
            for seed in family_seeds:
                play(env, int(seed), data, student, follow_teacher, rng)
                if on_episode is not None:
                    on_episode()
        finally:
            env.close()


def fit(
    q_net: th.nn.Module,
    data: Dataset,
    epochs: int,
    batch_size: int,
    learning_rate: float,
    generator: th.Generator,
) -> list[float]:
    """Fit ``q_net`` (SB3's QNetwork over the explorer observation) to ``data``; the mean
    squared error over valid slots per epoch."""
    slots, masks, targets, valid = data.tensors()
    optimizer = th.optim.Adam(q_net.parameters(), lr=learning_rate)
    losses = []
    q_net.train()
    for _ in range(epochs):
        order = th.randperm(len(slots), generator=generator)
        total, count = 0.0, 0
        for start in range(0, len(order), batch_size):
            batch = order[start : start + batch_size]
            q_values = q_net({"slots": slots[batch], "action_mask": masks[batch]})
            error = th.where(valid[batch], q_values - targets[batch], th.zeros_like(q_values))
            loss = (error**2).sum() / valid[batch].sum()
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
            total += loss.item() * len(batch)
            count += len(batch)
        losses.append(total / count)
    q_net.eval()
    return losses
