"""Which protocol choice puts every cell of the thesis's Table 6.5 within one thesis std?

    python baselines/table65.py                      # every candidate (about 5 minutes)
    python baselines/table65.py --only adopted --json table65.json

Greedy distance (GD) and greedy gain (GG), 30 episodes (seeds 0-29), one robot, Reward 2, on
the four settings of the thesis's Table 6.5 (20x20 r = 3 and 30x30 r = 5, static and dynamic
maps), for each candidate choice (docs/calibration.md, "Table 6.5"). For each candidate it
reports the eight cells; whether the thesis's four known cells (``frontier_marl.config.thesis.
HEURISTIC_BASELINES``) are within one thesis std; how far the four cells the thesis's figures
are not known for moved from the current default; the two calibration rows (20x20 static),
and exactly unchanged or not; the thesis's two qualitative claims: (a) greedy distance
ahead of greedy gain in all four settings, (b) on both grids, for both heuristics, dynamic
maps give a lower mean and a wider spread than the static map; and which episodes it
changed from the default (and whether the default had reached the threshold in them).
``--episodes 300`` gives the stuck episodes (300 minus the terminations) of each rule.

Some candidates are variants of greedy distance that the package does not offer (another
distance, a tolerance for ties, a commitment triggered by Reward 2's oscillation test): they
are defined here, as the package's heuristics with one thing changed. ``adopted`` is what
``frontier-marl baselines`` runs now (``THESIS_PROTOCOL``: greedy distance with ``commit``
``on-cycle``). Every figure is plain ``frontier_marl.evaluation.evaluate``.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from frontier_marl.config.thesis import HEURISTIC_BASELINES
from frontier_marl.evaluation import evaluate
from frontier_marl.policies import Policy, make_policy
from frontier_marl.policies.base import Info, first_by, previous_target_slot, slot_table
from frontier_marl.policies.heuristics import GreedyDistance

SETTINGS = (
    ("thesis-20x20", "static"),
    ("thesis-20x20", "dynamic"),
    ("thesis-30x30", "static"),
    ("thesis-30x30", "dynamic"),
)
HEURISTICS = ("greedy-distance", "greedy-gain")
CALIBRATION = ("thesis-20x20", "static")


class DistanceVariant(GreedyDistance):
    """Greedy distance with another distance: Euclidean to the cluster's ``target`` cell, or
    ``manhattan`` (4-connected) to its centroid; ties: lowest slot."""

    def __init__(self, distance: str) -> None:
        super().__init__()
        self.distance = distance

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if not table.live:
            return 0
        robot = np.asarray(info["position"], dtype=float)
        if self.distance == "target":
            d = np.hypot(*(table.target[: table.live] - robot).T)
        else:
            d = np.abs(table.centroid[: table.live] - robot).sum(axis=1)
        return int(np.argmin(d))


class TieTolerance(GreedyDistance):
    """Greedy distance that keeps the previous target while its centroid is within ``tolerance``
    cells of the nearest one (hysteresis)."""

    def __init__(self, tolerance: float) -> None:
        super().__init__()
        self.tolerance = tolerance

    def choose(self, info: Info) -> int:
        nearest = super().choose(info)
        previous = previous_target_slot(info)
        table = slot_table(info)
        if previous is not None and (
            table.distance[previous] <= table.distance[nearest] + self.tolerance
        ):
            return previous
        return nearest


class OscillationCommit(Policy):
    """``base``, but after a step that Reward 2's oscillation test flagged (the robot turned
    back to a target of its last ``oscillation_window`` steps) and that revealed nothing, it
    keeps its previous target (while offered): for that one step, or (``sticky``) until a
    new cell is seen."""

    def __init__(self, base: Policy, sticky: bool) -> None:
        self.base, self.sticky = base, sticky
        self.name = base.name
        self._armed = False

    def reset(self, seed: int | None = None) -> None:
        self.base.reset(seed)
        self._armed = False

    def act(self, obs: Any, info: Info) -> int:
        if info["new_cells"] or info["step"] == 0:
            self._armed = False
        flagged = bool(info["oscillation"]) and not info["new_cells"]
        self._armed = flagged or (self.sticky and self._armed)
        kept = previous_target_slot(info) if self._armed else None
        return self.base.act(obs, info) if kept is None else kept


class NearestPathByCentroid(GreedyDistance):
    """Greedy distance by known-free path length to the cluster's target (ties: nearest
    centroid), i.e. ``nearest-path``."""

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if not table.live:
            return 0
        return first_by(table.path_length[: table.live], table.distance[: table.live])


Factory = Callable[[], Policy]


def plain(name: str, **options: Any) -> Factory:
    return lambda: make_policy(name, **options)


@dataclass
class Candidate:
    """One protocol choice: how each heuristic is built and the env keywords per preset."""

    note: str
    gd: Factory = field(default_factory=lambda: plain("greedy-distance"))
    gg: Factory = field(default_factory=lambda: plain("greedy-gain"))
    gd_key: str = "plain"  # identical keys share their evaluations
    gg_key: str = "plain"
    env: dict[str, dict[str, Any]] = field(default_factory=dict)  # preset -> keywords
    dynamic_env: dict[str, Any] = field(default_factory=dict)  # dynamic maps only


CANDIDATES: dict[str, Candidate] = {
    "default": Candidate("re-decide every step (the defaults until now)"),
    "gd-target-distance": Candidate(
        "GD: Euclidean distance to the cluster's target cell",
        gd=lambda: DistanceVariant("target"),
        gd_key="target",
    ),
    "gd-manhattan": Candidate(
        "GD: Manhattan distance to the centroid",
        gd=lambda: DistanceVariant("manhattan"),
        gd_key="manhattan",
    ),
    "gd-path": Candidate(
        "GD: known-free path length to the target (nearest-path)",
        gd=NearestPathByCentroid,
        gd_key="path",
    ),
    "gd-ties-0.1": Candidate(
        "GD: keep the current target within 0.1 cell of the nearest",
        gd=lambda: TieTolerance(0.1),
        gd_key="ties-0.1",
    ),
    "gd-ties-0.5": Candidate(
        "GD: keep the current target within 0.5 cell of the nearest",
        gd=lambda: TieTolerance(0.5),
        gd_key="ties-0.5",
    ),
    "until-progress": Candidate(
        "both: commit until-progress",
        gd=plain("greedy-distance", commit="until-progress"),
        gg=plain("greedy-gain", commit="until-progress"),
        gd_key="until-progress",
        gg_key="until-progress",
    ),
    "gd-until-progress": Candidate(
        "GD only: commit until-progress",
        gd=plain("greedy-distance", commit="until-progress"),
        gd_key="until-progress",
    ),
    "oscillation": Candidate(
        "both: keep the target for one step after a flagged turn-back without progress",
        gd=lambda: OscillationCommit(make_policy("greedy-distance"), sticky=False),
        gg=lambda: OscillationCommit(make_policy("greedy-gain"), sticky=False),
        gd_key="oscillation",
        gg_key="oscillation",
    ),
    "gd-oscillation": Candidate(
        "GD only: keep the target for one step after a flagged turn-back without progress",
        gd=lambda: OscillationCommit(make_policy("greedy-distance"), sticky=False),
        gd_key="oscillation",
    ),
    "gd-oscillation-sticky": Candidate(
        "GD only: from a flagged turn-back without progress, keep the target until progress",
        gd=lambda: OscillationCommit(make_policy("greedy-distance"), sticky=True),
        gd_key="oscillation-sticky",
    ),
    "on-cycle": Candidate(
        "both: commit on-cycle",
        gd=plain("greedy-distance", commit="on-cycle"),
        gg=plain("greedy-gain", commit="on-cycle"),
        gd_key="on-cycle",
        gg_key="on-cycle",
    ),
    "adopted": Candidate(
        "GD only: commit on-cycle (the thesis protocol now)",
        gd=plain("greedy-distance", commit="on-cycle"),
        gd_key="on-cycle",
    ),
    "no-progress-30": Candidate(
        "no_progress_limit 30 on 30x30 (proportional to the side)",
        env={"thesis-30x30": {"no_progress_limit": 30}},
    ),
    "density-0.1": Candidate(
        "dynamic maps: density from U(0, 0.2) (obstacle_prob_spread 0.1)",
        dynamic_env={"obstacle_prob_spread": 0.1},
    ),
    "any-free": Candidate(
        "start cell drawn from all free cells (start_cells any-free)",
        env={p: {"start_cells": "any-free"} for p in ("thesis-20x20", "thesis-30x30")},
    ),
}


def env_kwargs(candidate: Candidate, preset: str, mode: str) -> dict[str, Any]:
    kwargs: dict[str, Any] = {"preset": preset, "map_mode": mode, **candidate.env.get(preset, {})}
    if mode == "dynamic":
        kwargs.update(candidate.dynamic_env)
    return kwargs


@dataclass
class Cell:
    """One heuristic on one setting: mean and std of the total reward (rounded to 0.01),
    terminations, and each episode's (reward, end reason, steps, cells travelled)."""

    mean: float
    std: float
    terminations: int
    episodes: list[tuple[float, str, int, int]]


