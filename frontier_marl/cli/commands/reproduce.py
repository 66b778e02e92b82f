"""``frontier-marl reproduce``: the thesis's main result, end to end.

Trains configuration 1 (``training/config01.toml``: absolute centroids + agent position,
unsorted, Reward 2, thesis-20x20, static map) with the thesis's DQN hyperparameters, evaluates
it with the thesis protocol (30 deterministic episodes), for three seeds trained side by side
in worker processes; runs the heuristic baselines (greedy-distance, greedy-gain, cost-utility,
random) on the same episodes; and prints and saves the comparison with the thesis's figures
(docs/results.md): the seeds' policies pooled, each seed, and the spread across seeds::

    frontier-marl reproduce                              # 3 seeds x 1e6 steps, ~26 min on 2 cores
    frontier-marl reproduce --seed 0                     # one seed, ~14 min
    frontier-marl reproduce --steps 50000 --out runs/quick
    frontier-marl reproduce --resume                     # after Ctrl-C: continue the runs

Files (under ``--out``, default ``runs/reproduce``): ``comparison.md`` / ``comparison.json``
(the table), ``comparison_rewards.png``, ``comparison_actions.png``, ``learning_curve.png``,
``baselines.json`` and one training run folder ``config01_seed<S>/`` per seed (model,
TensorBoard logs, checkpoints, ``evaluation.json``). The config is read from the repository's
``training/`` folder, found from the installed package (editable install), so any working
directory works.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from frontier_marl.cli.arguments import fail, int_list, positive_int
from frontier_marl.experiments.comparison import format_comparison_markdown
from frontier_marl.experiments.reproduce import DEFAULT_SEEDS, ReproduceResult, reproduce


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--steps",
        type=positive_int,
        default=1_000_000,
        metavar="N",
        help="training steps (default: %(default)s, the thesis's budget)",
    )
    parser.add_argument(
        "--seeds",
        "--seed",
        type=int_list(0),
        default=list(DEFAULT_SEEDS),
        metavar="S,S,...",
        help=f"training seeds, comma-separated (default: {','.join(map(str, DEFAULT_SEEDS))}); "
        "the table pools their policies and gives each seed and the spread",
    )
    parser.add_argument(
        "--jobs",
        type=positive_int,
        default=None,
        metavar="N",
        help="runs trained at a time, one worker process each (default: all seeds at once; "
        "1 trains them one after the other in this process)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("runs/reproduce"),
        metavar="DIR",
        help="output folder (default: %(default)s)",
    )
    parser.add_argument(
        "--episodes",
        type=positive_int,
        default=30,
        metavar="N",
        help="evaluation episodes, seeds 0..N-1 (default: %(default)s)",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="continue the runs in --out from their newest checkpoints (after "
        "Ctrl-C), or re-evaluate finished ones",
    )
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bars")


def _row_line(row: Mapping[str, Any], width: int) -> str:
    """One comparison row: mean ± std, terminations, degeneracy and the thesis's figures."""
    thesis = ""
    if row["thesis_mean"] is not None:
        thesis = f"   (thesis {row['thesis_mean']:.2f} ± {row['thesis_std']:.2f}"
        if row["thesis_terminations"] is not None:
            thesis += f", {row['thesis_terminations']}/{row['thesis_episodes']}"
        thesis += ")"
    flag = "  DEGENERATE" if row["degenerate"] else ""
    return (
        f"  {row['policy']:<{width}} {row['mean_reward']:6.2f} ± {row['std_reward']:5.2f}, "
        f"{row['terminations']}/{row['episodes']} terminations{flag}{thesis}"
    )


#: Labels of the files :func:`_print_files` lists, in order.
_FILE_LABELS = {
    "markdown": "table (Markdown)",
    "json": "table (JSON)",
    "rewards_figure": "rewards figure",
    "actions_figure": "actions figure",
    "learning_curve": "learning curves",
    "baselines": "heuristic rows",
}


def _print_files(result: ReproduceResult) -> None:
    print("Files")
    for key, label in _FILE_LABELS.items():
        path = result.files.get(key)
        if path is not None:
            print(f"  {label + ':':<18} {path}")
    for run_dir in result.run_dirs:
        print(f"  {'training run:':<18} {run_dir}")


def _print_summary(result: ReproduceResult) -> None:
    table: Any = result.table  # set: the run was not interrupted
    setting, training = table["setting"], table["training"]
    print("\nSummary")
    print(
        f"  {setting['preset']}, {setting['map_mode']} map, {setting['episodes']} "
        f"deterministic episodes; DQN trained {training['steps']} steps per seed"
    )
    for run in training["runs"]:
        print(
            f"  seed {run['seed']}: {run['wall_time_s']:.0f} s of training "
            f"({run['steps_per_second'] or 0:.0f} steps/s), reports its {run['reported_policy']}"
        )
    width = max(16, *(len(row["policy"]) for row in table["rows"]))
    for row in table["rows"]:
        print(_row_line(row, width))
    spread = table["seed_spread"]
    if len(spread["seeds"]) > 1:
        print(
            f"  across seeds: {spread['mean']:.2f} ± {spread['std']:.2f} (seed means "
            f"{', '.join(f'{m:.2f}' for m in spread['means'])})"
        )
    checks = ", ".join(f"{k} {'ok' if v else 'FAIL'}" for k, v in table["checks"].items())
    print(f"  DQN checks: {checks}")
    _print_files(result)


def run(args: argparse.Namespace) -> int:
    try:
        result = reproduce(
            args.out,
            steps=args.steps,
            seeds=args.seeds,
            jobs=args.jobs,
            episodes=args.episodes,
            resume=args.resume,
            progress=not args.no_progress,
        )
    except ValueError as exc:
        return fail("reproduce", str(exc))
    if result.interrupted:
        seeds = ",".join(map(str, args.seeds))
        saved = [str(d) for d, t in zip(result.run_dirs, result.trains, strict=True) if t]
        waiting = [str(d) for d, t in zip(result.run_dirs, result.trains, strict=True) if not t]
        print(
            f"interrupted: checkpoints saved in {', '.join(saved) or '(none)'}"
            + (f"; not started: {', '.join(waiting)}" if waiting else "")
            + f"\ncontinue with: frontier-marl reproduce --resume --out {result.out} "
            f"--steps {args.steps} --seeds {seeds}",
            file=sys.stderr,
        )
        return 130
    print()
    print(format_comparison_markdown(result.table), end="")
    _print_summary(result)
    return 0
