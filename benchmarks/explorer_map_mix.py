"""The map scorer fitted to labels that mix the true map's cost with the completions' mean.

    python benchmarks/explorer_map_mix.py runs/rooms-c16-x4 runs/rooms-true-x8 --alphas 0.5

What it runs: :mod:`frontier_marl.experiments.explorer_studies.map_scorer_mix`.
"""

from frontier_marl.experiments.explorer_studies.map_scorer_mix import main

if __name__ == "__main__":
    raise SystemExit(main())
