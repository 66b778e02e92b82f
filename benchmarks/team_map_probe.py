"""A team scorer's regret on labelled decisions, beside the nearest candidate's.

    python benchmarks/team_map_probe.py runs/team-map-c4 runs/team-map-c4/labels.npz

See :func:`frontier_marl.experiments.explorer_studies.team_map_scorer.probe`.
"""

from frontier_marl.experiments.explorer_studies.team_map_scorer import probe_main

if __name__ == "__main__":
    raise SystemExit(probe_main())
