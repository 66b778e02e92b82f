"""Why does a trained policy stop making progress? A diagnostic for docs/results.md.

    python training/diagnose_cycles.py thesis-config01
    python training/diagnose_cycles.py runs/config01/seed0 --episodes 30

What it counts: :mod:`frontier_marl.experiments.diagnose_cycles`.
"""

from frontier_marl.experiments.diagnose_cycles import main

if __name__ == "__main__":
    raise SystemExit(main())
