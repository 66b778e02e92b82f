"""What a saved map scorer is worth, decision by decision and episode by episode, on
validation seeds only (docs/experiments/2026-12-04-map-aware-explorer.md).

* **Decisions.** frontier-rule plays ``--label-episodes`` validation episodes of every family;
  each real decision's candidates are labelled with their true-map cost-to-go
  (:mod:`frontier_marl.training.cost_to_go`). Reported per family: how often each chooser
  takes the cheapest candidate, and the mean relative regret of its choice, for the scorer at
  each rule weight, frontier-rule, the nearest path and a random valid slot; and the scorer's
  rank correlation with the true costs (Spearman, per decision, averaged).
* **Episodes.** The scorer at each rule weight beside frontier-rule on ``--episodes``
  validation episodes (``frontier-marl benchmark --split validation``).

::

    python benchmarks/explorer_map_probe.py RUN/best --weights 0,0.5,2 --episodes 16 \\
        --label-episodes 6
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
import torch

from frontier_marl.evaluation.benchmark.families import family, variant_configs
from frontier_marl.evaluation.benchmark.run import Contender, heuristic, run_benchmark
from frontier_marl.evaluation.benchmark.stats import format_table
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_WEIGHTS
from frontier_marl.policies.linear_scorer import feature_names, weight_vector
from frontier_marl.policies.map_explorer import MapExplorer, load_scorer
from frontier_marl.training.cost_regression import scorer_config
from frontier_marl.training.cost_to_go import Samples, first_choice_of, label_episode
from frontier_marl.training.regression import Decisions, group, predict

FAMILIES = ("random-20", "random-30", "rooms-32", "rooms-64")


def validation_labels(names: list[str], episodes: int) -> dict[str, Samples]:
    """frontier-rule's validation episodes, every real decision labelled, per family."""
    out = {}
    for name in names:
        fam = family(name)
        (world,) = variant_configs(fam, None, 1)
        cfg = scorer_config(world)
        rule = weight_vector(FRONTIER_RULE_WEIGHTS, feature_names(cfg), "rule")
        behaviour = first_choice_of(lambda obs, c, rule=rule: -(c.features @ rule))
        seeds = fam.seeds(episodes, "validation")
        out[name] = Samples.join([label_episode(cfg, s, behaviour, family=name) for s in seeds])
    return out


def decision_report(model: Any, data: Decisions, weights: list[float]) -> dict[str, Any]:
    """Per chooser: the share of decisions where it took the cheapest candidate, the mean
    regret of its choice (``data.regret``) and the mean cells it costs beyond the cheapest; the
    scorer's mean per-decision Spearman correlation."""
    rule_vector = torch.as_tensor(list(FRONTIER_RULE_WEIGHTS.values()), dtype=torch.float32)
    rule = data.features @ rule_vector
    margin = rule.masked_fill(~data.mask, -np.inf).max(dim=1, keepdim=True).values - rule
    predicted = predict(model, data)
    rng = np.random.default_rng(0)
    choosers = {f"scorer (rule weight {w:g})": predicted + w * margin for w in weights}
    choosers["frontier-rule"] = -rule
    choosers["nearest path"] = data.features[..., 0]
    choosers["random valid"] = torch.as_tensor(rng.random(data.mask.shape), dtype=torch.float32)
    rows = {}
    for label, scores in choosers.items():
        best = scores.masked_fill(~data.mask, float("inf")).argmin(dim=1)
        regret = data.regret[torch.arange(len(data)), best]
        rows[label] = {
            "cheapest": float((regret == 0).float().mean()),
            "regret": float(regret.mean()),
            "cells": float(data.extra[torch.arange(len(data)), best].mean()),
        }
    return {"decisions": len(data), "choosers": rows, "spearman": _spearman(predicted, data)}


def _spearman(predicted: torch.Tensor, data: Decisions) -> float:
    values = []
    for d in range(len(data)):
        keep = data.mask[d]
        if int(keep.sum()) < 3:
            continue
        a = np.argsort(np.argsort(predicted[d][keep].numpy()))
        b = np.argsort(np.argsort(data.regret[d][keep].numpy()))
        if a.std() > 0 and b.std() > 0:
            values.append(float(np.corrcoef(a, b)[0, 1]))
    return float(np.mean(values)) if values else float("nan")


def _decisions(
    model: Any, names: list[str], label_episodes: int, weights: list[float]
) -> dict[str, Any]:
    """Each family's decision report on labelled validation episodes, printed."""
    labels = validation_labels(names, label_episodes)
    decisions = {
        name: decision_report(model, group(samples, 12), weights)
        for name, samples in labels.items()
    }
    for name, part in decisions.items():
        print(f"{name}: {part['decisions']} decisions, spearman {part['spearman']:.3f}")
        for label, row in part["choosers"].items():
            print(
                f"  {label:<26} cheapest {row['cheapest']:.1%}  regret {row['regret']:.4f}  "
                f"cells {row['cells']:.2f}"
            )
    return decisions


def _benchmark_rows(
    model: Any, names: list[str], weights: list[float], episodes: int, progress: bool
) -> list[dict[str, Any]]:
    """The scorer at each rule weight beside frontier-rule on validation episodes."""
    contenders = [heuristic("frontier-rule")] + [
        Contender(
            f"scorer-w{w:g}",
            False,
            lambda w=w: MapExplorer(model, f"scorer-w{w:g}", w),
            scorer_config,
        )
        for w in weights
    ]
    return run_benchmark(
        [family(name) for name in names],
        contenders,
        episodes,
        progress=progress,
        split="validation",
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", type=Path, help="a saved map scorer's folder")
    parser.add_argument("--weights", default="0", help="rule weights, comma-separated")
    parser.add_argument("--families", default=",".join(FAMILIES))
    parser.add_argument("--episodes", type=int, default=16, help="validation episodes")
    parser.add_argument("--label-episodes", type=int, default=6, help="labelled episodes")
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    try:
        weights = [float(w) for w in args.weights.split(",")]
        model, _ = load_scorer(args.model)
    except ValueError as exc:
        parser.error(str(exc))
    names = args.families.split(",")
    report: dict[str, Any] = {"options": {k: str(v) for k, v in vars(args).items()}}
    if args.label_episodes:
        report["decisions"] = _decisions(model, names, args.label_episodes, weights)
    if args.episodes:
        rows = _benchmark_rows(model, names, weights, args.episodes, not args.no_progress)
        report["rows"] = rows
        print(format_table(rows))
    if args.json is not None:
        args.json.write_text(json.dumps(report, default=str))
    return 0
