"""Command-line options shared by the commands, and their parsing into validated values."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any

from frontier_marl.config import PRESETS, make_config
from frontier_marl.core.example_maps import example_map_names
from frontier_marl.policies import POLICIES
from frontier_marl.utils.parallel import default_jobs, require_ray
from frontier_marl.utils.set_options import parse_set_options


def int_at_least(low: int) -> Callable[[str], int]:
    """argparse type: an integer >= ``low``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected an integer >= {low}, got {text!r}"
            ) from None
        if value < low:
            raise argparse.ArgumentTypeError(f"expected an integer >= {low}, got {value}")
        return value

    return parse


positive_int = int_at_least(1)
non_negative_int = int_at_least(0)


def int_list(low: int) -> Callable[[str], list[int]]:
    """argparse type: comma-separated integers >= ``low`` (``1e6`` and ``1_000_000`` work)."""

    def parse(text: str) -> list[int]:
        values = []
        for item in text.split(","):
            item = item.strip().replace("_", "")
            if not item:
                continue
            try:
                value = int(float(item)) if "e" in item.lower() else int(item)
            except ValueError:
                raise argparse.ArgumentTypeError(
                    f"expected comma-separated integers >= {low}, got {text!r}"
                ) from None
            if value < low:
                raise argparse.ArgumentTypeError(f"expected integers >= {low}, got {value}")
            values.append(value)
        if not values:
            raise argparse.ArgumentTypeError(f"expected at least one integer, got {text!r}")
        return values

    return parse


def add_set_argument(parser: argparse.ArgumentParser, help_text: str) -> None:
    """The repeatable ``--set KEY=VALUE`` option (values in ``args.overrides``)."""
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE", help=help_text
    )


def add_env_arguments(parser: argparse.ArgumentParser) -> None:
    """``--preset --map --map-generator --map-mode --seed --agents --set`` (shared by
    ``baselines`` and ``gif``)."""
    parser.add_argument(
        "--preset",
        choices=sorted(PRESETS),
        default="thesis-20x20",
        help="thesis geometry (default: %(default)s)",
    )

    parser.add_argument(
        "--map",
        default=None,
        metavar="PATH",
        help="load the layout from a .txt, .pgm or .png file, or name an "
        f"example map ({', '.join(example_map_names())}); the file sets the "
        "size and the map is static",
    )
    parser.add_argument(
        "--map-generator",
        choices=["random", "rooms"],
        default=None,
        help="random obstacles or rooms and corridors (default: the preset's)",
    )
    parser.add_argument(
        "--map-mode",
        choices=["static", "dynamic"],
        default=None,
        help="static: one layout from the config's map_seed; dynamic: a new "
        "layout per episode (default: the preset's)",
    )
    parser.add_argument(
        "--seed",
        type=non_negative_int,
        default=0,
        help="episode i uses reset seed SEED + i (default: %(default)s)",
    )
    parser.add_argument(
        "--agents",
        type=positive_int,
        default=1,
        help="robots sharing one belief (default: %(default)s)",
    )
    add_set_argument(
        parser,
        "any other env parameter, e.g. --set cells_per_step=full --set sensor=raycast (repeatable)",
    )


def env_kwargs_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """Env keyword arguments from the shared options, validated (ValueError if invalid)."""
    kwargs: dict[str, Any] = {"preset": args.preset}
    overrides = parse_set_options(args.overrides)
    for reserved in ("preset", "config"):
        if reserved in overrides:
            raise ValueError(f"--set {reserved}=... is not allowed; use the dedicated option")
    kwargs.update(overrides)
    map_file = getattr(args, "map", None)
    generator = getattr(args, "map_generator", None)
    if map_file is not None:
        from frontier_marl.core.example_maps import resolve_map

        if generator is not None:
            raise ValueError("--map and --map-generator exclude each other (a file is the map)")
        if "map_path" in overrides:
            raise ValueError("give the map file once: --map or --set map_path=..., not both")
        kwargs["map_path"] = resolve_map(map_file)
    if generator is not None:
        kwargs["map_generator"] = generator
    if args.map_mode is not None:
        kwargs["map_mode"] = args.map_mode
    kwargs["n_agents"] = args.agents
    make_config(**kwargs)  # validate now, with the config's own error messages
    return kwargs


def add_parallel_arguments(parser: argparse.ArgumentParser) -> None:
    """``--jobs N`` and ``--ray-address ADDRESS``: where the episodes run
    (:func:`frontier_marl.utils.parallel.map_tasks`)."""
    parser.add_argument(
        "--jobs",
        type=positive_int,
        default=None,
        metavar="N",
        help=f"play the episodes in N processes (default: every core, {default_jobs()} here; "
        "1: in this process); the results do not depend on N",
    )
    parser.add_argument(
        "--ray-address",
        default=None,
        metavar="ADDRESS",
        help="play the episodes on a Ray cluster instead (auto: the cluster this machine "
        "joined with `ray start`; HOST:PORT or ray://HOST:10001: that cluster; local: a new "
        "one here); needs the ray extra, and --jobs is then ignored",
    )


def check_parallel_arguments(args: argparse.Namespace) -> None:
    """ValueError when ``--ray-address`` is given without Ray installed."""
    if args.ray_address is not None:
        try:
            require_ray()
        except ImportError as exc:
            raise ValueError(f"--ray-address: {exc}") from None


def fail(command: str, message: str | Exception) -> int:
    """Print the one-line error of ``command`` (an exception's message with its notes, e.g.
    which episode raised it) and return exit status 2."""
    if isinstance(message, Exception):
        message = "; ".join([str(message), *getattr(message, "__notes__", ())])
    print(f"frontier-marl {command}: error: {message}", file=sys.stderr)
    return 2


def parse_policies(text: str) -> list[str]:
    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names:
        raise ValueError(f"--policies must name at least one of {list(POLICIES)}")
    unknown = [name for name in names if name not in POLICIES]
    if unknown:
        raise ValueError(f"unknown policy {unknown[0]!r}; valid: {', '.join(POLICIES)}")
    return names
