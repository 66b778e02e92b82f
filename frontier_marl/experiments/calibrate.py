"""Calibrate the parameters the thesis left open against its two 20x20 static baselines.

The thesis reports, over 30 episodes on a static 20x20 map with r = 3 (docs/calibration.md):
greedy distance 16.48 +- 1.78 and greedy information gain 15.01 +- 1.12 (total episode reward).
This script searches the open parameters of the ``thesis-20x20`` setting and scores each
setting by how well the two heuristics reproduce those figures::

    python baselines/calibrate.py                      # the full search (about 6 min, one core)
    python baselines/calibrate.py --quick              # smoke test (seconds)
    python baselines/calibrate.py --protocol --out calibration-protocol.json
                                                       # greedy distance as in Table 6.5

Every setting is evaluated with :func:`frontier_marl.evaluation.evaluate` (episode ``i`` uses
reset seed ``seed + i``) on the static map drawn from ``--map-seed`` (fixed, never searched),
with the reward named by ``--reward`` (the preset's default, Reward 2). Every searched
parameter is passed explicitly, so the search does not depend on the package's current defaults.

Score (lower is better)::

    score = |GD - 16.48| + |GG - 15.01| + 0.25 * (|sd_GD - 1.78| + |sd_GG - 1.12|)
            + 10 if GD <= GG  (the thesis's ordering is required)
            + 1 if n_slots != 4  (the thesis's 20x20 policy had four actions)

A setting *fits* when both means are within ``--tolerance`` (0.5) of the thesis and GD > GG.

Stages:

1. **coarse grid** over the parameters expected to matter most: ``obstacle_prob``, ``sensor``,
   ``cells_per_step`` and ``explore_threshold`` (the others at their reference values,
   :data:`REFERENCE`; ``threshold_basis`` moved the means by about 0.05 in a first full grid,
   so it is left to stage 2).
2. **refinement** of the ``--top`` best stage-1 settings with distinct outcomes by coordinate
   descent over every open parameter (finer ``obstacle_prob`` and threshold steps,
   ``threshold_basis``, ``max_cluster_cells``, ``connectivity``, ``max_steps``,
   ``oscillation_window``, ``n_slots``): one parameter at a time, keeping a change only if it
   lowers the score by at least ``--min-gain`` (so a parameter leaves its plainer value only
   for a clear improvement), until a pass changes nothing or ``--passes`` passes are done.
3. **validation**: a 30-episode mean carries a standard error of about 0.2-0.5, so many
   settings fit by the luck of the sample. The ``--validate`` best fitting settings with
   distinct outcomes, among the coarse settings and the stage-2 end points (not the probes
   that coordinate descent rejected), are run again on held-out episode seeds
   (``--check-seed``, same static map); the winner is the fitting setting with the lowest sum
   of its score on the calibration seeds and its score on the held-out seeds.
4. **checks of the winner** (reported, never used to choose): other static map seeds, the
   dynamic map, and Reward 1.

The heuristics are the plain rules (re-decide every step), as the calibration was run;
``--protocol`` gives them the options of the thesis protocol of ``frontier-marl baselines``
(:data:`frontier_marl.experiments.baselines.THESIS_PROTOCOL`: greedy distance keeps its target
once it is caught in a cycle), recorded as ``policy_options``.

Writes ``--out`` (JSON: every evaluated setting with its figures and CPU time, the stages,
the winner and its checks) and prints a summary.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frontier_marl.experiments.baselines import THESIS_PROTOCOL
from frontier_marl.experiments.calibration_search import (
    FIXED,
    ORDER_PENALTY,
    POLICIES,
    SLOTS_PENALTY,
    STD_WEIGHT,
    THESIS,
    Evaluator,
    coordinate_descent,
    distinct,
    fits,
    grid_points,
    setting_key,
    setting_text,
    summary_line,
)

#: The starting point: the plainest reading of the thesis for each open parameter.
REFERENCE: dict[str, Any] = {
    "obstacle_prob": 0.2,
    "sensor": "square",
    "cells_per_step": 1,
    "explore_threshold": 0.95,
    "threshold_basis": "reachable",
    "max_steps": 400,
    "n_slots": 4,
    "max_cluster_cells": 8,
    "connectivity": 8,
    "oscillation_window": 4,
}

#: Stage 1: coarse grid over the most influential parameters.
COARSE: dict[str, list[Any]] = {
    "obstacle_prob": [0.1, 0.15, 0.2, 0.25, 0.3],
    "sensor": ["square", "raycast"],
    "cells_per_step": [1, 2, 3, "full"],
    "explore_threshold": [0.85, 0.9, 0.95, 0.99],
}

#: Stage 2: values tried for each parameter during coordinate descent. Numeric entries given
#: as ("around", step, half_width) are a fine grid centred on the current value.
REFINE: dict[str, Any] = {
    "obstacle_prob": ("around", 0.01, 0.05),
    "explore_threshold": ("around", 0.01, 0.04),
    "cells_per_step": [1, 2, 3, "full"],
    "sensor": ["square", "raycast"],
    "threshold_basis": ["all", "free", "reachable"],
    "max_cluster_cells": [4, 6, 8, 10, 12, 16],
    "connectivity": [4, 8],
    "max_steps": [100, 150, 200, 300, 400],
    "oscillation_window": [2, 3, 4, 6, 8],
    "n_slots": [3, 4, 5, 6],
}

QUICK_COARSE: dict[str, list[Any]] = {
    "obstacle_prob": [0.15, 0.2],
    "sensor": ["square"],
    "cells_per_step": [1, "full"],
    "explore_threshold": [0.95],
}
QUICK_REFINE: dict[str, Any] = {
    "obstacle_prob": ("around", 0.01, 0.01),
    "max_cluster_cells": [6, 8],
}

#: A results row: one evaluated setting with its figures (see ``Evaluator.run``).
Row = dict[str, Any]

#: The default folder of ``--out``, relative to the working directory (the repository root).
RESULTS = Path("baselines") / "results"


@dataclass
class _Search:
    """What stages 1-3 of the search found, passed on to the checks and the results file."""

    stage1: list[Row]
    stage1_fits: int
    stage1_cpu: float
    refined: list[Row]
    stage2_cpu: float
    fitting: list[Row]
    validation: list[Row]
    choice: Row
    search_cpu: float
    n_settings: int

    @property
    def winner(self) -> Row:
        """The chosen setting's row on the calibration seeds."""
        return self.choice["calibration"]


