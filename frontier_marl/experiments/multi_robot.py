"""The multi-robot experiment of docs/multi-robot.md (heuristic part).

1, 2 and 4 robots on the ``thesis-30x30`` preset (its static random-obstacle map) and on the
64x64 rooms example map (``rooms-64``, with the same preset's sensor range r = 5), each driven by
independent greedy distance, coordinated assignment and utility discount; compared on team
cells travelled and makespan (longest single robot path) to 90 % and 99 % coverage, and on the
overlap ratio. Every policy sees the same episodes (reset seeds ``seed .. seed + episodes - 1``:
same map, same start cells)::

    python baselines/multi_robot.py                     # 30 episodes per row (about 1-2 min)
    python baselines/multi_robot.py --episodes 3 --out /tmp/mr   # smoke test

So that 99 % coverage is reachable, every episode runs with ``explore_threshold=1.0`` (the
episode ends when the whole reachable free region is known), ``max_steps=5000`` and
``no_progress_limit=500``; everything else is the preset's default, recorded in the JSON.

Writes to ``--out`` (default ``baselines/results/multi_robot``): ``results.json`` (every row, with
per-episode records; the coverage curves only with ``--curves``), ``comparison.json`` (the
paired comparison with greedy distance), ``summary.md`` (the tables of docs/multi-robot.md) and
one PNG per map (:func:`frontier_marl.evaluation.plots.plot_team_comparison`).

The shared-parameter DQN (``frontier-marl train team_30x30``, ``team_rooms64``) is
evaluated with ``--dqn-30x30 RUN_DIR --dqn-rooms64 RUN_DIR`` (either or both): each model on its
own map with 1, 2 and 4 robots (policy ``dqn-shared``, deterministic), beside greedy distance and
coordinated assignment re-run on the same episodes, into ``dqn.json`` and ``dqn.md`` (the other
outputs are not touched)::

    python baselines/multi_robot.py --episodes 50 \\
        --dqn-30x30 runs/team_30x30 --dqn-rooms64 runs/team_rooms64

Other policies plug in through
:func:`run_experiment`'s ``policies`` argument: a dict of name -> zero-argument factory of a
:class:`frontier_marl.evaluation.Policy`, evaluated with the env kwargs of each setting.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from frontier_marl.config import make_config
from frontier_marl.core.example_maps import example_map_path
from frontier_marl.evaluation import evaluate
from frontier_marl.evaluation.plots import plot_team_comparison
from frontier_marl.experiments.baselines import dumps_rows
from frontier_marl.experiments.multi_robot_tables import (
    comparison,
    comparison_table,
    endings_table,
    results_table,
    without_curves,
)
from frontier_marl.policies import ModelPolicy, Policy, make_policy
from frontier_marl.policies.models import check_model_env, load_model

#: The default output folder, relative to the working directory (the repository root);
#: ``baselines/multi_robot.py`` passes its own ``results/multi_robot``.
OUT = Path("baselines") / "results" / "multi_robot"
HEURISTICS = ("greedy-distance", "coordinated-assignment", "utility-discount")

#: Episode-end settings that let every episode reach full coverage.
LONG_EPISODES: dict[str, Any] = {
    "explore_threshold": 1.0,
    "max_steps": 5000,
    "no_progress_limit": 500,
}


def settings() -> dict[str, dict[str, Any]]:
    """Setting name -> env kwargs (without ``n_agents``)."""
    return {
        "thesis-30x30": {"preset": "thesis-30x30", **LONG_EPISODES},
        "rooms-64": {
            "preset": "thesis-30x30",
            "map_path": str(example_map_path("rooms-64")),
            **LONG_EPISODES,
        },
    }


def run_experiment(
    env_settings: Mapping[str, Mapping[str, Any]],
    policies: Mapping[str, Callable[[], Policy]],
    robots: Sequence[int],
    episodes: int,
    seed: int = 0,
    log: Callable[[str], None] = print,
) -> list[dict[str, Any]]:
    """One evaluation row per (setting, team size, policy), with ``setting``,
    ``cpu_seconds`` and ``wall_seconds`` added to :meth:`EvaluationResult.to_dict`."""
    rows = []
    for setting, kwargs in env_settings.items():
        for n in robots:
            for name, factory in policies.items():
                wall, cpu = time.perf_counter(), time.process_time()
                result = evaluate({**kwargs, "n_agents": n}, factory(), episodes, seed)
                row = result.to_dict()
                row["policy"] = name
                row["setting"] = setting
                row["cpu_seconds"] = time.process_time() - cpu
                row["wall_seconds"] = time.perf_counter() - wall
                rows.append(row)
                log(f"{setting:13s} {n} robot(s) {name:24s} {row['cpu_seconds']:6.1f} s CPU")
    return rows


#: Setting name -> command-line flag of its shared-parameter DQN run folder.
DQN_FLAGS = {"thesis-30x30": "dqn_30x30", "rooms-64": "dqn_rooms64"}
DQN_COMPARED = ("greedy-distance", "coordinated-assignment")


def dqn_factory(run: Path, setting_kwargs: Mapping[str, Any], robots: Sequence[int]):
    """A zero-argument factory of the deterministic ``dqn-shared`` policy of run folder ``run``,
    after checking that the model fits the setting's env with every team size."""
    loaded = load_model(run)
    for n in robots:
        check_model_env(loaded, make_config(**{**setting_kwargs, "n_agents": n}))
    return lambda: ModelPolicy(loaded.model, name="dqn-shared", deterministic=True)


