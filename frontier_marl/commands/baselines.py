"""``frontier-marl baselines``: evaluate the heuristics with the thesis's protocol.

Example::

    frontier-marl baselines --preset thesis-20x20 --map-mode static --episodes 30 \\
        --json baselines.json --plot baselines.png --set cells_per_step=full

Prints a table (the thesis's figures beside ours where SPEC gives them), and optionally writes
the rows as JSON and a PNG figure. With ``--agents N > 1`` the table and JSON also hold the team
metrics (makespan to 90 % / 99 % coverage, overlap; see :mod:`frontier_marl.evaluation`), and
the joint heuristics ``coordinated-assignment`` and ``utility-discount`` are worth naming in
``--policies``. Maps: ``--map FILE_OR_NAME`` (e.g. ``--map rooms-64``) or
``--map-generator rooms``. Also home of the env options shared with ``gif``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from frontier_marl.config import PRESETS

DEFAULT_POLICIES = "greedy-distance,greedy-gain,cost-utility,random"


# --------------------------------------------------------------------------- shared env options


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


def parse_value(text: str) -> Any:
    """A ``--set`` value: int, float, bool (true/false), None (none), else the string
    (e.g. ``full``, ``raycast``)."""
    lowered = text.strip().lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    if lowered in ("none", "null"):
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text.strip()


def parse_set_options(items: Sequence[str] | None) -> dict[str, Any]:
    """``["key=value", ...]`` -> ``{key: parsed value}``; ValueError on a malformed item."""
    out: dict[str, Any] = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        key = key.strip().replace("-", "_")
        if not sep or not key:
            raise ValueError(f"--set expects key=value, got {item!r}")
        out[key] = parse_value(value)
    return out


def add_env_arguments(parser: argparse.ArgumentParser) -> None:
    """``--preset --map --map-generator --map-mode --seed --agents --set`` (shared by
    ``baselines`` and ``gif``)."""
    parser.add_argument(
        "--preset",
        choices=sorted(PRESETS),
        default="thesis-20x20",
        help="thesis geometry (default: %(default)s)",
    )
    from frontier_marl.example_maps import example_map_names

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
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="any other env parameter, e.g. --set cells_per_step=full "
        "--set sensor=raycast (repeatable)",
    )


def env_kwargs_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """Env keyword arguments from the shared options, validated (ValueError if invalid)."""
    from frontier_marl.config import make_config

    kwargs: dict[str, Any] = {"preset": args.preset}
    overrides = parse_set_options(args.overrides)
    for reserved in ("preset", "config"):
        if reserved in overrides:
            raise ValueError(f"--set {reserved}=... is not allowed; use the dedicated option")
    kwargs.update(overrides)
    map_file = getattr(args, "map", None)
    generator = getattr(args, "map_generator", None)
    if map_file is not None:
        from frontier_marl.example_maps import resolve_map

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


def fail(command: str, message: str) -> int:
    print(f"frontier-marl {command}: error: {message}", file=sys.stderr)
    return 2


# --------------------------------------------------------------------------- command


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


def parse_policies(text: str) -> list[str]:
    from frontier_marl.policies import POLICIES

    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names:
        raise ValueError(f"--policies must name at least one of {list(POLICIES)}")
    unknown = [name for name in names if name not in POLICIES]
    if unknown:
        raise ValueError(f"unknown policy {unknown[0]!r}; valid: {', '.join(POLICIES)}")
    return names


def run_baselines(
    env_kwargs: dict[str, Any],
    policies: Sequence[str],
    episodes: int,
    seed: int,
    progress: bool = True,
) -> list[dict[str, Any]]:
    """Evaluate each heuristic; one JSON-able row per policy (see ``EvaluationResult``)."""
    from tqdm import tqdm

    from frontier_marl.config import make_config
    from frontier_marl.evaluation import evaluate, thesis_figure
    from frontier_marl.policies import make_policy

    cfg = make_config(**env_kwargs)
    preset = str(env_kwargs.get("preset", "thesis-20x20"))
    # The thesis's figures are shown for its geometry (size, range) with one robot only.
    base = make_config(preset)
    comparable = (
        cfg.n_agents == 1
        and cfg.map_path is None
        and cfg.map_generator == base.map_generator
        and (cfg.height, cfg.width, cfg.perception_range)
        == (base.height, base.width, base.perception_range)
    )
    rows = []
    with tqdm(
        total=episodes * len(policies),
        disable=not progress,
        unit="ep",
        file=sys.stderr,
        dynamic_ncols=True,
    ) as bar:
        for name in policies:
            bar.set_description(name)
            result = evaluate(
                dict(env_kwargs),
                make_policy(name, seed),
                episodes=episodes,
                seed=seed,
                on_episode=lambda _i, _rec: bar.update(1),
            )
            row = result.to_dict()
            figure = thesis_figure(preset, cfg.map_mode, name) if comparable else None
            row["preset"] = preset
            row["thesis_mean"] = None if figure is None else figure[0]
            row["thesis_std"] = None if figure is None else figure[1]
            rows.append(row)
    return rows


def _fmt_cells(entry: dict[str, Any], episodes: int) -> str:
    if not entry["reached"]:
        return f"— (0/{episodes})"
    return f"{entry['mean']:.1f} ({entry['reached']}/{episodes})"


def _fmt_mean_std(mean: float | None, std: float | None, digits: int = 1) -> str:
    if mean is None:
        return "—"
    return f"{mean:.{digits}f} ± {std:.{digits}f}"


def format_table(rows: Sequence[dict[str, Any]]) -> str:
    """The results as a plain-text table; with a team (``n_agents > 1``) also the makespan
    (longest single robot path) at the end and to each coverage level, and the overlap."""
    header = ["policy", "reward", "thesis", "term.", "steps", "travelled"]
    levels = list(rows[0]["cells_to_coverage"]) if rows else []
    team = any(row.get("n_agents", 1) > 1 for row in rows)
    header += [f"cells→{float(key):.0%}" for key in levels]
    if team:
        header += ["makespan", *(f"makespan→{float(key):.0%}" for key in levels), "overlap"]
    header.append("action shares")
    lines = [header]
    for row in rows:
        n = row["episodes"]
        thesis = (
            "—"
            if row.get("thesis_mean") is None
            else f"{row['thesis_mean']:.2f} ± {row['thesis_std']:.2f}"
        )
        cells = [_fmt_cells(row["cells_to_coverage"][key], n) for key in levels]
        if team:
            spans = row.get("makespan_to_coverage", {})
            cells += [
                _fmt_mean_std(row.get("mean_makespan"), row.get("std_makespan")),
                *(_fmt_cells(spans[key], n) if key in spans else "—" for key in levels),
                _fmt_mean_std(row.get("mean_overlap"), row.get("std_overlap"), 3),
            ]
        shares = " ".join(f"{s:.2f}" for s in row["action_shares"])
        lines.append(
            [
                row["policy"],
                f"{row['mean_reward']:.2f} ± {row['std_reward']:.2f}",
                thesis,
                f"{row['terminations']}/{n}",
                f"{row['mean_steps']:.1f}",
                f"{row['mean_travelled']:.1f}",
                *cells,
                shares,
            ]
        )
    widths = [max(len(line[i]) for line in lines) for i in range(len(header))]
    out = []
    for k, line in enumerate(lines):
        out.append("  ".join(cell.ljust(w) for cell, w in zip(line, widths, strict=True)).rstrip())
        if k == 0:
            out.append("  ".join("-" * w for w in widths))
    return "\n".join(out)


def _describe(env_kwargs: dict[str, Any], episodes: int, seed: int) -> str:
    from frontier_marl.config import make_config

    cfg = make_config(**env_kwargs)
    if cfg.map_path is not None:
        layout = f"file {Path(cfg.map_path).name}"
    elif cfg.map_mode == "static":
        layout = f"{cfg.map_generator}, map_seed={cfg.map_seed}"
    else:
        layout = f"{cfg.map_generator}, fresh layout per seed"
    return (
        f"{env_kwargs.get('preset')} ({cfg.height}x{cfg.width}, r={cfg.perception_range}), "
        f"{cfg.map_mode} map ({layout}), {cfg.n_agents} robot(s), {episodes} episodes, "
        f"seeds {seed}..{seed + episodes - 1}"
    )


def _json_safe(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_json_safe(v) for v in value]
    return value


def dumps_rows(rows: Sequence[dict[str, Any]]) -> str:
    """JSON text of the rows: summary fields indented, one compact line per episode."""
    parts = []
    for row in _json_safe(list(rows)):
        episodes = row.pop("per_episode", None)
        text = json.dumps(row, indent=1)
        if episodes is not None:
            lines = ",\n  ".join(json.dumps(e, separators=(",", ":")) for e in episodes)
            text = text[: -len("\n}")] + f',\n "per_episode": [\n  {lines}\n ]\n}}'
        parts.append(text)
    return "[\n" + ",\n".join(parts) + "\n]\n"


def run(args: argparse.Namespace) -> int:
    try:
        env_kwargs = env_kwargs_from_args(args)
        policies = parse_policies(args.policies)
    except ValueError as exc:
        return fail("baselines", str(exc))
    rows = run_baselines(env_kwargs, policies, args.episodes, args.seed, not args.no_progress)
    print(_describe(env_kwargs, args.episodes, args.seed))
    print(format_table(rows))
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(dumps_rows(rows))
        print(f"wrote {args.json}")
    if args.plot is not None:
        from frontier_marl.plots import plot_baselines

        args.plot.parent.mkdir(parents=True, exist_ok=True)
        plot_baselines(rows, args.plot, title=_describe(env_kwargs, args.episodes, args.seed))
        print(f"wrote {args.plot}")
    return 0
