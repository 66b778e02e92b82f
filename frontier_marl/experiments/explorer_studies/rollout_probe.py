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

import argparse
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from frontier_marl.evaluation.benchmark.families import FAMILIES, check_families, family
from frontier_marl.evaluation.benchmark.run import Contender, contenders, heuristic, run_benchmark
from frontier_marl.evaluation.benchmark.stats import format_table
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
    weights = dict(FRONTIER_RULE_WEIGHTS)
    return Contender(
        ExplorerRollout.name,
        False,
        lambda: ExplorerRollout(weights),
        heuristic("frontier-rule").config,
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", default="random-20,random-30,rooms-32")
    parser.add_argument("--episodes", type=int, default=16, help="validation episodes")
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    names = args.families.split(",")
    try:
        check_families(names, "--families")
    except ValueError as exc:
        parser.error(f"{exc} (valid: {', '.join(FAMILIES)})")
    policies = [
        *contenders(["nearest-path", "frontier-rule", "lookahead-oracle"]),
        explorer_rollout(),
    ]
    rows = run_benchmark(
        [family(name) for name in names],
        policies,
        args.episodes,
        progress=not args.no_progress,
        split="validation",
    )
    print(format_table(rows))
    if args.json is not None:
        args.json.write_text(json.dumps({"options": vars(args) | {"json": None}, "rows": rows}))
    return 0
