"""Would the explorer gain from knowing what each frontier would reveal? A privileged probe.

    python benchmarks/explorer_true_gain_probe.py --weights=-0.25,-0.1,0.1,0.25 \\
        --episodes 64 --first 736000 --json training/results/explorer/true-gain-probe.json

The probe: :mod:`frontier_marl.experiments.explorer_studies.true_gain_probe`.
"""

from frontier_marl.experiments.explorer_studies.true_gain_probe import main

if __name__ == "__main__":
    raise SystemExit(main())
