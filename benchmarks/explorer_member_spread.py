"""A scorer's members' disagreement as a penalty, on validation episodes.

    python benchmarks/explorer_member_spread.py runs/m4w16 --spreads 0,1,2 --weights 1,0.5,0

What it runs: :mod:`frontier_marl.experiments.explorer_studies.member_spread`.
"""

from frontier_marl.experiments.explorer_studies.member_spread import main

if __name__ == "__main__":
    raise SystemExit(main())