def _log(text: str) -> None:
    print(text, flush=True)


def _parse_args(argv: list[str] | None, results_dir: Path) -> argparse.Namespace:
    """The options, with ``--quick`` applied and ``--out`` defaulted under ``results_dir``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0, help="episode i uses reset seed seed+i")
    parser.add_argument("--map-seed", type=int, default=0, help="static layout (not searched)")
    parser.add_argument("--reward", choices=["reward1", "reward2"], default="reward2")
    parser.add_argument("--top", type=int, default=6, help="stage-1 settings refined")
    parser.add_argument("--passes", type=int, default=3, help="coordinate-descent passes")
    parser.add_argument("--min-gain", type=float, default=0.1)
    parser.add_argument("--validate", type=int, default=10, help="fitting settings validated")
    parser.add_argument("--tolerance", type=float, default=0.5)
    parser.add_argument("--check-seed", type=int, default=1000, help="held-out episode seeds")
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help="results file (default baselines/results/calibration.json, "
        "or calibration-quick.json with --quick)",
    )
    parser.add_argument("--quick", action="store_true", help="tiny search, 3 episodes")
    parser.add_argument(
        "--protocol",
        action="store_true",
        help="the heuristics take the thesis protocol's options (THESIS_PROTOCOL)",
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.episodes = min(args.episodes, 3)
        args.top, args.passes, args.validate = 1, 1, 2
    if args.out is None:
        name = "calibration-quick.json" if args.quick else "calibration.json"
        args.out = results_dir / name
    return args


def _evaluator(args: argparse.Namespace) -> Evaluator:
    """The evaluator of the options, after logging the target and running the reference."""
    options = {}
    if args.protocol:
        options = {n: dict(THESIS_PROTOCOL[n]) for n in POLICIES if n in THESIS_PROTOCOL}
    ev = Evaluator(args.episodes, args.seed, args.map_seed, args.reward, options)
    _log(
        f"calibrating against GD {THESIS['greedy-distance']} and GG {THESIS['greedy-gain']}: "
        f"{args.episodes} episodes, seed {args.seed}, static map seed {args.map_seed}, "
        f"{args.reward}"
    )
    reference = ev.run(dict(REFERENCE), stage="reference")
    if options:
        _log(f"heuristic options: {options}")
    _log(f"reference: {summary_line(reference)}")
    return ev


def _coarse_stage(
    ev: Evaluator, coarse: dict[str, list[Any]], tolerance: float
) -> tuple[list[Row], int]:
    """Stage 1: every coarse grid point, best first, and how many of them fit."""
    grid = list(grid_points(coarse))
    _log(f"\nstage 1: coarse grid, {len(grid)} settings")
    stage1 = []
    for i, point in enumerate(grid, 1):
        stage1.append(ev.run({**REFERENCE, **point}, stage="coarse"))
        if i % 40 == 0 or i == len(grid):
            _log(f"  {i}/{len(grid)} done, {ev.cpu_seconds:.0f} s CPU so far")
    stage1.sort(key=lambda r: r["score"])
    for row in stage1[:10]:
        _log(f"  {summary_line(row)}  | " + setting_text({k: row["setting"][k] for k in coarse}))
    stage1_fits = sum(fits(r, tolerance) for r in stage1)
    _log(f"  {stage1_fits} of {len(stage1)} coarse settings fit within ±{tolerance}")
    return stage1, stage1_fits


def _refine_stage(
    ev: Evaluator, stage1: list[Row], refine: dict[str, Any], args: argparse.Namespace
) -> list[Row]:
    """Stage 2: coordinate descent from the ``--top`` best distinct coarse settings."""
    starts = distinct(stage1, args.top)
    _log(f"\nstage 2: coordinate descent from the {len(starts)} best distinct coarse settings")
    refined = []
    for i, row in enumerate(starts, 1):
        best, moves = coordinate_descent(
            ev, row["setting"], refine, args.passes, args.min_gain, f"start {i}", _log
        )
        refined.append({"start": row["setting"], "best": best, "moves": moves})
        _log(f"  start {i} -> {summary_line(best)}\n           {setting_text(best['setting'])}")
    return refined


def _finalists(stage1: list[Row], refined: list[Row], args: argparse.Namespace) -> list[Row]:
    """The best distinct fitting coarse settings and stage-2 end points, or the best of them if
    none fits (not the probes coordinate descent rejected: they lost by less than min-gain)."""
    pool = {setting_key(r["setting"]): r for r in stage1 + [r["best"] for r in refined]}
    candidates = sorted(pool.values(), key=lambda r: r["score"])
    finalists = distinct([r for r in candidates if fits(r, args.tolerance)], args.validate)
    return finalists or candidates[:1]


def _validate_stage(ev: Evaluator, finalists: list[Row], args: argparse.Namespace) -> list[Row]:
    """Stage 3: each finalist again on the held-out episode seeds, with its total score."""
    _log(
        f"stage 3: validation of {len(finalists)} fitting settings on episode seeds "
        f"{args.check_seed}..{args.check_seed + args.episodes - 1}"
    )
    validation = []
    for row in finalists:
        held = ev.run(row["setting"], seed=args.check_seed, stage="validation")
        total = round(row["score"] + held["score"], 6)
        validation.append(
            {"setting": row["setting"], "calibration": row, "held_out": held, "total": total}
        )
        _log(f"  cal. {summary_line(row)}\n  held {summary_line(held)}  -> total {total:.3f}")
        _log(f"       {setting_text(row['setting'])}")
    return validation


def _search(ev: Evaluator, args: argparse.Namespace) -> _Search:
    """Stages 1-3: the coarse grid, the refinement and the validation, with the winner."""
    coarse = QUICK_COARSE if args.quick else COARSE
    refine = QUICK_REFINE if args.quick else REFINE
    stage1, stage1_fits = _coarse_stage(ev, coarse, args.tolerance)
    stage1_cpu = ev.cpu_seconds
    refined = _refine_stage(ev, stage1, refine, args)
    stage2_cpu = ev.cpu_seconds - stage1_cpu
    evaluated = sorted(ev.cache.values(), key=lambda r: r["score"])
    fitting = [r for r in evaluated if fits(r, args.tolerance)]
    _log(f"\n{len(fitting)} of {len(evaluated)} evaluated settings fit within ±{args.tolerance}")
    validation = _validate_stage(ev, _finalists(stage1, refined, args), args)
    search = _Search(
        stage1=stage1,
        stage1_fits=stage1_fits,
        stage1_cpu=stage1_cpu,
        refined=refined,
        stage2_cpu=stage2_cpu,
        fitting=fitting,
        validation=validation,
        choice=min(validation, key=lambda v: v["total"]),
        search_cpu=ev.cpu_seconds,
        n_settings=sum(1 for r in ev.cache.values() if r["stage"] != "validation"),
    )
    _log_winner(search, args.tolerance)
    return search


def _log_winner(search: _Search, tolerance: float) -> None:
    winner = search.winner
    _log(f"\nwinner: {setting_text(winner['setting'])}\n        {summary_line(winner)}")
    _log(f"held out: {summary_line(search.choice['held_out'])}")
    _log(f"fits within ±{tolerance}: {fits(winner, tolerance)}")
    _log(
        f"search: {search.n_settings} settings + {len(search.validation)} validation runs, "
        f"{search.search_cpu:.0f} s CPU (stage 1 {search.stage1_cpu:.0f} s, "
        f"stage 2 {search.stage2_cpu:.0f} s)"
    )


def _check_winner(ev: Evaluator, winner: Row, quick: bool) -> dict[str, Row]:
    """Stage 4: the winner under Reward 1, the dynamic map and (full run) other map seeds."""
    _log("\nstage 4: checks of the winner (not used to choose)")
    checks = {}
    variants: dict[str, Row] = {
        "reward1": {"reward": "reward1"},
        "dynamic map": {"map_mode": "dynamic"},
    }
    if not quick:
        for map_seed in range(1, 5):
            variants[f"map_seed {map_seed}"] = {"map_seed": map_seed}
    for label, extra in variants.items():
        row = ev.run(winner["setting"], stage="check", **extra)
        checks[label] = row
        _log(f"  {label:12s} {summary_line(row)}")
    return checks


def _results(
    args: argparse.Namespace,
    ev: Evaluator,
    search: _Search,
    checks: dict[str, Row],
    wall_s: float,
    argv: list[str] | None,
) -> dict[str, Any]:
    """The contents of the results file."""
    refine = QUICK_REFINE if args.quick else REFINE
    return {
        "thesis": THESIS,
        "episodes": args.episodes,
        "seed": args.seed,
        "check_seed": args.check_seed,
        "map_seed": args.map_seed,
        "reward": args.reward,
        **({"policy_options": ev.options} if ev.options else {}),
        "fixed": FIXED,
        "reference": REFERENCE,
        "coarse_space": QUICK_COARSE if args.quick else COARSE,
        "refine_space": {k: list(v) for k, v in refine.items()},
        "score": {
            "std_weight": STD_WEIGHT,
            "order_penalty": ORDER_PENALTY,
            "slots_penalty": SLOTS_PENALTY,
            "min_gain": args.min_gain,
            "tolerance": args.tolerance,
        },
        "winner": search.winner,
        "winner_held_out": search.choice["held_out"],
        "winner_fits": fits(search.winner, args.tolerance),
        "refined": search.refined,
        "validation": search.validation,
        "checks": checks,
        "settings_evaluated": search.n_settings,
        "coarse_fits": search.stage1_fits,
        "fitting_settings": len(search.fitting),
        "stage1_cpu_s": round(search.stage1_cpu, 1),
        "stage2_cpu_s": round(search.stage2_cpu, 1),
        "search_cpu_s": round(search.search_cpu, 1),
        "total_cpu_s": round(ev.cpu_seconds, 1),
        "wall_s": round(wall_s, 1),
        "command": "python baselines/calibrate.py " + " ".join(argv or sys.argv[1:]),
        "rows": sorted(ev.cache.values(), key=lambda r: (r["stage"], r["score"])),
    }


def main(argv: list[str] | None = None, *, results_dir: Path = RESULTS) -> int:
    """The command line of ``baselines/calibrate.py``, which passes its own ``results/`` folder
    as ``results_dir`` (where ``--out`` goes by default)."""
    args = _parse_args(argv, results_dir)
    wall = time.perf_counter()
    ev = _evaluator(args)
    search = _search(ev, args)
    checks = _check_winner(ev, search.winner, args.quick)
    wall_s = time.perf_counter() - wall
    out = _results(args, ev, search, checks, wall_s, argv)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=1))
    _log(f"\nwrote {args.out} ({ev.cpu_seconds:.0f} s CPU, {wall_s:.0f} s wall)")
    return 0
