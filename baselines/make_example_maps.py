"""Regenerate the example maps in frontier_marl/assets/maps/ from their fixed seeds.

    python baselines/make_example_maps.py            # write the .txt files
    python baselines/make_example_maps.py --check    # exit 1 if a file differs

The code: :mod:`frontier_marl.experiments.make_example_maps`.
"""

from pathlib import Path

from frontier_marl.experiments.make_example_maps import main

if __name__ == "__main__":
    raise SystemExit(
        main(default_out=Path(__file__).resolve().parents[1] / "frontier_marl" / "assets" / "maps")
    )
