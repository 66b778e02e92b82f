"""How much a chooser among frontier-rule's own 12 slots could gain: two true-map oracles in
frontier-rule's env (docs/experiments/2026-12-04-map-aware-explorer.md).

* ``oracle-np-12``: each valid slot simulated on the true map, nearest-path finishing
  (:class:`~frontier_marl.policies.lookahead.LookaheadOracle`), the cheapest taken;
* ``oracle-rule-12``: the same with frontier-rule finishing each simulation.

Both read the true map (bounds, not contenders) and choose among exactly the slots that
``frontier-rule`` and the map-aware explorer choose among. Validation episodes::

    python benchmarks/explorer_headroom.py --families random-20,rooms-32 --episodes 16
"""

from __future__ import annotations

from functools import partial

from frontier_marl.evaluation.benchmark.run import Contender, heuristic
from frontier_marl.experiments.explorer_studies.rollout_probe import ExplorerRollout
from frontier_marl.experiments.explorer_studies.validation_study import run_study, study_parser
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_WEIGHTS
from frontier_marl.policies.lookahead import LookaheadOracle


def oracles() -> list[Contender]:
    """frontier-rule and the two oracles in its env."""
    rule = heuristic("frontier-rule")
    return [
        rule,
        Contender("oracle-np-12", False, LookaheadOracle, rule.config),
        Contender(
            "oracle-rule-12",
            False,
            partial(ExplorerRollout, dict(FRONTIER_RULE_WEIGHTS)),
            rule.config,
        ),
    ]


def main(argv: list[str] | None = None) -> int:
    parser = study_parser(__doc__, "random-20,rooms-32")
    return run_study(parser, parser.parse_args(argv), oracles())
