"""What the clustering's ``scipy.ndimage.label`` costs, and how often it could be skipped.

    python benchmarks/bench_labelling.py                # ~20 s
    python benchmarks/bench_labelling.py --steps 5000 --json labelling.json

What it times and counts: :mod:`frontier_marl.experiments.speed.bench_labelling`.
"""

from frontier_marl.experiments.speed.bench_labelling import main

if __name__ == "__main__":
    raise SystemExit(main())
