"""Would the explorer gain from knowing what each frontier would reveal? A privileged probe.

Each slot gets one more score term, ``W * gain``, beside frontier-rule's weights (the linear
``explorer``'s until the map-aware model replaced it): ``gain`` is the share of the sensor's
disc that one sensing at the slot's target would newly reveal, computed on the TRUE map
(``true``: line of sight through the true walls, as the env senses) or, as a control without
privilege, the unknown share of that disc in the belief (``belief``: no occlusion). Every W of
``--weights`` plays the same training episodes of every family of the ``explorer-cem`` config
as the unchanged weights (W = 0), played as CEM plays them; the paired per-episode T99 change
is reported with its standard error::

    python benchmarks/explorer_true_gain_probe.py --weights=-0.25,-0.1,0.1,0.25 \\
        --episodes 64 --first 736000 --json training/results/explorer/true-gain-probe.json

No policy may read the true map; this only asks how much a perfect predictor of a frontier's
immediate gain would be worth to the explorer's linear scorer.
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
from frontier_marl.core.grid import UNKNOWN
from frontier_marl.core.sensing import reveal
from frontier_marl.envs.vector import FrontierVectorEnv
from frontier_marl.evaluation.benchmark.families import TRAIN_SEEDS
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_WEIGHTS
from frontier_marl.policies.linear_scorer import feature_names, weight_vector
from frontier_marl.training.cem import changes_text, paired_change, play_scorer
from frontier_marl.training.experiment import load_experiment

KINDS = ("true", "belief")
Scorer = Callable[[dict[str, np.ndarray], FrontierVectorEnv], np.ndarray]


def disc_gains(env: FrontierVectorEnv, kind: str) -> np.ndarray:
    """(N, n_slots) share of the sensor's disc that is unknown around each live slot's target
    and, for ``true``, would be revealed there (line of sight on the true map); 0 elsewhere."""
    worlds = env.mdp.worlds
    slots = env.mdp.slots.rows(slice(None))
    offsets, between = worlds.params.sensor.rays
    height, width = worlds.belief.shape[1:]
    gains = np.zeros(slots.valid.shape)
    for world, slot in zip(*np.nonzero(slots.valid), strict=True):
        row, col = (int(x) for x in slots.target[world, slot])
        belief = worlds.belief[world]
        if kind == "true":
            seen = np.zeros(belief.shape, dtype=bool)
            revealed = reveal(worlds.true[world], belief.copy(), seen, row, col, offsets, between)
        else:
            rows, cols = row + offsets[:, 0], col + offsets[:, 1]
            inside = (rows >= 0) & (rows < height) & (cols >= 0) & (cols < width)
            revealed = np.count_nonzero(belief[rows[inside], cols[inside]] == UNKNOWN)
        gains[world, slot] = revealed / len(offsets)
    return gains


def scorer(names: list[str], weights: dict[str, float], kind: str, weight: float) -> Scorer:
    """The linear scores of ``weights`` plus ``weight`` times :func:`disc_gains`."""
    linear = weight_vector(weights, names, "the explorer's weights")

    def score(observations: dict[str, np.ndarray], env: FrontierVectorEnv) -> np.ndarray:
        scores = observations["slots"].astype(np.float64) @ linear
        return scores + weight * disc_gains(env, kind) if weight else scores

    return score


def _parse_args(argv: list[str] | None) -> tuple[argparse.Namespace, list[float], list[str]]:
    """The options, with the checked weights and gain kinds."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--weights", default="-0.25,-0.1,0.1,0.25", help="weights W of the gain")
    parser.add_argument("--kinds", default="true,belief", help=f"gains among {KINDS}")
    parser.add_argument("--episodes", type=int, default=64, help="training episodes per family")
    parser.add_argument("--first", type=int, default=736_000, help="first training seed")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    if args.episodes < 2:
        parser.error(f"--episodes must be at least 2 (for the standard error), got {args.episodes}")
    if not TRAIN_SEEDS.start <= args.first <= TRAIN_SEEDS.stop - args.episodes:
        parser.error(f"--first .. --first + --episodes must be training seeds, in {TRAIN_SEEDS}")
    try:
        weights = [float(w) for w in args.weights.split(",")]
    except ValueError:
        parser.error(f"--weights must be comma-separated numbers, got {args.weights!r}")
    kinds = args.kinds.split(",")
    if not set(kinds) <= set(KINDS):
        parser.error(f"--kinds must be among {KINDS}, got {args.kinds!r}")
    return args, weights, kinds


def _family_rows(
    family: str,
    cfg: EnvConfig,
    seeds: list[int],
    shipped: dict[str, float],
    kinds: list[str],
    weights: list[float],
) -> list[dict[str, Any]]:
    """Each gain kind and weight's paired T99 change against the shipped weights."""
    rows = []
    names = feature_names(cfg)
    reference, _ = play_scorer(cfg, seeds, scorer(names, shipped, "true", 0.0))
    for kind in kinds:
        for weight in weights:
            t99, _ = play_scorer(cfg, seeds, scorer(names, shipped, kind, weight))
            rows.append(
                {"family": family, "kind": kind, "weight": weight, **paired_change(t99, reference)}
            )
    return rows


def main(argv: list[str] | None = None) -> int:
    args, weights, kinds = _parse_args(argv)
    experiment = load_experiment("explorer-cem")
    shipped = dict(FRONTIER_RULE_WEIGHTS)
    seeds = list(range(args.first, args.first + args.episodes))
    rows = []
    for family, cfg in zip(experiment.train.families, experiment.env_configs(), strict=True):
        started = time.perf_counter()
        rows += _family_rows(family, cfg, seeds, shipped, kinds, weights)
        mine = [row for row in rows if row["family"] == family]
        cells = changes_text({f"{row['kind']} W{row['weight']:+g}": row for row in mine})
        print(f"{family}: {cells}  ({time.perf_counter() - started:.0f} s)", flush=True)
    if args.json is not None:
        options = {"weights": weights, "kinds": kinds, "episodes": args.episodes}
        what = "mean paired per-episode T99 change against frontier-rule's weights"
        payload = {"what": what, "options": {**options, "first_seed": args.first}, "rows": rows}
        args.json.write_text(json.dumps(payload, indent=1))
    return 0