def _log_stderr(text: str) -> None:
    print(text, file=sys.stderr)


def _dqn_rows(
    args: argparse.Namespace, robots: Sequence[int]
) -> tuple[list[dict[str, Any]], dict[str, str]]:
    """The rows of each ``--dqn-*`` model and the compared heuristics on its own map, and the
    run folder of each setting."""
    rows: list[dict[str, Any]] = []
    runs = {}
    for setting, kwargs in settings().items():
        run = getattr(args, DQN_FLAGS[setting])
        if run is None:
            continue
        runs[setting] = str(run)
        policies: dict[str, Callable[[], Policy]] = {
            name: (lambda name=name: make_policy(name, args.seed)) for name in DQN_COMPARED
        }
        policies["dqn-shared"] = dqn_factory(run, kwargs, robots)
        rows += run_experiment(
            {setting: kwargs}, policies, robots, args.episodes, args.seed, log=_log_stderr
        )
    return rows, runs


def _dqn_summary(
    args: argparse.Namespace,
    runs: Mapping[str, str],
    rows: list[dict[str, Any]],
    entries: list[dict[str, Any]],
    cpu_wall: tuple[float, float],
) -> str:
    """The text of dqn.md."""
    cpu, wall = cpu_wall
    command = "python baselines/multi_robot.py " + " ".join(sys.argv[1:])
    runs_text = "\n".join(f"- {setting}: `{run}`" for setting, run in runs.items())
    return (
        f"# Shared-parameter DQN in the multi-robot experiment\n\n"
        f"Generated by `{command.strip()}` ({args.episodes} episodes per row, reset seeds "
        f"{args.seed}..{args.seed + args.episodes - 1}, {cpu:.0f} s CPU, {wall:.0f} s wall). "
        "Each model is evaluated on the map it was trained on; greedy distance and "
        "coordinated assignment are re-run on the same episodes.\n\n"
        f"Models:\n\n{runs_text}\n\n"
        f"## Results (mean ± std over episodes; (k/n): episodes that reached the level)\n\n"
        f"{results_table(rows)}\n\n"
        "## How the episodes ended\n\n"
        f"{endings_table(rows)}\n\n"
        "## Against independent greedy distance (teams of 2 and 4)\n\n"
        "Relative change of the mean against greedy distance on the episodes where both "
        "reached the level (negative = better) ± the half-width of a 95 % confidence "
        "interval of the paired difference, and paired episodes (wins/ties/losses).\n\n"
        f"{comparison_table(entries)}\n"
    )


def run_dqn(args: argparse.Namespace, robots: Sequence[int]) -> int:
    """The ``--dqn-*`` mode: each model on its own map, beside two heuristics; dqn.json/.md."""
    start_wall, start_cpu = time.perf_counter(), time.process_time()
    rows, runs = _dqn_rows(args, robots)
    cpu = time.process_time() - start_cpu
    wall = time.perf_counter() - start_wall
    entries = comparison(rows)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "dqn.json").write_text(
        dumps_rows([{**row, "run": runs[row["setting"]]} for row in without_curves(rows)])
    )
    summary = _dqn_summary(args, runs, rows, entries, (cpu, wall))
    (args.out / "dqn.md").write_text(summary)
    print(summary)
    print(f"wrote {args.out}/dqn.json and dqn.md")
    return 0


def _parse_args(argv: list[str] | None, default_out: Path) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description="multi-robot coordination experiment")
    parser.add_argument("--episodes", type=int, default=30, help="per row (default: 30)")
    parser.add_argument("--seed", type=int, default=0, help="first reset seed (default: 0)")
    parser.add_argument("--robots", default="1,2,4", help="team sizes (default: 1,2,4)")
    parser.add_argument("--out", type=Path, default=default_out, help="output folder")
    parser.add_argument(
        "--curves",
        action="store_true",
        help="keep the per-episode coverage curves in results.json (large)",
    )
    for setting, dest in DQN_FLAGS.items():
        parser.add_argument(
            "--" + dest.replace("_", "-"),
            type=Path,
            default=None,
            metavar="RUN_DIR",
            help=f"evaluate this shared-parameter DQN run on {setting} (writes dqn.json/.md only)",
        )
    return parser.parse_args(argv)


