"""Wall time of ``lookahead-oracle`` per episode, this tree against another checkout.

    python benchmarks/bench_oracle.py                          # this tree alone
    python benchmarks/bench_oracle.py --old ../frontier_marl-main --rounds 2 --json oracle.json

What it times: :mod:`frontier_marl.experiments.speed.bench_oracle`.
"""

from frontier_marl.experiments.speed.bench_oracle import main

if __name__ == "__main__":
    raise SystemExit(main())
