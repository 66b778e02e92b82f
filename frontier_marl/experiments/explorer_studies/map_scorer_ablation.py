"""What each part of the map-aware explorer is worth: an ablation on a run's labels and on
validation seeds (docs/experiments/2026-12-04-map-aware-explorer.md).

A cost-regression run (``frontier-marl train explorer``) keeps each round's labels in
``RUN/labels/``. This fits one scorer per variant on every round but the last (or the first
``--train-rounds``: a learning curve; a one-round run, or ``--train-rounds`` set to all of
them, fits every round and has no held-out decisions), with the run's fit settings
(``[regression]``):

* ``full``: the shipped fit, squared error on each candidate's relative regret, reading the
  map crops and the slot features;
* ``no-map``: the same with every crop blank (the slot features and the pooled context only);
* ``ranking``: a listwise ranking loss in place of the regression
  (:data:`~frontier_marl.training.regression.LOSSES`);
* ``argmax``: imitation of each decision's cheapest candidate (the argmax labels that DAgger
  imitated before the cost targets);
* ``cells``: the regression on each candidate's cells beyond its decision's cheapest, over the
  map's side (:func:`~frontier_marl.training.cost_to_go.cells_regret`), in place of the
  relative regret: every decision weighs by its share of an episode, where the relative regret
  weighs the last decisions, whose costs are small, the most.

Each is reported (a) on the last round's decisions (other training episodes, held out of the
fit) per family, as :func:`~frontier_marl.experiments.explorer_studies.map_scorer_probe.
decision_report` gives it: how often it takes the cheapest candidate, the mean relative regret
and the mean cells beyond the cheapest of its choice beside frontier-rule's and the nearest
path's, its rank correlation with the true costs;
and (b) by its T99 against frontier-rule on ``--episodes`` validation episodes of every family,
at each rule weight of ``--weights`` (:class:`~frontier_marl.policies.map_explorer.MapExplorer`;
the cross-entropy variants score in other units, so their weights are not comparable)::

    python benchmarks/explorer_map_ablation.py runs/explorer-map --episodes 16 --weights 0,0.5 \\
        --json ablation.json
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from frontier_marl.evaluation.benchmark.families import family, variant_configs
from frontier_marl.experiments.explorer_studies.map_scorer_probe import decision_report
from frontier_marl.training.cost_regression import Validation, fitted
from frontier_marl.training.cost_to_go import Samples
from frontier_marl.training.experiment import Experiment, experiment_from_dict
from frontier_marl.training.regression import group
from frontier_marl.training.settings import RegressionSettings

#: Each variant: its fit's loss, whether it reads the map crops, whether its target is in
#: cells (over the map's side) rather than relative.
VARIANTS: dict[str, tuple[str, bool, bool]] = {
    "full": ("regret", True, False),
    "no-map": ("regret", False, False),
    "ranking": ("ranking", True, False),
    "argmax": ("argmax", True, False),
    "cells": ("regret", True, True),
}


class BlankMap(nn.Module):
    """A scorer that sees every crop blank (all zeros), as it was fitted."""

    def __init__(self, model: nn.Module) -> None:
        super().__init__()
        self.model = model
        self.feature_mean = model.feature_mean

    def forward(
        self, crops: torch.Tensor, features: torch.Tensor, mask: torch.Tensor
    ) -> torch.Tensor:
        return self.model(torch.zeros_like(crops), features, mask)


def map_sides(families: np.ndarray) -> np.ndarray:
    """Per sample, the square root of its family's map area (cells)."""
    side = {}
    for name in set(families.tolist()):
        (world,) = variant_configs(family(name), None, 1)
        side[name] = float(np.sqrt(world.height * world.width))
    return np.array([side[name] for name in families.tolist()])


def run_labels(run: Path, minimum: int = 2) -> list[Samples]:
    """Every round's labels of a cost-regression run, in round order (ValueError when there
    are fewer than ``minimum`` rounds)."""
    paths = sorted((run / "labels").glob("round*.npz"), key=lambda p: int(p.stem[5:]))
    if len(paths) < minimum:
        raise ValueError(f"{run}/labels holds {len(paths)} rounds; this needs {minimum} or more")
    return [Samples.load(path) for path in paths]


