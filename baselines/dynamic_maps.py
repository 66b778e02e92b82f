"""Which open choice gives dynamic maps the thesis's lower means and wider spread?

    python baselines/dynamic_maps.py                         # every candidate, both grids
    python baselines/dynamic_maps.py --commit until-progress --json dynamic.json

The candidates and the pattern: :mod:`frontier_marl.experiments.dynamic_maps`.
"""

from frontier_marl.experiments.dynamic_maps import main

if __name__ == "__main__":
    raise SystemExit(main())
