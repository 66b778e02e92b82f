"""How the tour rule gains from the ``unknown_near`` feature, by square size and weight.

The rule "path -1, tour -0.5" plus ``W * unknown_near`` computed over a square of half-side
``R`` cells (the env's feature uses R = :data:`~frontier_marl.sim.features.NEAR`), for every
R of ``--radii`` and W of ``--weights``, against the path-only scorer (nearest-path among the
slots) on the same training episodes of every family, played as CEM plays them (the
``explorer`` config's episodes; seeds from ``--first``, training seeds only)::

    python benchmarks/explorer_near_probe.py --radii 4,8,12,16,20 --weights=-0.2,-0.4,-0.7 \\
        --episodes 64 --first 720000 --json training/results/explorer/near-probe.json

A negative W sends the robot first to frontiers hemmed in by walls or the map's edge, and
leaves those that open onto a large unexplored region for later.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.envs.vector import FrontierVectorEnv
from frontier_marl.evaluation.benchmark.families import TRAIN_SEEDS
from frontier_marl.policies.linear_scorer import feature_names, weight_vector
from frontier_marl.sim.features import unknown_near
from frontier_marl.training.cem import play_scorer, relative_t99
from frontier_marl.training.experiment import load_experiment

RULE = {"path": -1.0, "tour": -0.5}


Scorer = Callable[[dict[str, np.ndarray], FrontierVectorEnv], np.ndarray]


def scorer(names: list[str], radius: int, weight: float, rule: dict = RULE) -> Scorer:
    """``rule``'s linear scores plus ``weight`` times the unknown share of the square of
    half-side ``radius`` around each slot's target."""
    linear = weight_vector(rule, names, "the probe's rule")

    def score(observations: dict[str, np.ndarray], env: FrontierVectorEnv) -> np.ndarray:
        scores = observations["slots"].astype(np.float64) @ linear
        if weight:
            slots = env.mdp.slots.rows(slice(None))
            near = unknown_near(slots, env.mdp.worlds.belief, radius)[..., 0]
            scores = scores + weight * near
        return scores

    return score


def parse_list(text: str, kind: type, what: str, parser: argparse.ArgumentParser) -> list:
    try:
        return [kind(value) for value in text.split(",")]
    except ValueError:
        parser.error(f"{what} must be comma-separated numbers, got {text!r}")


def _family_row(
    family: str, cfg: EnvConfig, seeds: list[int], variants: dict[str, tuple[int, float]]
) -> dict[str, Any]:
    """Each variant's mean T99 relative to the path-only scorer on ``family``'s episodes."""
    names = feature_names(cfg)
    reference, _ = play_scorer(cfg, seeds, scorer(names, 0, 0.0, {"path": -1.0}))
    row: dict[str, Any] = {"family": family}
    for label, (radius, weight) in variants.items():
        t99, _ = play_scorer(cfg, seeds, scorer(names, radius, weight))
        row[label] = float(relative_t99(t99, reference).mean())
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--radii", default="4,8,12,16,20", help="half-sides R, in cells")
    parser.add_argument("--weights", default="-0.2,-0.4,-0.7", help="feature weights W")
    parser.add_argument("--episodes", type=int, default=64, help="training episodes per family")
    parser.add_argument("--first", type=int, default=720_000, help="first training seed")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    if not TRAIN_SEEDS.start <= args.first <= TRAIN_SEEDS.stop - args.episodes:
        parser.error(f"--first .. --first + --episodes must be training seeds, in {TRAIN_SEEDS}")
    radii = parse_list(args.radii, int, "--radii", parser)
    weights = parse_list(args.weights, float, "--weights", parser)
    experiment = load_experiment("explorer-cem")
    seeds = list(range(args.first, args.first + args.episodes))
    variants = {"rule": (0, 0.0)} | {f"R{r} W{w:+g}": (r, w) for r in radii for w in weights}
    rows = []
    for family, cfg in zip(experiment.train.families, experiment.env_configs(), strict=True):
        started = time.perf_counter()
        row = _family_row(family, cfg, seeds, variants)
        rows.append(row)
        cells = "  ".join(
            f"{label} {100 * value:+.2f}" for label, value in row.items() if label != "family"
        )
        print(f"{family}: {cells}  ({time.perf_counter() - started:.0f} s)", flush=True)
    means = {label: float(np.mean([row[label] for row in rows])) for label in variants}
    print("mean: " + "  ".join(f"{label} {100 * value:+.2f}" for label, value in means.items()))
    if args.json is not None:
        options = {
            "radii": radii,
            "weights": weights,
            "episodes": args.episodes,
            "first_seed": args.first,
        }
        payload = {"what": "mean T99 relative to the path-only scorer", "options": options}
        args.json.write_text(json.dumps({**payload, "rows": rows, "mean": means}, indent=1))
    return 0