def measure(candidate: Candidate, episodes: int, cache: dict[str, Cell]) -> dict[str, Cell]:
    """Each of the eight cells, by ``"preset mode policy"``."""
    cells = {}
    for preset, mode in SETTINGS:
        kwargs = env_kwargs(candidate, preset, mode)
        for policy, factory, key in (
            ("greedy-distance", candidate.gd, candidate.gd_key),
            ("greedy-gain", candidate.gg, candidate.gg_key),
        ):
            memo = json.dumps([kwargs, policy, key], sort_keys=True)
            if memo not in cache:
                result = evaluate(kwargs, factory(), episodes)
                cache[memo] = Cell(
                    round(result.mean_reward, 2),
                    round(result.std_reward, 2),
                    result.terminations,
                    [(e.reward, e.end_reason, e.steps, e.travelled) for e in result.episodes],
                )
            cells[f"{preset} {mode} {policy}"] = cache[memo]
    return cells


def checks(cells: dict[str, Cell], default: dict[str, Cell]) -> dict[str, Any]:
    """The criteria of the task for one candidate's cells, and which episodes it changed."""
    known = {}
    for (preset, mode, policy), (mean, std) in HEURISTIC_BASELINES.items():
        ours = cells[f"{preset} {mode} {policy}"].mean
        known[f"{preset} {mode} {policy}"] = abs(ours - mean) <= std
    moved = {
        key: round(cells[key].mean - default[key].mean, 2)
        for key in cells
        if tuple(key.split()) not in HEURISTIC_BASELINES
    }
    ahead = all(
        cells[f"{p} {m} greedy-distance"].mean > cells[f"{p} {m} greedy-gain"].mean
        for p, m in SETTINGS
    )
    dynamic = all(
        cells[f"{p} dynamic {h}"].mean < cells[f"{p} static {h}"].mean
        and cells[f"{p} dynamic {h}"].std > cells[f"{p} static {h}"].std
        for p in ("thesis-20x20", "thesis-30x30")
        for h in HEURISTICS
    )
    calibration = {
        h: cells[f"{CALIBRATION[0]} {CALIBRATION[1]} {h}"].episodes
        == default[f"{CALIBRATION[0]} {CALIBRATION[1]} {h}"].episodes
        for h in HEURISTICS
    }
    return {
        "known_within": known,
        "unknown_moved": moved,
        "gd_ahead_everywhere": ahead,
        "dynamic_lower_and_wider": dynamic,
        "calibration_rows_identical": calibration,
        "all": all(known.values()) and ahead and dynamic and all(calibration.values()),
        "changed_episodes": _changed_episodes(cells, default),
    }


