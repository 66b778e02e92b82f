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

import argparse
import json
from pathlib import Path

from frontier_marl.evaluation.benchmark.families import FAMILIES, check_families, family
from frontier_marl.evaluation.benchmark.run import Contender, heuristic, run_benchmark
from frontier_marl.evaluation.benchmark.stats import format_table
from frontier_marl.experiments.explorer_studies.rollout_probe import ExplorerRollout
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_WEIGHTS
from frontier_marl.policies.lookahead import LookaheadOracle


def oracles() -> list[Contender]:
    """frontier-rule and the two oracles in its env."""
    rule = heuristic("frontier-rule")
    return [
        rule,
        Contender("oracle-np-12", False, LookaheadOracle, rule.config),
        Contender(
            "oracle-rule-12", False, lambda: ExplorerRollout(FRONTIER_RULE_WEIGHTS), rule.config
        ),
    ]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", default="random-20,rooms-32")
    parser.add_argument("--episodes", type=int, default=16, help="validation episodes")
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    names = args.families.split(",")
    try:
        check_families(names, "--families")
    except ValueError as exc:
        parser.error(f"{exc} (valid: {', '.join(FAMILIES)})")
    rows = run_benchmark(
        [family(name) for name in names],
        oracles(),
        args.episodes,
        progress=not args.no_progress,
        split="validation",
    )
    print(format_table(rows))
    if args.json is not None:
        args.json.write_text(json.dumps({"options": vars(args) | {"json": None}, "rows": rows}))
    return 0
