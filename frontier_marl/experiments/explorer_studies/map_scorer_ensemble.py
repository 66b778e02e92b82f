"""How much of the map scorer's error is model variance: scorers fitted alike but for their
seeds, and their average (docs/experiments/2026-12-04-map-aware-explorer.md). Validation seeds
only.

It fits ``max(--sizes)`` scorers on every round's labels of a cost-regression run (``frontier-
marl train explorer``), with the run's fit settings and the seeds ``seed``, ``seed + 1``,
..., and scores, for each k of ``--sizes``, the mean predicted regret of the first k
(:class:`Averaged`) against frontier-rule on ``--episodes`` validation episodes of every family
at each rule weight of ``--weights`` (k = 1 is one plain fit)::

    python benchmarks/explorer_map_ensemble.py runs/explorer-map-r0 --sizes 1,4,8 \\
        --weights 0,0.5,1 --episodes 16 --json ensemble.json

``--set KEY=VALUE`` changes a fit setting of the run's ``[regression]`` section (e.g.
``--set scorer_width=64`` for a wider scorer, ``--set scorer_members=4`` for four scorers
fitted as one batched network, each fit then itself an average). ``--with RUN``
(repeatable) adds another cost-regression run's labels to the fit and its families to the
validation. ``--save
FOLDER`` keeps the first fit (seed ``seed``) as a map explorer the benchmark plays, with the
first of ``--weights`` as its rule weight.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import torch
from torch import nn

from frontier_marl.experiments.explorer_studies.map_scorer_ablation import (
    run_experiment,
    run_labels,
)
from frontier_marl.policies.map_explorer import save_map_explorer
from frontier_marl.training.cost_regression import Validation, fitted
from frontier_marl.training.cost_to_go import Samples
from frontier_marl.training.experiment import parse_override
from frontier_marl.training.settings import RegressionSettings
from frontier_marl.utils.progress import progress_bar


class Averaged(nn.Module):
    """Scorers of one shape as one: the mean of their predicted regrets."""

    def __init__(self, members: list[nn.Module]) -> None:
        super().__init__()
        self.members = nn.ModuleList(members)
        self.feature_mean = members[0].feature_mean  # what MapExplorer checks its env against

    def forward(
        self, crops: torch.Tensor, features: torch.Tensor, mask: torch.Tensor
    ) -> torch.Tensor:
        return torch.stack([member(crops, features, mask) for member in self.members]).mean(0)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a cost-regression run folder")
    parser.add_argument("--sizes", default="1,4,8", help="ensemble sizes, comma-separated")
    parser.add_argument("--weights", default="0,0.5,1", help="rule weights, comma-separated")
    parser.add_argument("--episodes", type=int, default=16, help="validation episodes")
    parser.add_argument("--epochs", type=int, default=None, help="default: the run's")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a fit setting of [regression] instead of the run's (e.g. scorer_width=64)",
    )
    parser.add_argument(
        "--with",
        dest="others",
        type=Path,
        action="append",
        default=[],
        metavar="RUN",
        help="another cost-regression run whose labels and families join the fit",
    )
    parser.add_argument(
        "--save", type=Path, default=None, metavar="FOLDER", help="keep the first fit here"
    )
    parser.add_argument("--no-progress", action="store_true")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    try:
        sizes = [int(k) for k in args.sizes.split(",")]
        weights = [float(w) for w in args.weights.split(",")]
        runs = [args.run, *args.others]
        train = Samples.join([part for run in runs for part in run_labels(run, minimum=1)])
        experiment = run_experiment(args.run)
        families = list(
            dict.fromkeys(name for run in runs for name in run_experiment(run).train.families)
        )
    except (ValueError, OSError, KeyError) as exc:
        parser.error(str(exc))
    if min(sizes) < 1:
        parser.error(f"--sizes must be integers >= 1, got {args.sizes}")
    settings = dict(experiment.regression)
    if args.epochs is not None:
        settings["fit_epochs"] = args.epochs
    try:
        for text in args.overrides:
            section, key, value = parse_override(text)
            if section != "regression":
                raise ValueError(f"--set takes [regression] settings only, got {text!r}")
            settings[key] = value
        reg = RegressionSettings(**settings)
    except (ValueError, TypeError) as exc:
        parser.error(str(exc))
    seed = experiment.train.seed
    members = []
    with progress_bar(max(sizes), disable=args.no_progress, desc="fits", unit="fit") as bar:
        for offset in range(max(sizes)):
            members.append(fitted(train, reg, seed + offset))
            bar.update(1)
    if args.save is not None:
        meta = {"trained_by": "explorer_map_ensemble", "labels": len(train)}
        regression = {**settings, "runs": [str(run) for run in runs]}
        save_map_explorer(
            members[0], args.save, {**meta, "regression": regression, "rule_weight": weights[0]}
        )
    validation = Validation(families, args.episodes)
    report: dict[str, Any] = {"run": str(args.run), "labels": len(train), "sizes": {}}
    for k in sizes:
        model = Averaged(members[:k]).eval()
        results = {str(w): validation(model, w) for w in weights}
        report["sizes"][str(k)] = results
        validation.print_results(f"{k} scorer(s)", results)
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0
