"""What ``frontier-marl benchmark --jobs N`` gains over ``--jobs 1``, runs alternated.

    python benchmarks/bench_jobs.py                             # ~2 min on 2 idle cores
    python benchmarks/bench_jobs.py --jobs 2 --repeats 3 --json bench_jobs.json

What it runs and records: :mod:`frontier_marl.experiments.speed.bench_jobs`.
"""

from frontier_marl.experiments.speed.bench_jobs import main

if __name__ == "__main__":
    raise SystemExit(main())
