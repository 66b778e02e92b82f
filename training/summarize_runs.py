"""A training run folder as one small JSON summary: what a doc may cite, without the artefacts.

    python training/summarize_runs.py runs/config01/seed0 --out training/results
    python training/summarize_runs.py runs/reproduce/config01_seed* --out training/results/x

What a summary holds: :mod:`frontier_marl.experiments.summarize_runs`.
"""

from frontier_marl.experiments.summarize_runs import main

if __name__ == "__main__":
    raise SystemExit(main())