def _changed_episodes(cells: dict[str, Cell], default: dict[str, Cell]) -> dict[str, list[int]]:
    """Cell -> [episodes changed, of which the default ended at the threshold]."""
    changed = {}
    for key, cell in cells.items():
        pairs = list(zip(cell.episodes, default[key].episodes, strict=True))
        differ = [old for new, old in pairs if new != old]
        if differ:
            changed[key] = [len(differ), sum(old[1] == "threshold" for old in differ)]
    return changed


def _print_candidate(
    name: str, candidate: Candidate, cells: dict[str, Cell], verdict: dict[str, Any]
) -> None:
    """A candidate's cells, setting by setting, and its verdict."""
    print(f"\n{name}: {candidate.note}")
    for preset, mode in SETTINGS:
        row = "   ".join(
            f"{h.split('-')[1]} {c.mean:6.2f} ± {c.std:.2f} ({c.terminations:3d} term.)"
            for h in HEURISTICS
            for c in [cells[f"{preset} {mode} {h}"]]
        )
        print(f"  {preset} {mode:7s}  {row}")
    within = sum(verdict["known_within"].values())
    moved = ", ".join(
        f"{k.replace('thesis-', '')} {v:+.2f}" for k, v in verdict["unknown_moved"].items()
    )
    changed = ", ".join(
        f"{k.replace('thesis-', '')} {n} ({finished} had reached the threshold)"
        for k, (n, finished) in verdict["changed_episodes"].items()
    )
    print(
        f"  known cells within one thesis std: {within}/{len(verdict['known_within'])}; "
        f"(a) GD ahead everywhere: {verdict['gd_ahead_everywhere']}; "
        f"(b) dynamic lower and wider: {verdict['dynamic_lower_and_wider']}; "
        f"calibration rows identical: {verdict['calibration_rows_identical']}"
    )
    print(f"  unknown cells moved: {moved}")
    print(f"  episodes changed from the default: {changed or 'none'}")
    print(f"  every criterion: {verdict['all']}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--only", default=None, help="comma-separated candidate names")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    names = list(CANDIDATES) if args.only is None else args.only.split(",")
    unknown = sorted(set(names) - set(CANDIDATES))
    if unknown:
        parser.error(f"unknown candidate(s) {unknown}; known: {', '.join(CANDIDATES)}")
    cache: dict[str, Cell] = {}
    default = measure(CANDIDATES["default"], args.episodes, cache)
    report = []
    for name in names:
        candidate = CANDIDATES[name]
        cells = measure(candidate, args.episodes, cache)
        verdict = checks(cells, default)
        report.append(
            {
                "candidate": name,
                "note": candidate.note,
                "episodes": args.episodes,
                "cells": {k: [c.mean, c.std, c.terminations] for k, c in cells.items()},
                **verdict,
            }
        )
        _print_candidate(name, candidate, cells, verdict)
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
