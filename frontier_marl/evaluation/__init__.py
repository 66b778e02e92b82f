"""The evaluation layer: the thesis's protocol, exploration metrics, the heuristics, plots.

* :mod:`~frontier_marl.evaluation.protocol`: :func:`evaluate`; its records in
  :mod:`~frontier_marl.evaluation.records`;
* :mod:`~frontier_marl.evaluation.metrics`: coverage curves, cells to a coverage level, overlap;
* :mod:`~frontier_marl.evaluation.policies`: the :class:`Policy` interface and model adapters;
  :mod:`~frontier_marl.evaluation.heuristics` and :mod:`~frontier_marl.evaluation.team`: the
  heuristics, by name in :mod:`~frontier_marl.evaluation.registry`;
* :mod:`~frontier_marl.evaluation.plots`: result figures;
* :mod:`~frontier_marl.evaluation.families`, :mod:`~frontier_marl.evaluation.benchmark` and
  :mod:`~frontier_marl.evaluation.benchmark_stats`: the exploration benchmark (map families,
  T99/T90, the paired difference to the best heuristic; docs/benchmark.md).
"""

from frontier_marl.evaluation.heuristics import (
    CostUtility,
    FirstSlot,
    GreedyDistance,
    GreedyGain,
    NearestPath,
    RandomValid,
)
from frontier_marl.evaluation.policies import CallablePolicy, HeuristicPolicy, ModelPolicy, Policy
from frontier_marl.evaluation.protocol import evaluate, run_episode
from frontier_marl.evaluation.records import (
    DEFAULT_LEVELS,
    EpisodeRecord,
    EvaluationResult,
    level_key,
)
from frontier_marl.evaluation.registry import POLICIES, TEAM_POLICIES, make_policy
from frontier_marl.evaluation.team import CoordinatedAssignment, TeamHeuristic, UtilityDiscount

__all__ = [
    "DEFAULT_LEVELS",
    "POLICIES",
    "TEAM_POLICIES",
    "CallablePolicy",
    "CoordinatedAssignment",
    "CostUtility",
    "EpisodeRecord",
    "EvaluationResult",
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
    "evaluate",
    "level_key",
    "make_policy",
    "run_episode",
]
