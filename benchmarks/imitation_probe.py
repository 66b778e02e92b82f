"""Can the explorer's observation imitate the lookahead oracle? (docs/beyond-the-thesis.md)

    python benchmarks/imitation_probe.py                     # 4 rounds, ~6 minutes
    python benchmarks/imitation_probe.py --json probe.json --rounds 6

The probe (DAgger on the oracle's labels):
:mod:`frontier_marl.experiments.explorer_studies.imitation_probe`.
"""

from frontier_marl.experiments.explorer_studies.imitation_probe import main

if __name__ == "__main__":
    raise SystemExit(main())
