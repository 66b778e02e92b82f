"""The team map scorer as a correction to team-explorer's Q-values, on validation episodes.

    python benchmarks/team_anchor.py --scorer runs/team-map --weights 0,0.1,1,10 \
        --families random-30,rooms-64 --agents 4 --episodes 16

The policy and the options: :mod:`frontier_marl.experiments.explorer_studies.team_anchor`.
"""

from frontier_marl.experiments.explorer_studies.team_anchor import main

if __name__ == "__main__":
    raise SystemExit(main())
