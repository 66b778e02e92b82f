"""What an incremental step could skip: distance-field cells that change, the belief's window.

    python benchmarks/incremental_potential.py --worlds 8 --steps 3000

What it counts: :mod:`frontier_marl.experiments.speed.incremental_potential`.
"""

from frontier_marl.experiments.speed.incremental_potential import main

if __name__ == "__main__":
    raise SystemExit(main())
