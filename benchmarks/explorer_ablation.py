"""What each part of `explorer` is worth (docs/beyond-the-thesis.md, "Ablation").

    python benchmarks/explorer_ablation.py --episodes 64 \\
        --json training/results/explorer/ablation.json

Saves the hand-set rules under ``--out`` (default ``runs/explorer-ablation``) and scores them
beside nearest-path, explorer-dqn and explorer with ``frontier-marl benchmark`` on validation
episodes. The policies and the options: :mod:`frontier_marl.experiments.explorer_studies.ablation`.
"""

from pathlib import Path

from frontier_marl.cli.main import main as cli
from frontier_marl.experiments.explorer_studies.ablation import benchmark_command

if __name__ == "__main__":
    explorer_dqn = Path(__file__).resolve().parents[1] / "training" / "models" / "explorer-dqn"
    raise SystemExit(cli(benchmark_command(explorer_dqn=explorer_dqn)))
