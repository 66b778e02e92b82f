"""The command line the benchmark-style studies share: contenders on validation episodes of
some families, the table printed and the rows written as JSON."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from pathlib import Path

from frontier_marl.evaluation.benchmark.families import check_families, family
from frontier_marl.evaluation.benchmark.run import Contender, run_benchmark
from frontier_marl.evaluation.benchmark.stats import format_table


def study_parser(doc: str, families: str) -> argparse.ArgumentParser:
    """A parser described by ``doc``'s first line, with the options every study takes:
    ``--families`` (default ``families``), ``--episodes``, ``--jobs``, ``--json`` and
    ``--no-progress``."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--families", default=families, help="comma-separated map families")
    parser.add_argument("--episodes", type=int, default=16, help="validation episodes")
    parser.add_argument("--jobs", type=int, default=None, help="processes (default: every core)")
    parser.add_argument("--json", type=Path, default=None, help="write the options and rows")
    parser.add_argument("--no-progress", action="store_true")
    return parser


def study_families(parser: argparse.ArgumentParser, args: argparse.Namespace) -> list[str]:
    """The names of ``--families`` (a parser error naming the valid ones otherwise)."""
    names = args.families.split(",")
    try:
        check_families(names, "--families")
    except ValueError as exc:
        parser.error(str(exc))
    return names


def run_study(
    parser: argparse.ArgumentParser,
    args: argparse.Namespace,
    contenders: Sequence[Contender],
    agents: int = 1,
) -> int:
    """Play ``contenders`` on the validation episodes of ``args``'s families, print the table
    and write ``--json``; exit status 0."""
    names = study_families(parser, args)
    rows = run_benchmark(
        [family(name) for name in names],
        contenders,
        args.episodes,
        agents=agents,
        progress=not args.no_progress,
        split="validation",
        jobs=args.jobs,
    )
    print(format_table(rows))
    if args.json is not None:
        args.json.write_text(json.dumps({"options": vars(args) | {"json": None}, "rows": rows}))
    return 0
