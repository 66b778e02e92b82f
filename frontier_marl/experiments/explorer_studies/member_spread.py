"""A scorer of several members with their disagreement as a penalty: each candidate scored by
the members' mean predicted regret plus ``c`` times their standard deviation (an uncertain
candidate must promise more to be chosen), then frontier-rule's margin as usual
(docs/experiments/2026-12-04-map-aware-explorer.md, the section "Four scorers as one
network"). Validation seeds only::

    python benchmarks/explorer_member_spread.py runs/m4w16 --spreads 0,1,2 --weights 1,0.5,0

``FOLDER`` is a saved map explorer of two or more members (for example ``--save`` of
``benchmarks/explorer_map_ensemble.py ... --set scorer_members=4``).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import torch
from torch import nn

from frontier_marl.policies.map_explorer import load_scorer
from frontier_marl.policies.networks.map_scorer import MapScorer
from frontier_marl.training.cost_regression import Validation

FAMILIES = "random-20,random-30,rooms-32,rooms-64,rooms-96-fine,floorplan-96"


class SpreadPenalised(nn.Module):
    """``model``'s members' mean regret plus ``spread`` times their standard deviation."""

    def __init__(self, model: MapScorer, spread: float) -> None:
        super().__init__()
        if model.members < 2:
            raise ValueError(f"a spread needs two or more members, the scorer has {model.members}")
        self.model, self.spread = model, spread
        self.feature_mean = model.feature_mean  # what MapExplorer checks its env against

    def forward(
        self, crops: torch.Tensor, features: torch.Tensor, mask: torch.Tensor
    ) -> torch.Tensor:
        each = self.model.member_regrets(crops, features, mask).masked_fill(
            ~mask.unsqueeze(-1), 0.0
        )
        score = each.mean(-1) + self.spread * each.std(-1)
        return score.masked_fill(~mask, float("inf"))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scorer", help="a saved map explorer of two or more members")
    parser.add_argument("--spreads", default="0,1,2", help="values of c, comma-separated")
    parser.add_argument("--weights", default="1,0.5", help="rule weights, comma-separated")
    parser.add_argument("--families", default=FAMILIES, help="comma-separated")
    parser.add_argument("--episodes", type=int, default=16, help="validation episodes")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    try:
        spreads = [float(c) for c in args.spreads.split(",")]
        weights = [float(w) for w in args.weights.split(",")]
        if min(spreads) < 0 or min(weights) < 0:
            raise ValueError("--spreads and --weights must be numbers >= 0")
        model, _ = load_scorer(args.scorer)
        SpreadPenalised(model, 0.0)
        validation = Validation(args.families.split(","), args.episodes)
    except ValueError as exc:
        parser.error(str(exc))
    report: dict[str, Any] = {"scorer": args.scorer, "members": model.members, "spreads": {}}
    for spread in spreads:
        scorer = SpreadPenalised(model, spread).eval()
        results = {str(w): validation(scorer, w) for w in weights}
        report["spreads"][str(spread)] = results
        validation.print_results(f"spread {spread}", results)
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0
