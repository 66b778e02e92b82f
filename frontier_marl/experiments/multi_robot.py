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

    python baselines/multi_robot.py --episodes 50 \
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

import numpy as np

from frontier_marl.config import make_config
from frontier_marl.core.example_maps import example_map_path
from frontier_marl.evaluation import evaluate
from frontier_marl.evaluation.plots import plot_team_comparison, team_value
from frontier_marl.experiments.baselines import dumps_rows
from frontier_marl.policies import ModelPolicy, Policy, make_policy
from frontier_marl.policies.models import check_model_env, load_model

#: The default output folder, relative to the working directory (the repository root);
#: ``baselines/multi_robot.py`` passes its own ``results/multi_robot``.
OUT = Path("baselines") / "results" / "multi_robot"
HEURISTICS = ("greedy-distance", "coordinated-assignment", "utility-discount")
BASELINE = "greedy-distance"

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


def endings_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """Markdown table: final coverage and end reasons of every row."""
    lines = [
        "| map | robots | policy | final coverage | end reasons |",
        "|---|---|---|---|---|",
    ]
    for row in rows:
        reasons = ", ".join(f"{k} {v}" for k, v in sorted(row["end_reasons"].items()))
        lines.append(
            f"| {row['setting']} | {row['n_agents']} | {row['policy']} "
            f"| {row['mean_final_coverage']:.3f} | {reasons} |"
        )
    return "\n".join(lines)


