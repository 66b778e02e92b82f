"""``frontier-marl evaluate``: the thesis protocol on a saved model, beside greedy-distance.

Examples::

    frontier-marl evaluate runs/config01/seed0                 # the run's final model.zip
    frontier-marl evaluate runs/config01/seed0/model.zip --map-mode dynamic --episodes 30 \\
        --json eval.json --plot actions.png
    frontier-marl evaluate thesis-config01 --jobs 4          # 4 processes (default: all cores)
    frontier-marl evaluate explorer --preset rooms-32        # the map-aware explorer

The env is the one the model was trained on (read from the ``model.json`` beside it), changed
only by ``--map-mode``, ``--preset`` and ``--set``. A map-aware scorer (``explorer``) was
trained on several families, so it plays the world of ``--preset`` (default thesis-20x20, fresh
layouts), observed as frontier-rule observes it. Reported: mean and std of the total episode
reward, terminations (episodes reaching the exploration threshold), action shares and the
degeneracy flag (one action in more than 90 % of steps), for the model (deterministic) and
greedy-distance on the same episodes. A model whose observation layout or spaces do not match
the env is refused with the list of differences.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from frontier_marl.cli.arguments import (
    add_parallel_arguments,
    add_set_argument,
    check_parallel_arguments,
    non_negative_int,
    parse_policies,
    positive_int,
)
from frontier_marl.config import PRESETS, EnvConfig
from frontier_marl.evaluation.model_evaluation import (
    evaluate_map_scorer,
    evaluate_model,
    evaluation_env_config,
    format_comparison,
    map_scorer_env_config,
)
from frontier_marl.policies.metadata import ModelEnvMismatchError
from frontier_marl.policies.models import load_model, map_scorer_folder
from frontier_marl.utils.set_options import parse_set_options


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "model",
        metavar="MODEL",
        help="model.zip, a run folder, a checkpoint folder, a map scorer's folder, or a "
        "shipped model's name (thesis-config01, explorer)",
    )
    parser.add_argument(
        "--episodes",
        type=positive_int,
        default=30,
        help="evaluation episodes (default: %(default)s)",
    )
    parser.add_argument(
        "--map-mode",
        choices=["static", "dynamic"],
        default=None,
        help="map mode (default: the one the model was trained on; dynamic for a map scorer)",
    )
    parser.add_argument(
        "--seed",
        type=non_negative_int,
        default=0,
        help="episode i uses reset seed SEED + i (default: %(default)s)",
    )
    parser.add_argument(
        "--preset",
        choices=sorted(PRESETS),
        default=None,
        help="evaluate on another geometry (default: the training env's; thesis-20x20 for a "
        "map scorer)",
    )
    parser.add_argument(
        "--agents",
        type=positive_int,
        default=None,
        help="robots sharing the belief; each acts with the shared-parameter "
        "model (default: as trained)",
    )
    add_set_argument(parser, "any other env parameter (repeatable)")
    parser.add_argument(
        "--heuristics",
        default="greedy-distance",
        help="comma-separated heuristics run on the same episodes "
        "(default: %(default)s; empty for none)",
    )
    add_parallel_arguments(parser)
    parser.add_argument(
        "--json",
        type=Path,
        default=None,
        metavar="FILE",
        help="write the result (rows with per-episode records) as JSON",
    )
    parser.add_argument(
        "--plot",
        type=Path,
        default=None,
        metavar="FILE",
        help="write the action histogram as a PNG",
    )
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")


def _fail(message: str) -> int:
    print(f"frontier-marl evaluate: error: {message}", file=sys.stderr)
    return 2


def run(args: argparse.Namespace) -> int:
    try:
        overrides = parse_set_options(args.overrides)
        if args.map_mode is not None:
            overrides["map_mode"] = args.map_mode
        if args.agents is not None:
            overrides["n_agents"] = args.agents
        heuristics = parse_policies(args.heuristics) if args.heuristics.strip() else []
        scorer = map_scorer_folder(args.model)
        if scorer is not None:
            check_parallel_arguments(args)
            return _run_map_scorer(args, scorer, overrides, heuristics)
        loaded = load_model(args.model)
        cfg = evaluation_env_config(loaded, args.preset, overrides)
        check_parallel_arguments(args)
    except ValueError as exc:
        return _fail(str(exc))
    if loaded.metadata is None:
        print(
            f"note: {loaded.path} has no model.json metadata; evaluating on "
            f"{args.preset or 'thesis-20x20'} with the given overrides",
            file=sys.stderr,
        )

    try:
        result = evaluate_model(loaded, cfg, **_protocol(args, heuristics))
    except (ModelEnvMismatchError, ConnectionError) as exc:
        return _fail(str(exc))
    _report(args, result, f"{loaded.path} ({result['num_timesteps']} training steps)", cfg)
    return 0


def _run_map_scorer(
    args: argparse.Namespace, folder: Path, overrides: dict[str, Any], heuristics: list[str]
) -> int:
    """The protocol for a map-aware scorer on the world of ``--preset``."""
    overrides.setdefault("map_mode", "dynamic")
    try:
        cfg = map_scorer_env_config(args.preset, overrides)
        result = evaluate_map_scorer(folder, cfg, **_protocol(args, heuristics))
    except (ValueError, ConnectionError) as exc:
        return _fail(str(exc))
    _report(args, result, f"{folder} (map scorer, {result['labels']:,} labelled candidates)", cfg)
    return 0


def _protocol(args: argparse.Namespace, heuristics: list[str]) -> dict[str, Any]:
    """The episodes, heuristics and workers of the command line, for either kind of model."""
    return {
        "episodes": args.episodes,
        "seed": args.seed,
        "heuristics": heuristics,
        "jobs": args.jobs,
        "ray_address": args.ray_address,
        "progress": not args.no_progress,
    }


def _report(args: argparse.Namespace, result: dict[str, Any], what: str, cfg: EnvConfig) -> None:
    """Print the comparison; write the JSON and the action histogram if asked."""
    layout = f"map_seed={cfg.map_seed}" if cfg.map_mode == "static" else "fresh layout per seed"
    last = args.seed + args.episodes - 1
    print(
        f"{what}: {cfg.height}x{cfg.width}, r={cfg.perception_range}, {cfg.map_mode} map "
        f"({layout}), {args.episodes} episodes, seeds {args.seed}..{last}, deterministic"
    )
    print(format_comparison(result))
    if args.json is not None:
        from frontier_marl.utils.json_files import write_json

        write_json(result, args.json)
        print(f"wrote {args.json}")
    if args.plot is not None:
        from frontier_marl.training.plots import plot_action_histogram

        args.plot.parent.mkdir(parents=True, exist_ok=True)
        title = f"{Path(result['model_path']).name}: actions"
        plot_action_histogram(result["rows"], args.plot, title=title)
        print(f"wrote {args.plot}")
