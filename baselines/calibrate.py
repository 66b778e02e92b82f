"""Calibrate the parameters the thesis left open against its two 20x20 static baselines.

    python baselines/calibrate.py                      # the full search (about 6 min, one core)
    python baselines/calibrate.py --quick              # smoke test (seconds)

Writes ``baselines/results/calibration.json`` (``calibration-quick.json`` with ``--quick``)
unless ``--out`` says otherwise. The search, its score and its options:
:mod:`frontier_marl.experiments.calibrate`.
"""

from pathlib import Path

from frontier_marl.experiments.calibrate import main

if __name__ == "__main__":
    raise SystemExit(main(results_dir=Path(__file__).parent / "results"))
