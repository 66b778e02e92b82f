"""Which protocol choice puts every cell of the thesis's Table 6.5 within one thesis std?

    python baselines/table65.py            # every candidate, 30 episodes per cell

The candidates, the criteria and the options: :mod:`frontier_marl.experiments.table65`.
"""

from frontier_marl.experiments.table65 import main

if __name__ == "__main__":
    raise SystemExit(main())