def _write_results(
    args: argparse.Namespace,
    env_settings: Mapping[str, Any],
    rows: list[dict[str, Any]],
    entries: list[dict[str, Any]],
) -> None:
    """results.json, comparison.json and one team comparison plot per setting."""
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(
        dumps_rows(rows if args.curves else without_curves(rows))
    )
    (args.out / "comparison.json").write_text(json.dumps(entries, indent=1) + "\n")
    for setting in env_settings:
        chosen = [r for r in rows if r["setting"] == setting]
        plot_team_comparison(
            chosen,
            args.out / f"{setting}.png",
            title=f"{setting}: {args.episodes} episodes per bar (seeds {args.seed}.."
            f"{args.seed + args.episodes - 1}), explore_threshold=1.0",
        )


#: The config fields listed for each setting in summary.md.
_SHOWN = (
    "perception_range",
    "sensor",
    "cells_per_step",
    "n_slots",
    "max_cluster_cells",
    "connectivity",
    "obstacle_prob",
    "map_seed",
    *LONG_EPISODES,
)


def _describe(cfg: Any) -> str:
    """A setting's config in one line: size, map file (if any) and the :data:`_SHOWN` fields."""
    keys = [k for k in _SHOWN if cfg.map_path is None or k not in ("obstacle_prob", "map_seed")]
    parts = [f"{cfg.height}x{cfg.width}"]
    if cfg.map_path is not None:
        parts.append(f"map file {Path(cfg.map_path).name}")
    for key in keys:
        value = getattr(cfg, key) if hasattr(cfg, key) else getattr(cfg.reward, key)
        parts.append(f"{key}={value}")
    return ", ".join(parts)


def _summary(
    argv: list[str] | None,
    args: argparse.Namespace,
    env_settings: Mapping[str, Mapping[str, Any]],
    rows: list[dict[str, Any]],
    entries: list[dict[str, Any]],
    cpu_wall: tuple[float, float],
) -> str:
    """The text of summary.md."""
    cpu, wall = cpu_wall
    command = (
        "python baselines/multi_robot.py"
        + (f" {' '.join(argv)}" if argv else " " + " ".join(sys.argv[1:])).rstrip()
    )
    config_lines = "\n".join(
        f"- {setting}: {_describe(make_config(**kw))}" for setting, kw in env_settings.items()
    )
    return (
        f"# Multi-robot experiment\n\nGenerated by `{command.strip()}` "
        f"({args.episodes} episodes per row, {cpu:.0f} s CPU, {wall:.0f} s wall).\n\n"
        f"Settings (the rest: package defaults, recorded in results.json):\n\n"
        f"{config_lines}\n\n"
        f"## Results (mean ± std over episodes; (k/n): episodes that reached the level)\n\n"
        f"{results_table(rows)}\n\n"
        "## Coordination against independent greedy distance\n\n"
        "Relative change of the mean against greedy distance on the same episodes (negative = "
        "less overlap / shorter paths = better) ± the half-width of a 95 % confidence "
        "interval of the paired difference, and paired episodes (wins/ties/losses).\n\n"
        f"{comparison_table(entries)}\n"
    )


def main(argv: list[str] | None = None, *, default_out: Path = OUT) -> int:
    """The command line of ``baselines/multi_robot.py`` (``default_out``: ``--out``'s default)."""
    args = _parse_args(argv, default_out)
    robots = [int(n) for n in args.robots.split(",")]
    if any(getattr(args, dest) is not None for dest in DQN_FLAGS.values()):
        return run_dqn(args, robots)
    policies = {name: (lambda name=name: make_policy(name, args.seed)) for name in HEURISTICS}
    start_wall, start_cpu = time.perf_counter(), time.process_time()
    env_settings = settings()
    rows = run_experiment(env_settings, policies, robots, args.episodes, args.seed, log=_log_stderr)
    cpu = time.process_time() - start_cpu
    wall = time.perf_counter() - start_wall
    entries = comparison(rows)
    _write_results(args, env_settings, rows, entries)
    summary = _summary(argv, args, env_settings, rows, entries, (cpu, wall))
    (args.out / "summary.md").write_text(summary)
    print(summary)
    print(
        f"wrote {args.out}/results.json, comparison.json, summary.md and "
        f"{', '.join(f'{s}.png' for s in env_settings)}"
    )
    return 0
