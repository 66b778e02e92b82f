"""Privileged targets for a map-aware chooser: each candidate's cost-to-go on the true map.

At every real decision of an episode (two or more valid slots) the robot's world is cloned
once per valid slot into one batch (:func:`frontier_marl.sim.branching.branch`); each clone
walks to that slot's target and a fixed base policy finishes the map, all clones rolled out
together (:func:`frontier_marl.sim.rollouts.rollout_costs`, through
:func:`frontier_marl.policies.lookahead.lookahead_costs`). The cells travelled until
the coverage level are the candidate's cost-to-go. A sample holds what the robot itself sees
of each candidate (its map crops, :mod:`frontier_marl.policies.map_crops`, and its explorer
slot features) and the candidates' costs; a scorer that regresses the costs from those inputs
over many maps learns their expectation under the unknown part of the map.

With ``completions`` K the cost of a candidate is instead its mean over K maps drawn from the
family's generator with the robot's known cells kept
(:func:`~frontier_marl.policies.lookahead.completion_costs`): a target of less noise, under a
generic prior rather than the true map.

The episodes are played by a behaviour policy (``frontier-rule`` first, then the learner:
DAgger, so the learner is trained on the states it visits itself); the labels do not depend on
it. Samples are stored as arrays of fixed shapes (:class:`Samples`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.policies.linear_scorer import explorer_slots
from frontier_marl.policies.lookahead import completion_costs, completion_draws, lookahead_costs
from frontier_marl.policies.map_crops import crop_shape, slot_crops
from frontier_marl.sim.episodes import EpisodeSource
from frontier_marl.sim.rollouts import RolloutBase
from frontier_marl.utils.checks import check_int

#: A behaviour: (observation, the decision's candidate inputs) -> the valid slot it takes.
Behaviour = Callable[[dict[str, np.ndarray], "Candidates"], int]


@dataclass
class Candidates:
    """The valid slots of one decision and what the robot sees of each."""

    slots: np.ndarray  # int (M,): slot indices
    crops: np.ndarray  # float32 (M, C, S, S)
    features: np.ndarray  # float32 (M, F): the explorer slot features


@dataclass
class Samples:
    """Labelled candidates, one row each; ``decision`` groups the rows of one decision."""

    crops: np.ndarray = field(default_factory=lambda: np.zeros((0, *crop_shape()), np.uint8))
    features: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), np.float32))
    cost: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float64))
    decision: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    family: np.ndarray = field(default_factory=lambda: np.zeros(0, "U16"))

    def __len__(self) -> int:
        return len(self.cost)

    def save(self, path: Path) -> None:
        np.savez_compressed(path, **{f.name: getattr(self, f.name) for f in fields(self)})

    @classmethod
    def load(cls, path: Path) -> Samples:
        with np.load(path) as data:
            return cls(**{f.name: data[f.name] for f in fields(cls)})

    @classmethod
    def join(cls, parts: Sequence[Samples]) -> Samples:
        """One set of samples; decision numbers stay distinct across the parts."""
        parts = [p for p in parts if len(p)]
        if not parts:
            return cls()
        offsets = np.cumsum([0] + [int(p.decision.max()) + 1 for p in parts[:-1]])
        return cls(
            crops=np.concatenate([p.crops for p in parts]),
            features=np.concatenate([p.features for p in parts]),
            cost=np.concatenate([p.cost for p in parts]),
            decision=np.concatenate([p.decision + o for p, o in zip(parts, offsets, strict=True)]),
            family=np.concatenate([p.family for p in parts]),
        )


def decision_candidates(env: FrontierParallelEnv, obs: dict[str, np.ndarray]) -> Candidates:
    """The valid slots of robot 0's decision in ``env`` (explorer observation ``obs``)."""
    slots, mask = explorer_slots(obs)
    valid = np.flatnonzero(mask > 0)
    return Candidates(valid, slot_crops(env, valid), slots[valid].astype(np.float32))


