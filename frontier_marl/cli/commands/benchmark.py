"""``frontier-marl benchmark``: exploration efficiency on map families' held-out episodes.

Examples::

    frontier-marl benchmark                                  # 4 families, every heuristic
    frontier-marl benchmark --families random-20 --policies nearest-path,thesis-config01
    frontier-marl benchmark --map ../shared/maps/explore-bench --json eb.json --plot eb.png
    frontier-marl benchmark --agents 3 --set cells_per_step=full
    frontier-marl benchmark --jobs 8                         # 8 processes (default: all cores)
    frontier-marl benchmark --ray-address auto               # on the Ray cluster of this node

Prints per family and policy: success (99 % coverage before the limit), T99 and T90 (cells
travelled, mean ± std over the episodes that got there), and the paired relative T99
difference to the family's best heuristic with its 95 % confidence interval; with
``--agents K > 1`` also the makespan to 99 % and the overlap. docs/benchmark.md has the
definitions.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from frontier_marl.cli.arguments import (
    add_parallel_arguments,
    add_set_argument,
    check_parallel_arguments,
    fail,
    positive_int,
)
from frontier_marl.evaluation.benchmark import families as map_families
from frontier_marl.evaluation.benchmark import run as bench
from frontier_marl.evaluation.benchmark.families import DEFAULT_EPISODES, FAMILIES, SPLITS
from frontier_marl.evaluation.benchmark.stats import format_table, plot_benchmark
from frontier_marl.utils.json_files import write_json
from frontier_marl.utils.set_options import parse_set_options

#: The default heuristics: the thesis's two, cost-utility and nearest-path; teams add the joint
#: ones.
HEURISTICS = ("greedy-distance", "greedy-gain", "cost-utility", "nearest-path", "frontier-rule")
TEAM_HEURISTICS = ("coordinated-assignment", "utility-discount")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--families",
        default=None,
        help=f"comma-separated map families ({', '.join(FAMILIES)}; default: all of them, "
        "or none when --map is given)",
    )
    parser.add_argument(
        "--map",
        dest="maps",
        action="append",
        default=[],
        metavar="PATH",
        help="a map file (.pgm, .png, .txt), a folder of them or an example map name "
        "(repeatable): one more family whose episodes cycle through the maps",
    )
    parser.add_argument(
        "--policies",
        default=None,
        help="comma-separated heuristic names, lookahead-oracle (one robot) or "
        "team-lookahead-oracle (any team; both read the true map) and model names or paths "
        "(default: "
        f"{','.join(HEURISTICS)}, plus {','.join(TEAM_HEURISTICS)} with --agents > 1)",
    )
    parser.add_argument(
        "--episodes",
        type=positive_int,
        default=DEFAULT_EPISODES,
        help="episodes per family and policy (default: %(default)s)",
    )
    parser.add_argument(
        "--split",
        choices=list(SPLITS),
        default="heldout",
        help="which episodes: heldout (seeds 900,000+, the report's; the default) or validation "
        "(seeds 800,000+, for model selection and tuning)",
    )
    parser.add_argument(
        "--agents", type=positive_int, default=1, help="robots per team (default: %(default)s)"
    )
    parser.add_argument(
        "--commit",
        choices=["auto", "until-progress", "until-reached", "none"],
        default="auto",
        help="the heuristics' commit rule; auto (the default): until-progress with one robot "
        "(it prevents livelocks), none with a team (docs/benchmark.md)",
    )
    add_set_argument(
        parser,
        "an env parameter for every family and policy, e.g. --set perception_range=4 "
        "--set cells_per_step=full (repeatable)",
    )
    add_parallel_arguments(parser)
    parser.add_argument("--json", type=Path, default=None, metavar="FILE", help="write the rows")
    parser.add_argument(
        "--plot", type=Path, default=None, metavar="FILE", help="write a PNG of T99 per family"
    )
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")


def _names(text: str | None) -> list[str]:
    return [] if text is None else [n.strip() for n in text.split(",") if n.strip()]


def run(args: argparse.Namespace) -> int:
    try:
        names = _names(args.families)
        if args.families is not None and not names:
            raise ValueError("--families must name at least one family")
        if args.families is None and not args.maps:
            names = list(map_families.FAMILIES)
        families = [map_families.family(name) for name in names]
        if args.maps:
            families.append(map_families.map_family(args.maps))
        overrides = parse_set_options(args.overrides)
        policy_names = _names(args.policies)
        if args.policies is None:
            policy_names = list(HEURISTICS) + (list(TEAM_HEURISTICS) if args.agents > 1 else [])
        if not policy_names:
            raise ValueError("--policies must name at least one policy")
        commit = bench.default_commit(args.agents) if args.commit == "auto" else args.commit
        policies = bench.contenders(policy_names, commit)
        if args.agents > 1 and bench.ORACLE in policy_names:
            raise ValueError(f"{bench.ORACLE} drives one robot; drop it or use --agents 1")
        for fam in families:
            fam.seeds(args.episodes, args.split)
            map_families.variant_configs(fam, overrides, args.agents)
        check_parallel_arguments(args)
    except ValueError as exc:
        return fail("benchmark", str(exc))
    start = time.perf_counter()
    try:
        rows = bench.run_benchmark(
            families,
            policies,
            args.episodes,
            args.agents,
            overrides,
            progress=not args.no_progress,
            log=lambda text: print(text, file=sys.stderr),
            split=args.split,
            jobs=args.jobs,
            ray_address=args.ray_address,
        )
    except (ValueError, ConnectionError) as exc:  # e.g. a policy refusing a family's world
        return fail("benchmark", exc)
    wall = time.perf_counter() - start
    first = (
        map_families.HELDOUT_SEEDS if args.split == "heldout" else map_families.VALIDATION_SEEDS
    ).start
    split = "held-out" if args.split == "heldout" else "validation"
    title = (
        f"{args.episodes} {split} episodes per family (seeds {first}..."
        f"{first + args.episodes - 1}), {args.agents} robot(s)"
        + (f", {' '.join(args.overrides)}" if args.overrides else "")
    )
    print(title)
    print(format_table(rows, markdown=args.markdown))
    print(
        "T99/T90: cells travelled to 99 %/90 % coverage, mean ± std over the episodes that got "
        "there (* = not all did); vs best: paired per-episode relative difference to the "
        f"family's best heuristic, 95 % t-interval. {wall:.0f} s wall."
    )
    if args.json is not None:
        options = {
            "families": [fam.name for fam in families],
            "maps": list(args.maps),
            "policies": policy_names,
            "episodes": args.episodes,
            "split": args.split,
            "agents": args.agents,
            "commit": commit,
            "set": list(args.overrides),
            "jobs": args.jobs,
            "ray_address": args.ray_address,
        }
        write_json({"options": options, "wall_seconds": wall, "rows": rows}, args.json)
        print(f"wrote {args.json}")
    if args.plot is not None and rows:
        args.plot.parent.mkdir(parents=True, exist_ok=True)
        plot_benchmark(rows, args.plot, title=title)
        print(f"wrote {args.plot}")
    return 0
