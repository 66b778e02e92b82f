"""How much frontier-rule's T99 moves when its weights move, on several sets of episodes.

frontier-rule's weights were the linear ``explorer``'s until the map-aware model replaced it.

For every ``NAME:FACTOR`` of ``--directions`` (``NAME`` a feature, or ``lengths`` for every
weight on a length feature at once: path, distance, d_row, d_col, isolation, extra_path, tour),
frontier-rule's weights with that weight multiplied by ``FACTOR`` play the same training
episodes of every family of the ``explorer-cem`` config as the unchanged weights, played as CEM
plays them; the paired per-episode T99 change is reported with its standard error, once per
seed set of ``--seed-sets`` (disjoint sets of training seeds). A change that is real shows on
every set; one that shows on a single set is the noise of that set's episodes::

    python benchmarks/explorer_weight_sensitivity.py --seed-sets 730000,731000,732000 \\
        --episodes 64 --json training/results/explorer/weight-sensitivity.json
"""

from __future__ import annotations

import argparse
import json
import time
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.evaluation.benchmark.families import TRAIN_SEEDS
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_WEIGHTS
from frontier_marl.policies.linear_scorer import feature_names, weight_vector
from frontier_marl.training.cem import changes_text, paired_change, play_t99
from frontier_marl.training.experiment import load_experiment

DIRECTIONS = "lengths:1.25,lengths:1.6,tour:0.8,tour:1.25,unknown_near:0.7,unknown_near:1.4"
LENGTHS = ("path", "distance", "d_row", "d_col", "isolation", "extra_path", "tour")


def parse_directions(text: str, names: list[str]) -> list[tuple[str, float]]:
    """``NAME:FACTOR,...`` as (name, factor) pairs; ValueError naming a bad entry."""
    directions = []
    for entry in text.split(","):
        name, _, factor = entry.partition(":")
        if name != "lengths" and name not in names:
            raise ValueError(f"--directions: {name!r} is neither 'lengths' nor a feature {names}")
        try:
            directions.append((name, float(factor)))
        except ValueError:
            raise ValueError(f"--directions: {entry!r} is not NAME:FACTOR") from None
    return directions


def scaled(weights: np.ndarray, names: list[str], name: str, factor: float) -> np.ndarray:
    """``weights`` with the weight of ``name`` (every length weight for ``lengths``) times
    ``factor``."""
    chosen = LENGTHS if name == "lengths" else (name,)
    return np.array([w * factor if n in chosen else w for w, n in zip(weights, names, strict=True)])


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--directions", default=DIRECTIONS, help="NAME:FACTOR,...")
    parser.add_argument("--seed-sets", default="730000,731000,732000", help="first seeds")
    parser.add_argument("--episodes", type=int, default=64, help="episodes per family and set")
    parser.add_argument("--json", type=Path, default=None)
    return parser


def _seed_sets(parser: argparse.ArgumentParser, args: argparse.Namespace) -> list[int]:
    """The first seed of each set, after checking that the sets are disjoint training seeds."""
    if args.episodes < 2:
        parser.error(f"--episodes must be at least 2 (for the standard error), got {args.episodes}")
    try:
        firsts = [int(first) for first in args.seed_sets.split(",")]
    except ValueError:
        parser.error(f"--seed-sets must be comma-separated seeds, got {args.seed_sets!r}")
    ranges = sorted((first, first + args.episodes) for first in firsts)
    if any(a[1] > b[0] for a, b in pairwise(ranges)):
        parser.error("the seed sets overlap: space their first seeds at least --episodes apart")
    if ranges[0][0] < TRAIN_SEEDS.start or ranges[-1][1] > TRAIN_SEEDS.stop:
        parser.error(f"every seed set must lie in the training seeds, {TRAIN_SEEDS}")
    return firsts


def _family_rows(
    family: str,
    cfg: EnvConfig,
    firsts: list[int],
    episodes: int,
    weights: np.ndarray,
    names: list[str],
    directions: list[tuple[str, float]],
) -> list[dict[str, Any]]:
    """Each direction's paired T99 change against the shipped weights, on each seed set."""
    rows = []
    for first in firsts:
        seeds = list(range(first, first + episodes))
        reference, _ = play_t99(cfg, seeds, weights)
        for name, factor in directions:
            t99, _ = play_t99(cfg, seeds, scaled(weights, names, name, factor))
            rows.append(
                {
                    "family": family,
                    "first_seed": first,
                    "direction": f"{name}:{factor:g}",
                    **paired_change(t99, reference),
                }
            )
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    firsts = _seed_sets(parser, args)
    experiment = load_experiment("explorer-cem")
    names = feature_names(experiment.env_config())  # the same on every family
    try:
        directions = parse_directions(args.directions, names)
    except ValueError as exc:
        parser.error(str(exc))
    weights = weight_vector(FRONTIER_RULE_WEIGHTS, names, "frontier-rule's weights")
    rows = []
    for family, cfg in zip(experiment.train.families, experiment.env_configs(), strict=True):
        started = time.perf_counter()
        rows += _family_rows(family, cfg, firsts, args.episodes, weights, names, directions)
        mine = [row for row in rows if row["family"] == family]
        cells = changes_text({f"{row['direction']}@{row['first_seed']}": row for row in mine})
        print(f"{family}: {cells}  ({time.perf_counter() - started:.0f} s)", flush=True)
    if args.json is not None:
        options = {"episodes": args.episodes, "seed_sets": firsts, "directions": args.directions}
        what = "mean paired per-episode T99 change against frontier-rule's weights"
        args.json.write_text(json.dumps({"what": what, "options": options, "rows": rows}, indent=1))
    return 0