def run_experiment(run: Path) -> Experiment:
    """The experiment a cost-regression run was trained with (from its ``model.json``)."""
    metadata = json.loads((run / "model.json").read_text())
    return experiment_from_dict(metadata["experiment"], str(run / "model.json"))


def fit_variant(name: str, train: Samples, reg: RegressionSettings, seed: int) -> nn.Module:
    """The ``name`` variant's scorer fitted to ``train``."""
    loss, reads_map, in_cells = VARIANTS[name]
    if not reads_map:
        train = Samples(
            np.zeros_like(train.crops), train.features, train.cost, train.decision, train.family
        )
    model = fitted(train, reg, seed, loss, map_sides(train.family) if in_cells else None)
    return model if reads_map else BlankMap(model).eval()


def held_out_report(model: nn.Module, test: Samples, weights: list[float]) -> dict[str, Any]:
    """Per family of ``test``: the decision report of ``model``."""
    report = {}
    for name in sorted(set(test.family.tolist())):
        keep = test.family == name
        part = Samples(
            test.crops[keep], test.features[keep], test.cost[keep], test.decision[keep], name
        )
        report[name] = decision_report(model, group(part, 12), weights)
    return report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a cost-regression run folder")
    parser.add_argument("--variants", default=",".join(VARIANTS))
    parser.add_argument("--weights", default="0,0.5", help="rule weights, comma-separated")
    parser.add_argument("--episodes", type=int, default=16, help="validation episodes")
    parser.add_argument("--epochs", type=int, default=None, help="default: the run's")
    parser.add_argument(
        "--train-rounds",
        type=int,
        default=None,
        help="fit on the first N rounds (default: all but the last, or the only one); N = "
        "all rounds: no held-out decisions, the validation episodes only",
    )
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    variants = args.variants.split(",")
    unknown = sorted(set(variants) - set(VARIANTS))
    if unknown:
        parser.error(f"unknown variants {unknown}; choose from {', '.join(VARIANTS)}")
    try:
        weights = [float(w) for w in args.weights.split(",")]
        rounds = run_labels(args.run, minimum=1)
        experiment = run_experiment(args.run)
    except (ValueError, OSError, KeyError) as exc:
        parser.error(str(exc))
    reg = RegressionSettings(**experiment.regression)
    if args.epochs is not None:
        reg = RegressionSettings(**{**experiment.regression, "fit_epochs": args.epochs})
    fitted_rounds = max(len(rounds) - 1, 1) if args.train_rounds is None else args.train_rounds
    if not 1 <= fitted_rounds <= len(rounds):
        parser.error(f"--train-rounds must be in [1, {len(rounds)}], got {fitted_rounds}")
    train = Samples.join(rounds[:fitted_rounds])
    test = rounds[-1] if fitted_rounds < len(rounds) else None  # None: no held-out decisions
    validation = Validation(list(experiment.train.families), args.episodes)
    report: dict[str, Any] = {
        "run": str(args.run),
        "train_rounds": fitted_rounds,
        "train_labels": len(train),
        "episodes": args.episodes,
        "variants": {},
    }
    for name in variants:
        model = fit_variant(name, train, reg, experiment.train.seed)
        decisions = {} if test is None else held_out_report(model, test, weights)
        episodes = {str(w): validation(model, w) for w in weights}
        report["variants"][name] = {"held_out_decisions": decisions, "validation": episodes}
        _print_variant(name, decisions, episodes)
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0


def _print_variant(name: str, decisions: dict[str, Any], episodes: dict[str, Any]) -> None:
    print(f"{name}:")
    for family_name, part in decisions.items():
        choosers = part["choosers"]
        regrets = ", ".join(
            f"{label} {row['regret']:.4f} ({row['cells']:.2f} cells)"
            for label, row in choosers.items()
        )
        print(f"  {family_name} held-out regret: {regrets}; spearman {part['spearman']:.3f}")
    for weight, result in episodes.items():
        families = ", ".join(f"{k} {v:+.1%}" for k, v in result["by_family"].items())
        print(
            f"  rule weight {weight}: T99 vs frontier-rule {result['vs_frontier_rule']:+.1%} "
            f"({families})"
        )
