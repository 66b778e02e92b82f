"""Privileged targets for a team's map-aware chooser: each candidate's makespan to go on the
true map.

A team plays an episode by the protocol of
:class:`~frontier_marl.policies.team_decider.SequentialTeamDecider`. At every real decision of
a robot (two or more candidates) each candidate is rolled out on the true map: the robot heads
for it, the robots that kept or just chose their targets head for theirs, and
:class:`~frontier_marl.sim.team_rollouts.ClaimingNearestBase` finishes the map
(:func:`~frontier_marl.policies.team_lookahead.team_lookahead_costs`, every cost exact). A
sample holds what the robot sees of each candidate (its team crops, with its teammates'
channels, and its slot features) and the candidates' costs, as
:class:`~frontier_marl.training.cost_to_go.Samples`. The behaviour takes the cheapest candidate
(the team oracle's choice) with probability ``oracle_share``, otherwise the base's choice or,
given a ``learner`` (any team decider: a fitted scorer for DAgger), the learner's (the
labelled states are then the learner's own).

With ``completions`` K each cost is instead the mean over K maps drawn from the family's
generator that complete the team's belief
(``maps`` of :func:`~frontier_marl.policies.team_lookahead.team_lookahead_costs`): no true map, less
noise, and the "oracle's" choice is then the cheapest under that prior.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.core.slots import SlotTable
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.policies.base import first_by
from frontier_marl.policies.linear_scorer import explorer_slots
from frontier_marl.policies.lookahead import completion_draws, require_generated_maps
from frontier_marl.policies.map_crops import slot_crops
from frontier_marl.policies.team_decider import SequentialTeamDecider
from frontier_marl.policies.team_lookahead import team_lookahead_costs
from frontier_marl.sim.episodes import EpisodeSource
from frontier_marl.sim.team_rollouts import ClaimingNearestBase, claimed_nearest_slot
from frontier_marl.training.cost_to_go import Samples
from frontier_marl.utils.checks import check_int


class _Labeller(SequentialTeamDecider):
    """The behaviour of :func:`label_team_episode`, recording every ``every``-th decision."""

    name = "team-labeller"

    def __init__(
        self,
        oracle_share: float,
        rng: np.random.Generator,
        every: int,
        learner: SequentialTeamDecider | None = None,
        completions: int = 0,
        source: EpisodeSource | None = None,
        seed: int = 0,
    ) -> None:
        super().__init__()
        self.oracle_share, self.rng, self.every = oracle_share, rng, every
        self.learner = learner
        self.completions, self.source, self.seed = completions, source, seed
        self.decisions = 0
        self.rows: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []  # crops, features, cost

    def attach(self, env: Any) -> None:
        super().attach(env)
        if self.learner is not None:
            self.learner.attach(env)

    def pick(
        self, robot: int, obs: Any, table: SlotTable, candidates: np.ndarray, goals: np.ndarray
    ) -> int:
        env = self._attached()
        world, config = env.world, env.config
        base = ClaimingNearestBase(config.perception_range)
        cap = 4 * config.height * config.width
        maps = None
        if self.completions and self.source is not None:
            maps = completion_draws(
                self.source, world.belief, world.positions, self.completions, self.seed
            )
        costs = team_lookahead_costs(
            world.batch, world.index, robot, table.target[candidates], goals,
            config.reward.explore_threshold, cap, base, maps=maps,
        )  # fmt: skip
        if self.decisions % self.every == 0:
            crops = slot_crops(env, candidates, robot, goals)
            features = explorer_slots(obs)[0][candidates].astype(np.float32)
            self.rows.append((crops, features, costs.astype(np.float64)))
        self.decisions += 1
        if self.rng.random() < self.oracle_share:
            best = first_by(costs, table.path_length[candidates], table.distance[candidates])
            return int(candidates[best])
        if self.learner is not None:
            return self.learner.pick(robot, obs, table, candidates, goals)
        return claimed_nearest_slot(
            np.isin(np.arange(len(table.target)), candidates), table.target, table.distance,
            table.path_length, np.full(2, -1), np.delete(goals, robot, axis=0), base.reach,
        )  # fmt: skip

    def samples(self, family: str) -> Samples:
        if not self.rows:
            return Samples()
        crops = np.concatenate([crops for crops, _, _ in self.rows])
        return Samples(
            crops=np.round(crops * 255).astype(np.uint8),
            features=np.concatenate([features for _, features, _ in self.rows]),
            cost=np.concatenate([cost for _, _, cost in self.rows]),
            decision=np.concatenate(
                [np.full(len(cost), i) for i, (_, _, cost) in enumerate(self.rows)]
            ),
            family=np.full(len(crops), family, dtype="U16"),
        )


def label_team_episode(
    cfg: EnvConfig,
    seed: int,
    family: str = "",
    oracle_share: float = 0.5,
    every: int = 1,
    learner: SequentialTeamDecider | None = None,
    completions: int = 0,
) -> Samples:
    """Play one team episode of ``cfg`` (reset ``seed``; its env settings those of a team's
    map scorer) and label every ``every``-th real decision (the module's docstring; the
    ``learner`` takes the decisions the oracle does not, if given; ``completions`` K >= 1:
    each cost the mean over K completions of the belief)."""
    if not 0.0 <= oracle_share <= 1.0:
        raise ValueError(f"oracle_share must be in [0, 1], got {oracle_share}")
    check_int("every", every, 1)
    if cfg.observation.commit != "none":
        raise ValueError(
            f"team labels need an env with commit 'none', got {cfg.observation.commit!r}"
        )
    env = FrontierParallelEnv(config=cfg)
    check_int("completions", completions, 0)
    source = None
    if completions:
        require_generated_maps(cfg)
        source = EpisodeSource(cfg)
    rng = np.random.default_rng([seed, 1])
    labeller = _Labeller(oracle_share, rng, every, learner, completions, source, seed)
    labeller.attach(env)
    labeller.reset(seed)
    observations, infos = env.reset(seed=seed)
    while env.agents:
        actions = labeller.act_team(observations, infos)
        observations, _, _, _, infos = env.step(actions)
    env.close()
    return labeller.samples(family)
