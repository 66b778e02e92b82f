"""Decision modules: what picks a frontier cluster for each robot.

* :mod:`~frontier_marl.policies.base`: the :class:`Policy` interface and the model adapter;
* :mod:`~frontier_marl.policies.heuristics` (one robot) and :mod:`~frontier_marl.policies.team`
  (coordinated teams): the classic rules;
* :mod:`~frontier_marl.policies.lookahead`: the one-step lookahead oracle on the true map;
* :mod:`~frontier_marl.policies.registry`: every policy by name (:func:`make_policy`);
* :mod:`~frontier_marl.policies.models` and :mod:`~frontier_marl.policies.metadata`: the shipped
  models, loading a saved model and checking it against an env;
* :mod:`~frontier_marl.policies.networks`: the torch networks of the learned policies.
"""

from frontier_marl.policies.base import CallablePolicy, HeuristicPolicy, ModelPolicy, Policy
from frontier_marl.policies.heuristics import (
    CostUtility,
    FirstSlot,
    GreedyDistance,
    GreedyGain,
    NearestPath,
    RandomValid,
)
from frontier_marl.policies.registry import POLICIES, TEAM_POLICIES, make_policy
from frontier_marl.policies.team import CoordinatedAssignment, TeamHeuristic, UtilityDiscount

__all__ = [
    "POLICIES",
    "TEAM_POLICIES",
    "CallablePolicy",
    "CoordinatedAssignment",
    "CostUtility",
    "FirstSlot",
    "GreedyDistance",
    "GreedyGain",
    "HeuristicPolicy",
    "ModelPolicy",
    "NearestPath",
    "Policy",
    "RandomValid",
    "TeamHeuristic",
    "UtilityDiscount",
    "make_policy",
]