def label_episode(
    cfg: EnvConfig,
    seed: int,
    behaviour: Behaviour,
    base: RolloutBase | None = None,
    family: str = "",
    completions: int = 0,
    every: int = 1,
) -> Samples:
    """Play one episode (reset ``seed``) with ``behaviour`` and label every ``every``-th real
    decision's candidates (the first, then each ``every`` later) with their cost-to-go
    (``base`` finishing each clone, nearest-path by default); with ``completions`` K >= 1,
    with their mean cost-to-go over K maps drawn from ``cfg``'s generator that complete the
    belief (no true map; nearest-path finishing)."""
    if completions and base is not None:
        raise ValueError("map completions are finished by nearest-path: pass no base")
    check_int("every", every, 1)
    source = EpisodeSource(cfg) if completions else None
    env = FrontierParallelEnv(config=cfg)
    rows: list[tuple[Candidates, np.ndarray]] = []
    decisions = 0
    observations, _ = env.reset(seed=seed)
    while env.agents:
        obs = observations["robot_0"]
        _, mask = explorer_slots(obs)
        action = int(np.argmax(mask))
        if int(mask.sum()) > 1:
            candidates = decision_candidates(env, obs)
            if decisions % every == 0:
                rows.append((candidates, _costs(env, candidates, base, source, completions, seed)))
            decisions += 1
            action = behaviour(obs, candidates)
        observations, *_ = env.step({"robot_0": action})
    env.close()
    return _samples(rows, family)


def _costs(
    env: FrontierParallelEnv,
    candidates: Candidates,
    base: RolloutBase | None,
    source: EpisodeSource | None,
    completions: int,
    seed: int,
) -> np.ndarray:
    """The candidates' cost-to-go (:func:`label_episode`)."""
    cfg, world = env.config, env.world
    targets = env.mdp.slot_tables()[0].target[candidates.slots]
    coverage, cap = cfg.reward.explore_threshold, 4 * cfg.height * cfg.width
    if source is not None:
        maps = completion_draws(source, world.belief, world.positions, completions, seed)
        costs = completion_costs(world.batch, world.index, targets, coverage, cap, maps)
    else:
        costs = lookahead_costs(world.batch, world.index, targets, coverage, cap, base)
    return costs.astype(np.float64)


def _samples(rows: list[tuple[Candidates, np.ndarray]], family: str) -> Samples:
    if not rows:
        return Samples()
    crops = np.concatenate([c.crops for c, _ in rows])
    return Samples(
        crops=np.round(crops * 255).astype(np.uint8),
        features=np.concatenate([c.features for c, _ in rows]),
        cost=np.concatenate([cost for _, cost in rows]),
        decision=np.concatenate([np.full(len(cost), i) for i, (_, cost) in enumerate(rows)]),
        family=np.full(len(crops), family, dtype="U16"),
    )


def relative_regret(cost: np.ndarray, decision: np.ndarray, cap: float = 1.0) -> np.ndarray:
    """Per candidate, its cost over the cheapest of its decision's, minus 1, capped at
    ``cap`` (a candidate twice as dear as the best is as bad as any worse one)."""
    best = np.full(int(decision.max()) + 1, np.inf)
    np.minimum.at(best, decision, cost)
    cheapest = np.maximum(best[decision], 1.0)  # a cost of 0 (nothing left) counts as 1
    return np.minimum(np.maximum(cost, 1.0) / cheapest - 1.0, cap)


def cells_regret(
    cost: np.ndarray, decision: np.ndarray, scale: np.ndarray, cap: float = 1.5
) -> np.ndarray:
    """Per candidate, the cells it costs beyond the cheapest of its decision's, over its
    ``scale`` (cells, per candidate: the map's side, so that every decision of every map size
    weighs by its share of an episode), capped at ``cap``."""
    best = np.full(int(decision.max()) + 1, np.inf)
    np.minimum.at(best, decision, cost)
    return np.minimum((cost - best[decision]) / scale, cap)


def first_choice_of(scores: Callable[[dict[str, np.ndarray], Candidates], np.ndarray]) -> Any:
    """A behaviour taking the candidate of lowest ``scores`` (ties: the lower slot)."""

    def behaviour(obs: dict[str, np.ndarray], candidates: Candidates) -> int:
        return int(candidates.slots[int(np.argmin(scores(obs, candidates)))])

    return behaviour
