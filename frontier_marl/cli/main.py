"""The ``frontier-marl`` command. Each subcommand lives in ``frontier_marl.cli.commands.<name>``
and exposes ``add_arguments(parser)`` and ``run(args) -> int``; modules load lazily, so
``frontier-marl --help`` does not import torch."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

#: subcommand -> (module under frontier_marl.cli.commands, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "gif": ("gif", "run one episode with a heuristic and write it as a GIF"),
    "baselines": ("baselines", "evaluate the heuristic baselines with the thesis's protocol"),
    "benchmark": (
        "benchmark",
        "exploration efficiency (T99, T90, success) of policies on map families",
    ),
    "train": ("train", "train an experiment config (DQN, PPO, MaskablePPO or CEM)"),
    "evaluate": ("evaluate", "evaluate a trained model with the thesis's protocol"),
    "reproduce": (
        "reproduce",
        "train configuration 1 and compare it with the heuristics and the thesis",
    ),
    "campaign": ("campaign", "train a grid of configs x seeds x budgets with Ray Tune"),
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="frontier-marl",
        description="Learned frontier selection for autonomous grid exploration.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in COMMANDS.items():
        module = importlib.import_module(f"frontier_marl.cli.commands.{module_name}")
        command = sub.add_parser(name, help=help_text, description=help_text)
        module.add_arguments(command)
        command.set_defaults(_module=module)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(args._module.run(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