def run_dqn(args: argparse.Namespace, robots: Sequence[int]) -> int:
    """The ``--dqn-*`` mode: each model on its own map, beside two heuristics; dqn.json/.md."""
    start_wall, start_cpu = time.perf_counter(), time.process_time()
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
            {setting: kwargs},
            policies,
            robots,
            args.episodes,
            args.seed,
            log=lambda text: print(text, file=sys.stderr),
        )
    cpu = time.process_time() - start_cpu
    wall = time.perf_counter() - start_wall
    entries = comparison(rows)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "dqn.json").write_text(
        dumps_rows([{**row, "run": runs[row["setting"]]} for row in without_curves(rows)])
    )
    command = "python baselines/multi_robot.py " + " ".join(sys.argv[1:])
    runs_text = "\n".join(f"- {setting}: `{run}`" for setting, run in runs.items())
    summary = (
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
    (args.out / "dqn.md").write_text(summary)
    print(summary)
    print(f"wrote {args.out}/dqn.json and dqn.md")
    return 0


def _cell(row: Mapping[str, Any], metric: str, digits: int = 1) -> str:
    mean, std = team_value(row, metric)
    if mean is None:
        return "—"
    kind, _, level = metric.partition("@")
    reached = ""
    if level:
        table = (
            "cells_to_coverage"
            if kind == "cells" or row["n_agents"] == 1
            else ("makespan_to_coverage")
        )
        entry = row[table][level]
        if entry["reached"] < row["episodes"]:
            reached = f" ({entry['reached']}/{row['episodes']})"
    return f"{mean:.{digits}f} ± {std:.{digits}f}{reached}"


def results_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """Markdown table: every row's team metrics (mean ± std over episodes)."""
    lines = [
        "| map | robots | policy | team cells → 90 % | team cells → 99 % | makespan → 90 % "
        "| makespan → 99 % | overlap | decisions |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        lines.append(
            f"| {row['setting']} | {row['n_agents']} | {row['policy']} "
            f"| {_cell(row, 'cells@0.90')} | {_cell(row, 'cells@0.99')} "
            f"| {_cell(row, 'makespan@0.90')} | {_cell(row, 'makespan@0.99')} "
            f"| {_cell(row, 'overlap', 3)} | {row['mean_steps']:.1f} |"
        )
    return "\n".join(lines)


def _per_episode(row: Mapping[str, Any], metric: str) -> np.ndarray:
    """Per-episode values of a team metric (NaN where a level was not reached)."""
    episodes = row["per_episode"]
    single = row["n_agents"] == 1
    if metric == "overlap":
        values = [0.0 if single else e["overlap"] for e in episodes]
    else:
        kind, _, level = metric.partition("@")
        table = "cells_to_coverage" if kind == "cells" or single else "makespan_to_coverage"
        values = [e[table][level] for e in episodes]
    return np.array([np.nan if v is None else float(v) for v in values])


COMPARED = {
    "overlap": "overlap",
    "makespan@0.90": "makespan → 90 %",
    "makespan@0.99": "makespan → 99 %",
    "cells@0.99": "team cells → 99 %",
}


def comparison(rows: Sequence[Mapping[str, Any]], baseline: str = BASELINE) -> list[dict]:
    """Each coordinated policy against ``baseline`` on the same episodes, per setting and team
    size > 1: relative change of the mean (negative = better) with the half-width of its 95 %
    confidence interval (normal approximation of the paired per-episode differences), and
    paired wins/ties/losses."""
    out = []
    for row in rows:
        if row["policy"] == baseline or row["n_agents"] == 1:
            continue
        base = next(
            r
            for r in rows
            if r["policy"] == baseline
            and r["setting"] == row["setting"]
            and r["n_agents"] == row["n_agents"]
        )
        entry: dict[str, Any] = {
            "setting": row["setting"],
            "n_agents": row["n_agents"],
            "policy": row["policy"],
        }
        for metric in COMPARED:
            ours, theirs = _per_episode(row, metric), _per_episode(base, metric)
            both = ~np.isnan(ours) & ~np.isnan(theirs)
            if not both.any():  # e.g. a policy that never reached the level
                entry[metric] = {"mean": None, "baseline_mean": None, "episodes": 0}
                entry[metric].update(change=None, ci95=None, wins=0, ties=0, losses=0)
                continue
            mean_ours, mean_theirs = float(ours[both].mean()), float(theirs[both].mean())
            diff = ours[both] - theirs[both]
            half = 1.96 * float(diff.std(ddof=1)) / np.sqrt(len(diff)) if len(diff) > 1 else None
            entry[metric] = {
                "mean": mean_ours,
                "baseline_mean": mean_theirs,
                "episodes": int(both.sum()),
                "change": (mean_ours - mean_theirs) / mean_theirs if mean_theirs else None,
                "ci95": half / mean_theirs if half is not None and mean_theirs else None,
                "wins": int(np.sum(ours[both] < theirs[both])),
                "ties": int(np.sum(ours[both] == theirs[both])),
                "losses": int(np.sum(ours[both] > theirs[both])),
            }
        out.append(entry)
    return out


def comparison_table(entries: Sequence[Mapping[str, Any]]) -> str:
    header = "| map | robots | policy | " + " | ".join(COMPARED.values()) + " |"
    lines = [header, "|---|---|---|" + "---|" * len(COMPARED)]
    for e in entries:
        cells = []
        for metric in COMPARED:
            m = e[metric]
            if m["episodes"] == 0:
                cells.append("— (no paired episode)")
                continue
            change = "—" if m["change"] is None else f"{m['change']:+.1%}"
            if m["ci95"] is not None:
                change += f" ± {m['ci95']:.1%}"
            cells.append(f"{change} ({m['wins']}/{m['ties']}/{m['losses']})")
        lines.append(
            f"| {e['setting']} | {e['n_agents']} | {e['policy']} | " + " | ".join(cells) + " |"
        )
    return "\n".join(lines)


def without_curves(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The rows with the per-episode curves left out (the plots keep them)."""
    return [
        {
            **row,
            "per_episode": [
                {k: v for k, v in e.items() if k not in ("curve", "makespan_curve")}
                for e in row["per_episode"]
            ],
        }
        for row in rows
    ]


def main(argv: list[str] | None = None, *, default_out: Path = OUT) -> int:
    """The command line of ``baselines/multi_robot.py`` (``default_out``: ``--out``'s default)."""
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
    args = parser.parse_args(argv)
    robots = [int(n) for n in args.robots.split(",")]
    if any(getattr(args, dest) is not None for dest in DQN_FLAGS.values()):
        return run_dqn(args, robots)
    policies = {name: (lambda name=name: make_policy(name, args.seed)) for name in HEURISTICS}
    start_wall, start_cpu = time.perf_counter(), time.process_time()
    env_settings = settings()
    rows = run_experiment(
        env_settings,
        policies,
        robots,
        args.episodes,
        args.seed,
        log=lambda text: print(text, file=sys.stderr),
    )
    cpu = time.process_time() - start_cpu
    wall = time.perf_counter() - start_wall
    entries = comparison(rows)
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
    command = (
        "python baselines/multi_robot.py"
        + (f" {' '.join(argv)}" if argv else " " + " ".join(sys.argv[1:])).rstrip()
    )
    shown = (
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

    def describe(cfg: Any) -> str:
        keys = [k for k in shown if cfg.map_path is None or k not in ("obstacle_prob", "map_seed")]
        parts = [f"{cfg.height}x{cfg.width}"]
        if cfg.map_path is not None:
            parts.append(f"map file {Path(cfg.map_path).name}")
        for key in keys:
            value = getattr(cfg, key) if hasattr(cfg, key) else getattr(cfg.reward, key)
            parts.append(f"{key}={value}")
        return ", ".join(parts)

    config_lines = "\n".join(
        f"- {setting}: {describe(make_config(**kw))}" for setting, kw in env_settings.items()
    )
    summary = (
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
    (args.out / "summary.md").write_text(summary)
    print(summary)
    print(
        f"wrote {args.out}/results.json, comparison.json, summary.md and "
        f"{', '.join(f'{s}.png' for s in env_settings)}"
    )
    return 0
