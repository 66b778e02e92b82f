"""A map-aware team scorer fitted to each candidate's makespan to go on the true map.

    python benchmarks/team_map_scorer.py --families random-30,rooms-64 --agents 4 \
        --episodes 48 --save runs/team-map

The labels, the fit and the options: :mod:`frontier_marl.experiments.explorer_studies.
team_map_scorer`.
"""

from frontier_marl.experiments.explorer_studies.team_map_scorer import main

if __name__ == "__main__":
    raise SystemExit(main())
