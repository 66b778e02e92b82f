"""What a saved map scorer is worth, decision by decision and episode by episode.

    python benchmarks/explorer_map_probe.py RUN/best --weights 0,0.5,2 --episodes 16 \\
        --label-episodes 6

The measurements and the options:
:mod:`frontier_marl.experiments.explorer_studies.map_scorer_probe`.
"""

from frontier_marl.experiments.explorer_studies.map_scorer_probe import main

if __name__ == "__main__":
    raise SystemExit(main())
