"""The single-robot map scorer in a team, with claimed targets discounted (Burgard-style).

    python benchmarks/explorer_team_claims.py --families random-30,rooms-64 --agents 4 \
        --variants 0.3:5,1:5,0.3:5:2,1:10,3:10 --episodes 16

The policy and the options: :mod:`frontier_marl.experiments.explorer_studies.team_claims`.
"""

from frontier_marl.experiments.explorer_studies.team_claims import main

if __name__ == "__main__":
    raise SystemExit(main())
