"""Training speed benchmark: steps per second and where the time goes.

    python benchmarks/bench_training.py                       # config01, 20 000 steps
    python benchmarks/bench_training.py config04 --steps 50000 --json speed.json
    python benchmarks/bench_training.py --stages   # also time the stages inside the env step

What it times: :mod:`frontier_marl.experiments.speed.bench_training`. Run one benchmark at a
time."""

from frontier_marl.experiments.speed.bench_training import main

if __name__ == "__main__":
    raise SystemExit(main())
