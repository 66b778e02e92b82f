"""How far below frontier-rule one step of lookahead on the true map goes: a privileged bound.

``lookahead-oracle`` simulates each candidate cluster on the true map and lets nearest-path
finish (rollout on nearest-path). ``explorer-rollout`` is the same with frontier-rule
(the linear ``explorer`` until the map-aware model replaced it) finishing each simulation (its
observation and weights), so it is one step of policy improvement over the rule itself, and
its costs are the labels a student of the rule would need. Both read the true map: bounds,
not contenders. Validation episodes::

    python benchmarks/explorer_rollout_probe.py --families random-20,random-30,rooms-32 \\
        --episodes 16 --json training/results/explorer/rollout-probe.json
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import partial
from typing import Any

from frontier_marl.evaluation.benchmark.run import Contender, contenders, heuristic
from frontier_marl.experiments.explorer_studies.validation_study import run_study, study_parser
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_WEIGHTS
from frontier_marl.policies.linear_scorer import feature_names, weight_vector
from frontier_marl.policies.lookahead import LinearScorerBase, LookaheadOracle


class ExplorerRollout(LookaheadOracle):
    """The lookahead oracle whose rollouts the linear scorer ``weights`` (by feature name)
    finishes, on the observation of the env it is attached to (the model's own, on the
    family's world)."""

    name = "explorer-rollout"

    def __init__(self, weights: Mapping[str, float]) -> None:
        super().__init__()
        self.weights = weights

    def attach(self, env: Any) -> None:
        super().attach(env)
        vector = weight_vector(self.weights, feature_names(env.config), "the scorer's weights")
        self.base = LinearScorerBase(env.config, vector)


def explorer_rollout() -> Contender:
    """``explorer-rollout`` with frontier-rule's weights, in frontier-rule's env."""
    maker = partial(ExplorerRollout, dict(FRONTIER_RULE_WEIGHTS))
    return Contender(ExplorerRollout.name, False, maker, heuristic("frontier-rule").config)


def main(argv: list[str] | None = None) -> int:
    parser = study_parser(__doc__, "random-20,random-30,rooms-32")
    policies = [
        *contenders(["nearest-path", "frontier-rule", "lookahead-oracle"]),
        explorer_rollout(),
    ]
    return run_study(parser, parser.parse_args(argv), policies)
