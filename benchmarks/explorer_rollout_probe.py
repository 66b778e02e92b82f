"""How far below the explorer one step of lookahead on the true map goes: a privileged bound.

    python benchmarks/explorer_rollout_probe.py --families random-20,random-30,rooms-32 \\
        --episodes 16 --json training/results/explorer/rollout-probe.json

The probe: :mod:`frontier_marl.experiments.explorer_studies.rollout_probe`.
"""

from frontier_marl.experiments.explorer_studies.rollout_probe import main

if __name__ == "__main__":
    raise SystemExit(main())
