"""Decisions per second of the batched env at batch 1, 8 and 64, and memory per world
(docs/performance.md, issue 34's report). Not a test: run it by hand.

    python benchmarks/bench_batches.py --seconds 3 --json out.json

1. **Decisions per second** (one decision = one robot's choice) of
   :func:`frontier_marl.vector_env` with random valid slots, only ``step``/``reset`` timed
   (:func:`~frontier_marl.experiments.speed.bench_vector_env.rate_batched`), on thesis-20x20
   and on 64x64 room layouts, each with 1 and 4 robots.
2. **Memory per world**: the bytes that Python and numpy hold (``tracemalloc``) after a reset
   and 50 steps of a batch of 64 worlds, less those of a batch of 8, per extra world; room
   layouts of 64x64 and 128x128 with 4 robots.
"""

from __future__ import annotations

import argparse
import gc
import json
import platform
import tracemalloc
from typing import Any

import numpy as np

import frontier_marl
from frontier_marl.experiments.speed.bench_vector_env import random_valid, rate_batched

ROOMS_64 = {"preset": "rooms-32", "height": 64, "width": 64, "perception_range": 5}
SETTINGS: dict[str, dict[str, Any]] = {
    "thesis-20x20, 1 robot": {"preset": "thesis-20x20"},
    "thesis-20x20, 4 robots": {"preset": "thesis-20x20", "n_agents": 4},
    "rooms 64x64, 1 robot": {**ROOMS_64, "max_steps": 2048},
    "rooms 64x64, 4 robots": {**ROOMS_64, "n_agents": 4, "max_steps": 2048},
}
BATCHES = (1, 8, 64)
MEMORY_SIZES = (64, 128)


def decisions_table(seconds: float) -> list[dict[str, Any]]:
    """Decisions per second for every setting and batch size."""
    rows = []
    for label, kwargs in SETTINGS.items():
        rate_batched(kwargs, 2, 0.2)  # loads the compiled kernels
        for n in BATCHES:
            rate = rate_batched(kwargs, n, seconds)
            rows.append({"setting": label, "worlds": n, "decisions_per_s": rate})
            print(f"{label}, batch {n:>2}: {rate:,.0f} decisions/s", flush=True)
    return rows


def held_bytes(kwargs: dict[str, Any], n: int, steps: int = 50) -> int:
    """Bytes traced while a batch of ``n`` worlds is alive after a reset and ``steps`` steps."""
    gc.collect()
    tracemalloc.start()
    env = frontier_marl.vector_env(n, info="mask", **kwargs)
    _, infos = env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(steps):
        _, _, _, _, infos = env.step(random_valid(infos["action_mask"], rng))
    gc.collect()
    held = tracemalloc.get_traced_memory()[0]
    tracemalloc.stop()
    env.close()
    return held


def memory_table() -> list[dict[str, Any]]:
    """Bytes per world (batch 64 less batch 8, over 56 worlds) for each map size."""
    rows = []
    for size in MEMORY_SIZES:
        kwargs = {**ROOMS_64, "height": size, "width": size, "n_agents": 4, "max_steps": 4096}
        held_bytes(kwargs, 2, 2)  # compiled kernels and caches, outside the measurement
        small, large = held_bytes(kwargs, 8), held_bytes(kwargs, 64)
        per_world = (large - small) / 56
        rows.append({"map": f"{size}x{size}", "robots": 4, "bytes_per_world": per_world})
        print(f"rooms {size}x{size}, 4 robots: {per_world / 1024:,.0f} KiB per world", flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="timed seconds per figure")
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args(argv)
    report = {
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "decisions": decisions_table(args.seconds),
        "memory": memory_table(),
    }
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(report, handle, indent=2)
    return 0
