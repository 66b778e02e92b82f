"""``frontier-marl baselines``: evaluate the heuristics with the thesis's protocol.

Example::

    frontier-marl baselines --preset thesis-20x20 --map-mode static --episodes 30 \\
        --json baselines.json --plot baselines.png --set cells_per_step=full

Prints a table (the thesis's figures beside ours where the thesis gives them), and optionally
writes the rows as JSON and a PNG figure. With ``--agents N > 1`` the table and JSON also hold
the team metrics (makespan to 90 % / 99 % coverage, overlap; see
:mod:`frontier_marl.evaluation`), and the joint heuristics ``coordinated-assignment`` and
``utility-discount`` are worth naming in ``--policies``. Maps: ``--map FILE_OR_NAME`` (e.g.
``--map rooms-64``) or ``--map-generator rooms``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from frontier_marl.cli.arguments import (
    add_env_arguments,
    env_kwargs_from_args,
    fail,
    parse_policies,
    positive_int,
)
from frontier_marl.experiments.baselines import (
    DEFAULT_POLICIES,
    describe,
    dumps_rows,
    format_table,
    run_baselines,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_env_arguments(parser)
    parser.add_argument(
        "--episodes",
        type=positive_int,
        default=30,
        help="episodes per policy (default: %(default)s)",
    )
    parser.add_argument(
        "--policies",
        default=DEFAULT_POLICIES,
        help="comma-separated heuristics (default: %(default)s)",
    )
    parser.add_argument(
        "--json",
        type=Path,
        default=None,
        metavar="FILE",
        help="write the result rows (with per-episode records) as JSON",
    )
    parser.add_argument(
        "--plot",
        type=Path,
        default=None,
        metavar="FILE",
        help="write a PNG: reward bars and coverage-vs-travel curves",
    )
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")


def run(args: argparse.Namespace) -> int:
    try:
        env_kwargs = env_kwargs_from_args(args)
        policies = parse_policies(args.policies)
    except ValueError as exc:
        return fail("baselines", str(exc))
    rows = run_baselines(env_kwargs, policies, args.episodes, args.seed, not args.no_progress)
    print(describe(env_kwargs, args.episodes, args.seed))
    print(format_table(rows))
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(dumps_rows(rows))
        print(f"wrote {args.json}")
    if args.plot is not None:
        from frontier_marl.evaluation.plots import plot_baselines

        args.plot.parent.mkdir(parents=True, exist_ok=True)
        plot_baselines(rows, args.plot, title=describe(env_kwargs, args.episodes, args.seed))
        print(f"wrote {args.plot}")
    return 0
