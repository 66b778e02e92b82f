"""``frontier-marl campaign``: a grid of experiment configs x seeds x budgets on Ray Tune.

Examples::

    frontier-marl campaign --configs config01,config04,config05 --seeds 0,1,2
    frontier-marl campaign --configs config01 --seeds 0,1,2 --steps 1000000,500000 \\
        --max-concurrent 2 --out runs/campaign
    frontier-marl campaign --configs config01 --seeds 0,1,2,3 --address auto   # a running cluster

Each trial is one training run (the same function as ``frontier-marl train``, one torch thread)
in ``OUT/runs/<config>/seed<S>_steps<N>``, evaluated with the thesis protocol; the results are
collected into ``OUT/campaign.md``, ``campaign.csv`` and ``campaign.json`` (config, seed,
budget, mean/std reward, terminations, action shares, degeneracy flag, wall time). Re-running
the same command reuses finished runs and resumes interrupted ones. Needs the optional extra:
``pip install "frontier-marl[ray]"``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from frontier_marl.cli.arguments import add_set_argument, fail, int_list, positive_int
from frontier_marl.experiments.campaign import CampaignResult, RayNotInstalledError, run_campaign
from frontier_marl.experiments.results import format_markdown


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {value}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--configs",
        default="config01",
        metavar="A,B,...",
        help="experiment configs: names under training/ or TOML paths (default: %(default)s)",
    )
    parser.add_argument(
        "--seeds",
        type=int_list(0),
        default=[0],
        metavar="S,S,...",
        help="training seeds (default: 0)",
    )
    parser.add_argument(
        "--steps",
        type=int_list(1),
        default=[1_000_000],
        metavar="N,N,...",
        help="training budgets (default: 1000000)",
    )
    parser.add_argument(
        "--episodes",
        type=positive_int,
        default=30,
        metavar="N",
        help="evaluation episodes per run (default: %(default)s)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("runs/campaign"),
        metavar="DIR",
        help="output folder (default: %(default)s)",
    )
    parser.add_argument(
        "--address",
        default=None,
        metavar="ADDR",
        help="an existing Ray cluster ('auto', 'ray://host:10001'); "
        "default: start a local Ray instance",
    )
    parser.add_argument(
        "--cpus-per-trial",
        type=_positive_float,
        default=1.0,
        metavar="C",
        help="CPUs Ray reserves per trial (default: %(default)s)",
    )
    parser.add_argument(
        "--max-concurrent",
        type=positive_int,
        default=None,
        metavar="K",
        help="at most K trials at once (default: as many as the CPUs allow)",
    )
    add_set_argument(
        parser,
        "override a config value in every experiment, as in "
        "'frontier-marl train --set' (repeatable)",
    )
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")


#: Columns of the table printed at the end (the files hold every column).
_COLUMNS = (
    "config",
    "seed",
    "steps",
    "mean_reward",
    "std_reward",
    "terminations",
    "episodes",
    "action_shares",
    "degenerate",
    "thesis",
    "wall_time_s",
    "status",
)


def _print_result(result: CampaignResult) -> int:
    """Print the table, the failed trials and the files; 1 if any trial failed."""
    print()
    print(format_markdown(result.rows, _COLUMNS), end="")
    print(
        f"\n{len(result.rows)} trial(s) in {result.wall_time_s:.0f} s, {len(result.failed)} failed"
    )
    for row in result.failed:
        print(
            f"  FAILED {row['config']} seed {row['seed']} steps {row['steps']}: {row.get('error')}",
            file=sys.stderr,
        )
    for label, path in result.files.items():
        print(f"  {label + ':':<10} {path}")
    return 1 if result.failed else 0


def run(args: argparse.Namespace) -> int:
    configs = [c.strip() for c in args.configs.split(",") if c.strip()]
    try:
        result = run_campaign(
            configs,
            args.seeds,
            args.steps,
            args.out,
            address=args.address,
            cpus_per_trial=args.cpus_per_trial,
            max_concurrent=args.max_concurrent,
            eval_episodes=args.episodes,
            overrides=args.overrides,
            progress=not args.no_progress,
        )
    except RayNotInstalledError as exc:
        return fail("campaign", str(exc))
    except ValueError as exc:
        return fail("campaign", str(exc))
    return _print_result(result)
