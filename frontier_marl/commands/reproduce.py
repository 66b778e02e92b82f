"""``frontier-marl reproduce``: the thesis's main result, end to end.

Trains configuration 1 (``training/config01.toml``: absolute centroids + agent position,
unsorted, Reward 2, thesis-20x20, static map) with the thesis's DQN hyperparameters, evaluates
it with the thesis protocol (30 deterministic episodes), runs the heuristic baselines
(greedy-distance, greedy-gain, cost-utility, random) on the same episodes, and prints and saves
the comparison with the thesis's figures (SPEC section 6)::

    frontier-marl reproduce                              # 1e6 steps, about 15 min on 2 cores
    frontier-marl reproduce --steps 50000 --out runs/quick
    frontier-marl reproduce --resume                     # after Ctrl-C: continue the run

Files (under ``--out``, default ``runs/reproduce``): ``comparison.md`` / ``comparison.json``
(the table), ``comparison_rewards.png``, ``comparison_actions.png``, ``learning_curve.png``,
``baselines.json`` and the training run folder ``config01_seed<S>/`` (model, TensorBoard logs,
checkpoints, ``evaluation.json``). The config is read from the repository's ``training/``
folder, found from the installed package (editable install), so any working directory works.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from frontier_marl.commands.baselines import non_negative_int, positive_int

    parser.add_argument(
        "--steps",
        type=positive_int,
        default=1_000_000,
        metavar="N",
        help="training steps (default: %(default)s, the thesis's budget)",
    )
    parser.add_argument(
        "--seed",
        type=non_negative_int,
        default=0,
        metavar="S",
        help="training seed (default: %(default)s)",
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
        help="continue the run in --out from its newest checkpoint (after "
        "Ctrl-C), or re-evaluate a finished one",
    )
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bars")


def _print_summary(result: object) -> None:
    table = result.table  # type: ignore[attr-defined]
    training = table["training"]
    print("\nSummary")
    print(
        f"  {table['setting']['preset']}, {table['setting']['map_mode']} map, "
        f"{table['setting']['episodes']} deterministic episodes; DQN trained "
        f"{training['steps']} steps in {training['wall_time_s']:.0f} s "
        f"({training['steps_per_second'] or 0:.0f} steps/s)"
    )
    for row in table["rows"]:
        thesis = ""
        if row["thesis_mean"] is not None:
            thesis = f"   (thesis {row['thesis_mean']:.2f} ± {row['thesis_std']:.2f}"
            if row["thesis_terminations"] is not None:
                thesis += f", {row['thesis_terminations']}/{row['thesis_episodes']}"
            thesis += ")"
        flag = "  DEGENERATE" if row["degenerate"] else ""
        print(
            f"  {row['policy']:<16} {row['mean_reward']:6.2f} ± {row['std_reward']:5.2f}, "
            f"{row['terminations']}/{row['episodes']} terminations{flag}{thesis}"
        )
    checks = ", ".join(f"{k} {'ok' if v else 'FAIL'}" for k, v in table["checks"].items())
    print(f"  DQN checks: {checks}")
    print("Files")
    labels = {
        "markdown": "table (Markdown)",
        "json": "table (JSON)",
        "rewards_figure": "rewards figure",
        "actions_figure": "actions figure",
        "learning_curve": "learning curve",
        "baselines": "heuristic rows",
        "run_dir": "training run",
    }
    for key, label in labels.items():
        path = result.files.get(key)  # type: ignore[attr-defined]
        if path is not None:
            print(f"  {label + ':':<18} {path}")


def run(args: argparse.Namespace) -> int:
    from frontier_marl.commands.baselines import fail
    from frontier_marl.reproduce import format_comparison_markdown, reproduce

    try:
        result = reproduce(
            args.out,
            steps=args.steps,
            seed=args.seed,
            episodes=args.episodes,
            resume=args.resume,
            progress=not args.no_progress,
        )
    except ValueError as exc:
        return fail("reproduce", str(exc))
    if result.interrupted:
        print(
            f"interrupted: checkpoint saved in {result.run_dir}\n"
            f"continue with: frontier-marl reproduce --resume --out {result.out} "
            f"--steps {args.steps} --seed {args.seed}",
            file=sys.stderr,
        )
        return 130
    print()
    print(format_comparison_markdown(result.table), end="")
    _print_summary(result)
    return 0
