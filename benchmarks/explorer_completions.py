"""A lookahead on maps drawn from the family's generator, completing the belief: how much of
the true-map oracle's gain the belief holds.

    python benchmarks/explorer_completions.py --families random-20,random-30,rooms-32 \
        --samples 1,8 --episodes 16

The planner and the options: :mod:`frontier_marl.experiments.explorer_studies.completions`.
"""

from frontier_marl.experiments.explorer_studies.completions import main

if __name__ == "__main__":
    raise SystemExit(main())
