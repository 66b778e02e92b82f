"""Where do the heuristics get stuck? Every episode a heuristic ends without reaching the
threshold, with what the robot did in its last decisions (docs/calibration.md, "Livelocks").

    python baselines/livelocks.py --preset thesis-30x30 --map-mode static --episodes 30
    python baselines/livelocks.py --episodes 300 --policies greedy-distance,greedy-gain \\
        --set commit=until-progress --json livelocks.json

For each stuck episode (ended by the no-progress or the step limit) it reports the coverage
reached and, over the last ``no_progress_limit`` decisions: the distinct target cells chosen
and robot cells visited, whether the choice alternated between targets (a cycle), how often
the previous target was still offered in a slot when the robot changed its mind, and, for the
nearest-cluster rule, whether moving toward a target made another centroid nearer (the Euclidean
distance to a centroid is not the path length to its target).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path
from typing import Any

from frontier_marl.core.example_maps import resolve_map
from frontier_marl.envs import FrontierParallelEnv
from frontier_marl.policies import make_policy
from frontier_marl.policies.base import slot_table, target_cell
from frontier_marl.sim.rewards import reason_name
from frontier_marl.utils.progress import progress_bar
from frontier_marl.utils.set_options import parse_set_options

STUCK = ("no_progress", "step_limit")


def _decision(info: dict[str, Any], action: int) -> dict[str, Any]:
    """What one decision did: the robot's cell, the chosen and the previous target, whether
    the previous target was still offered, and the chosen slot's distance and path ranks."""
    table = slot_table(info)
    target = tuple(table.target[action].tolist()) if action < table.live else None
    offered = {tuple(t) for t in table.target[: table.live].tolist()}
    previous = target_cell(info["target"])
    return {
        "position": tuple(info["position"].tolist()),
        "target": target,
        "previous": previous,
        "previous_offered": previous in offered,
        "distance_rank": int((table.distance[: table.live] < table.distance[action]).sum())
        if target
        else None,
        "path_rank": int((table.path_length[: table.live] < table.path_length[action]).sum())
        if target
        else None,
    }


def _play(
    env_kwargs: dict[str, Any], policy_name: str, options: dict[str, Any], seed: int
) -> tuple[list[dict[str, Any]], dict[str, Any], int]:
    """Play episode ``seed``: every decision, the last info, and the no-progress limit."""
    env = FrontierParallelEnv(**env_kwargs)
    policy = make_policy(policy_name, seed, **options)
    policy.attach(env)
    policy.reset(seed)
    observations, infos = env.reset(seed=seed)
    history: list[dict[str, Any]] = []
    while env.agents:
        action = policy.act_team(observations, infos)["robot_0"]
        history.append(_decision(infos["robot_0"], action))
        observations, _, _, _, infos = env.step({"robot_0": action})
    return history, next(iter(infos.values())), env.config.reward.no_progress_limit


def stuck_episode(
    env_kwargs: dict[str, Any], policy_name: str, options: dict[str, Any], seed: int
) -> dict[str, Any] | None:
    """The record of episode ``seed`` if it ends stuck, else ``None``."""
    history, last, limit = _play(env_kwargs, policy_name, options, seed)
    reason = reason_name(last["end_reason"])
    if not any(cause in reason for cause in STUCK):
        return None
    window = history[-limit:]
    targets = [h["target"] for h in window]
    switches = [h for h in window if h["previous"] is not None and h["target"] != h["previous"]]
    alternating = len(set(targets)) >= 2 and all(
        targets[i] == targets[i - 2] for i in range(2, len(targets))
    )
    return {
        "seed": seed,
        "end_reason": reason,
        "coverage": round(float(last["coverage"]), 4),
        "steps": len(history),
        "distinct_targets": len(set(targets)),
        "distinct_cells": len({h["position"] for h in window}),
        "alternating": alternating,
        "switches": len(switches),
        "switches_while_previous_offered": sum(h["previous_offered"] for h in switches),
        "switches_to_a_farther_path": sum(
            1 for h in switches if h["path_rank"] is not None and h["path_rank"] > 0
        ),
    }


def _parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="thesis-20x20")
    parser.add_argument("--map-mode", default="static", choices=["static", "dynamic"])
    parser.add_argument("--map", default=None, help="a map file or example map name")
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--policies", default="greedy-distance,greedy-gain,cost-utility")
    parser.add_argument(
        "--option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a heuristic option, e.g. --option commit=until-progress (repeatable)",
    )
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    return parser.parse_args(argv)


def _print_policy(name: str, stuck: list[dict[str, Any]], episodes: int) -> None:
    kinds = Counter("cycle" if r["alternating"] else "other" for r in stuck)
    print(f"{name}: {len(stuck)}/{episodes} stuck {dict(kinds)}")
    for r in stuck:
        print(
            f"  seed {r['seed']}: {r['end_reason']} at {100 * r['coverage']:.0f} %, "
            f"{r['distinct_targets']} targets / {r['distinct_cells']} cells in the last "
            f"window, {r['switches']} switches ({r['switches_while_previous_offered']} "
            f"with the previous target still offered, {r['switches_to_a_farther_path']} "
            "to a target farther by path)"
        )


def main(argv: list[str] | None = None) -> int:
    args = _parse_args(argv)
    env_kwargs: dict[str, Any] = {"preset": args.preset, "map_mode": args.map_mode}
    if args.map is not None:
        env_kwargs = {"preset": args.preset, "map_path": resolve_map(args.map)}
    env_kwargs.update(parse_set_options(args.overrides))
    options = parse_set_options(args.option)
    policies = [p.strip() for p in args.policies.split(",") if p.strip()]
    report: dict[str, Any] = {"env": env_kwargs, "options": options, "episodes": args.episodes}
    bar = progress_bar(len(policies) * args.episodes, disable=args.no_progress, unit="ep")
    for name in policies:
        bar.set_description(name)
        stuck = []
        for seed in range(args.seed, args.seed + args.episodes):
            record = stuck_episode(env_kwargs, name, options, seed)
            if record is not None:
                stuck.append(record)
            bar.update(1)
        report[name] = stuck
    bar.close()
    for name in policies:
        _print_policy(name, report[name], args.episodes)
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=1) + "\n")
        print(f"wrote {args.json}", file=sys.stderr)
    return 0
