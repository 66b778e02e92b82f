"""What each part of the linear slot scorer (now ``frontier-rule``) is worth
(docs/beyond-the-thesis.md, "Ablation").

Scores, on the same validation episodes of every family (seeds 800,000+, never the held-out
ones), with ``frontier-marl benchmark``:

* ``nearest-path``, the best heuristic (every reachable cluster);
* ``path-only``: the linear slot scorer with the path weight alone, nearest-path among the
  explorer's 12 slots (where CEM starts);
* ``tour-rule``: the path weight plus a hand-set tour weight of -0.5, no learning;
* ``near-rule``: the tour rule plus a hand-set ``unknown_near`` weight of -0.5, no learning;
* ``fill-rule``: the near rule plus hand-set ``size`` 0.8 and ``fill`` -0.4 weights (where
  CEM starts): long frontier pieces before specks on fine grids, about neutral on coarse ones;
* ``explorer-dqn``: the DQN-trained slot scorer (no tour feature; a research model in the
  repository's ``training/models/``, not in the wheel);
* ``frontier-rule``: the CEM-checked linear scorer with the tour, unknown-near and fill
  features (the shipped ``explorer`` until the map-aware model replaced it);
* any further model given with ``--models`` (e.g. a CEM run without the tour feature:
  ``frontier-marl train explorer-cem --set env.tour=false --out runs/no-tour``, then
  ``cp -r runs/no-tour/best runs/explorer-no-tour``: a model is labelled by its folder).

    python benchmarks/explorer_ablation.py --episodes 64 \\
        --json training/results/explorer/ablation.json
"""

from __future__ import annotations

import argparse
from pathlib import Path

from frontier_marl.training.cem import save_hand_set
from frontier_marl.training.experiment import load_experiment

HAND_SET = {
    "path-only": {"path": -1.0},
    "tour-rule": {"path": -1.0, "tour": -0.5},
    "near-rule": {"path": -1.0, "tour": -0.5, "unknown_near": -0.5},
    "fill-rule": {"path": -1.0, "tour": -0.5, "unknown_near": -0.5, "size": 0.8, "fill": -0.4},
}


def save_rules(out: Path) -> list[str]:
    """Save the hand-set linear scorers under ``out``; returns their folders."""
    experiment = load_experiment("explorer-cem")
    for label, weights in HAND_SET.items():
        save_hand_set(weights, out / label, experiment)
    return [str(out / label) for label in HAND_SET]


#: The DQN-trained slot scorer, from the repository's root.
EXPLORER_DQN = Path("training/models/explorer-dqn")


def benchmark_command(
    argv: list[str] | None = None, explorer_dqn: Path = EXPLORER_DQN
) -> list[str]:
    """The command line of ``benchmarks/explorer_ablation.py``: saves the hand-set rules under
    ``--out`` and returns the ``frontier-marl benchmark`` arguments that score them beside the
    other policies (the script runs them with :func:`frontier_marl.cli.main.main`; the CLI is
    the layer above this one). ``explorer_dqn`` is the folder of the DQN-trained scorer."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=64, help="validation episodes per family")
    parser.add_argument("--models", default="", help="comma-separated extra model folders")
    parser.add_argument("--out", type=Path, default=Path("runs/explorer-ablation"))
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    policies = ["nearest-path", *save_rules(args.out), str(explorer_dqn), "frontier-rule"]
    policies += [m for m in args.models.split(",") if m]
    command = ["benchmark", "--split", "validation", "--episodes", str(args.episodes)]
    command += ["--policies", ",".join(policies)]
    if args.json is not None:
        command += ["--json", str(args.json)]
    if args.no_progress:
        command.append("--no-progress")
    return command
