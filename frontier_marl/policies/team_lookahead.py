"""A privileged reference for teams: one-step lookahead on the true map for each robot.

:func:`team_lookahead_costs` copies a team's world into one simulation per candidate target of
one robot, sets every robot's first target (the candidate for that robot, given targets for the
others; row -1: the base decides), lets :class:`~frontier_marl.sim.team_rollouts.
ClaimingNearestBase` finish the map and returns each simulation's makespan to go until the
coverage level (:func:`~frontier_marl.sim.team_rollouts.team_rollout_costs`).
:class:`TeamLookaheadOracle` (``team-lookahead-oracle``) is that choice for every robot that
must decide, one robot after another (:mod:`~frontier_marl.policies.team_decider`): a robot
keeps its target until it reaches it or the target is no longer offered, and a robot deciding
after another sees that one's new target.
It reads the true map, so it measures what choosing among the same clusters can gain for a
team (the headroom of a team policy), not a heuristic. With one robot it is the single-robot
:class:`~frontier_marl.policies.lookahead.LookaheadOracle` with the base decided in rounds.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from frontier_marl.core.slots import SlotTable
from frontier_marl.core.worlds import Worlds
from frontier_marl.policies.base import first_by
from frontier_marl.policies.lookahead import completed_clones
from frontier_marl.policies.team_decider import SequentialTeamDecider
from frontier_marl.sim.branching import branch
from frontier_marl.sim.team_rollouts import (
    ClaimingNearestBase,
    TeamRolloutBase,
    team_rollout_costs,
)


def team_lookahead_costs(
    source: Worlds,
    index: int,
    robot: int,
    targets: np.ndarray,
    goals: np.ndarray,
    coverage: float,
    max_steps: int,
    base: TeamRolloutBase,
    prune: bool = False,
    maps: list[np.ndarray] | None = None,
) -> np.ndarray:
    """Makespan to go of world ``index`` of ``source`` until ``coverage`` is known, per
    candidate target ``targets[m]`` (M, 2) of ``robot``, the other robots first heading for
    ``goals`` (K, 2; row -1: ``base`` decides at once) and ``base`` finishing. A simulation
    that takes ``max_steps`` steps or stalls costs ``max_steps``; ``prune``: only the cheapest
    candidates' costs are exact (:func:`team_rollout_costs`).

    With ``maps``, each cost is instead its mean over those maps in place of the true map
    (each the drawn map where the robots do not know the cells, the belief where they do;
    :func:`~frontier_marl.policies.lookahead.completed_clones`): it reads no true map."""
    targets = np.asarray(targets, dtype=np.int64).reshape(-1, 2)
    goals = np.asarray(goals, dtype=np.int64).reshape(source.n_agents, 2)
    if maps is None:
        sims = branch(source, index, len(targets), base.gain)
    elif prune:
        raise ValueError("pruned costs cannot be averaged over maps: prune=False with maps")
    else:
        sims = completed_clones(source, index, len(targets), maps, base.gain)
    copies = 1 if maps is None else len(maps)
    sims.goals[:] = goals
    sims.goals[:, robot] = np.tile(targets, (copies, 1))
    costs = team_rollout_costs(sims, coverage, max_steps, base, prune)
    return costs if maps is None else costs.reshape(copies, len(targets)).mean(axis=0)


class TeamLookaheadOracle(SequentialTeamDecider):
    """For each robot that must decide (:class:`~frontier_marl.policies.team_decider.
    SequentialTeamDecider`), its cheapest candidate by :func:`team_lookahead_costs` (ties:
    nearest path, then nearest centroid). It reads the attached env's world, true map
    included, its coverage level and its sensor range (the base's claim reach)."""

    name = "team-lookahead-oracle"

    def pick(
        self, robot: int, obs: Any, table: SlotTable, candidates: np.ndarray, goals: np.ndarray
    ) -> int:
        env = self._attached()
        world, config = env.world, env.config
        height, width = world.shape
        order = candidates[np.argsort(table.path_length[candidates], kind="stable")]
        costs = team_lookahead_costs(
            world.batch, world.index, robot, table.target[order], goals,
            config.reward.explore_threshold, 4 * height * width,
            ClaimingNearestBase(config.perception_range), prune=True,
        )  # fmt: skip
        return int(order[first_by(costs, table.path_length[order], table.distance[order])])
