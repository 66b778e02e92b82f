"""Which open choice gives dynamic maps the thesis's lower means and wider spread?

    python baselines/dynamic_maps.py                         # every candidate, both grids
    python baselines/dynamic_maps.py --commit until-progress --json dynamic.json

Greedy distance and greedy gain, 30 episodes (seeds 0-29), on the static map and on dynamic
maps of both thesis grids, for each candidate open choice (docs/calibration.md, "Dynamic
maps"); the pattern holds for a candidate when every dynamic row has a lower mean and a wider
spread than the same heuristic's static row.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from frontier_marl.evaluation import evaluate
from frontier_marl.policies import make_policy
from frontier_marl.utils.progress import progress_bar

#: candidate name -> env keywords (on top of each preset; ``obstacle_prob_spread`` is given
#: explicitly everywhere so the table does not depend on the package's current default).
CANDIDATES: dict[str, dict[str, Any]] = {
    "fixed density": {"obstacle_prob_spread": 0.0},
    "start anywhere": {"obstacle_prob_spread": 0.0, "start_cells": "any-free"},
    "threshold on free cells": {"obstacle_prob_spread": 0.0, "threshold_basis": "free"},
    **{f"density spread {s}": {"obstacle_prob_spread": s} for s in (0.05, 0.1, 0.15, 0.2)},
    "density spread 0.2, start anywhere": {"obstacle_prob_spread": 0.2, "start_cells": "any-free"},
}
PRESETS = ("thesis-20x20", "thesis-30x30")
HEURISTICS = ("greedy-distance", "greedy-gain")


def score(env: dict[str, Any], policy: str, commit: str, episodes: int) -> tuple[float, float]:
    result = evaluate(env, make_policy(policy, commit=commit), episodes)
    return round(result.mean_reward, 2), round(result.std_reward, 2)


_Scores = dict[tuple[str, str], tuple[float, float]]


def _candidate_row(
    name: str, kwargs: dict[str, Any], static: _Scores, args: argparse.Namespace, bar: Any
) -> dict[str, Any]:
    """A candidate's dynamic-map scores, and whether every cell is lower and wider than the
    static map's (``pattern``)."""
    row: dict[str, Any] = {"candidate": name, "env": kwargs}
    holds = True
    for preset in PRESETS:
        for policy in HEURISTICS:
            env = {"preset": preset, "map_mode": "dynamic", **kwargs}
            mean, std = score(env, policy, args.commit, args.episodes)
            ref_mean, ref_std = static[preset, policy]
            holds &= mean < ref_mean and std > ref_std
            row[f"{preset} {policy}"] = [mean, std]
            bar.update(1)
    row["pattern"] = holds
    return row


def _print_report(commit: str, static: _Scores, rows: list[dict[str, Any]]) -> None:
    print(
        f"commit={commit}; static: "
        + ", ".join(f"{p} {h} {m:.2f} ± {s:.2f}" for (p, h), (m, s) in static.items())
    )
    for row in rows:
        cells = "  ".join(
            f"{row[f'{p} {h}'][0]:.2f} ± {row[f'{p} {h}'][1]:.2f}"
            for p in PRESETS
            for h in HEURISTICS
        )
        print(f"{row['candidate']:<36} {cells}  pattern: {'yes' if row['pattern'] else 'no'}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--commit", default="none", help="the heuristics' commit rule")
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    total = len(PRESETS) * len(HEURISTICS) * (1 + len(CANDIDATES))
    bar = progress_bar(total, disable=args.no_progress, unit="row")
    static: _Scores = {}
    for preset in PRESETS:
        for policy in HEURISTICS:
            static[preset, policy] = score({"preset": preset}, policy, args.commit, args.episodes)
            bar.update(1)
    rows = [_candidate_row(name, kw, static, args, bar) for name, kw in CANDIDATES.items()]
    bar.close()
    _print_report(args.commit, static, rows)
    if args.json is not None:
        report = {"commit": args.commit, "static": {f"{p} {h}": v for (p, h), v in static.items()}}
        args.json.write_text(json.dumps({**report, "rows": rows}, indent=1) + "\n")
    return 0
