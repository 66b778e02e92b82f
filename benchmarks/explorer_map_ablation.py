"""What each part of the map-aware explorer is worth (an ablation on a run's labels).

    python benchmarks/explorer_map_ablation.py runs/explorer-map --episodes 16 --json out.json

What it runs: :mod:`frontier_marl.experiments.explorer_studies.map_scorer_ablation`.
"""

from frontier_marl.experiments.explorer_studies.map_scorer_ablation import main

if __name__ == "__main__":
    raise SystemExit(main())
