"""Labels that mix the true map's cost-to-go with the completions' mean, refitted and scored
(docs/experiments/2026-12-04-map-aware-explorer.md, "Rooms"). Validation seeds only.

One true-map rollout is a draw from the exact posterior of the unknown, but a noisy one; the
mean over completions drawn from the family's generator is smooth, but under a generic prior.
For each ``ALPHA`` of ``--alphas`` this fits a scorer (the completions run's fit settings and
seed) to ``ALPHA * true cost + (1 - ALPHA) * completions' mean`` of every candidate, and scores
it against frontier-rule on ``--episodes`` validation episodes of the run's families::

    python benchmarks/explorer_map_mix.py runs/rooms-c16-x4 runs/rooms-true-x8 \\
        --alphas 0.5,0.25 --weights 0,0.5 --episodes 16

Both runs' round 0 follows frontier-rule from the same seeds, so they label the same
decisions; the true-map run may have more episodes (its first candidates are matched, and
checked equal crop for crop).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from frontier_marl.experiments.explorer_studies.map_scorer_ablation import (
    run_experiment,
    run_labels,
)
from frontier_marl.training.cost_regression import Validation, fitted
from frontier_marl.training.cost_to_go import Samples
from frontier_marl.training.settings import RegressionSettings


def mixed_labels(completions: Samples, true: Samples, alpha: float) -> Samples:
    """``completions`` with each cost replaced by ``alpha * true + (1 - alpha) * completions``
    (``true``: the same decisions first, labelled on the true map); ValueError if the
    decisions differ or ``alpha`` is outside [0, 1]."""
    if not 0.0 <= alpha <= 1.0:
        raise ValueError(f"an alpha must be in [0, 1], got {alpha}")
    n = len(completions)
    same = len(true) >= n and all(
        np.array_equal(getattr(true, key)[:n], getattr(completions, key))
        for key in ("crops", "features", "decision", "family")
    )
    if not same:
        raise ValueError(
            "the two runs' round 0 labels are not the same decisions (same families, seed and "
            "behaviour, the true-map run at least as many episodes)"
        )
    return replace(completions, cost=alpha * true.cost[:n] + (1.0 - alpha) * completions.cost)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("completions", type=Path, help="a cost-regression run with completions")
    parser.add_argument("true", type=Path, help="the same run with true-map labels")
    parser.add_argument("--alphas", default="0.5", help="true-map shares, comma-separated")
    parser.add_argument("--weights", default="0,0.5", help="rule weights, comma-separated")
    parser.add_argument("--episodes", type=int, default=16, help="validation episodes")
    parser.add_argument("--epochs", type=int, default=None, help="default: the run's")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    try:
        alphas = [float(a) for a in args.alphas.split(",")]
        weights = [float(w) for w in args.weights.split(",")]
        soft, true = (run_labels(run, minimum=1)[0] for run in (args.completions, args.true))
        experiment = run_experiment(args.completions)
        mixes = [mixed_labels(soft, true, alpha) for alpha in alphas]
    except (ValueError, OSError, KeyError) as exc:
        parser.error(str(exc))
    settings = dict(experiment.regression)
    if args.epochs is not None:
        settings["fit_epochs"] = args.epochs
    reg = RegressionSettings(**settings)
    validation = Validation(list(experiment.train.families), args.episodes)
    report: dict[str, Any] = {"labels": len(soft), "alphas": {}}
    for alpha, samples in zip(alphas, mixes, strict=True):
        model = fitted(samples, reg, experiment.train.seed)
        results = {str(w): validation(model, w) for w in weights}
        report["alphas"][str(alpha)] = results
        for weight, result in results.items():
            families = ", ".join(f"{n} {v:+.1%}" for n, v in result["by_family"].items())
            print(f"alpha {alpha}, rule weight {weight}: T99 vs frontier-rule {families}")
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0
