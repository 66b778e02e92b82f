"""What the clustering's ``scipy.ndimage.label`` costs, and how often it could be skipped.

    python benchmarks/bench_labelling.py                # ~20 s
    python benchmarks/bench_labelling.py --steps 5000 --json labelling.json

Times ``ndimage.label`` (as the core calls it: 8-connectivity, 20x20 and 5x5 random masks) and
SciPy's Cython ``_ni_label._label`` underneath it, warm; then plays a random-valid-slot policy
on thesis-20x20 and counts the labellings whose frontier mask equals the previous labelling's
(the only ones a cache could skip).
"""

from __future__ import annotations

import argparse
import json
import timeit
from pathlib import Path

import numpy as np
from scipy import ndimage
from scipy.ndimage import _ni_label

import frontier_marl
from frontier_marl.core import frontiers


def label_costs(repeats: int = 20_000) -> dict[str, float]:
    """Warm µs per call of ``ndimage.label`` and of the Cython ``_label`` it wraps."""
    rng = np.random.default_rng(0)
    structure = ndimage.generate_binary_structure(2, 2)
    costs = {}
    for size in (20, 5):
        mask = rng.random((size, size)) < 0.1
        out = np.empty(mask.shape, np.int32)
        calls = {
            f"ndimage.label {size}x{size}": lambda m=mask: ndimage.label(m, structure),
            f"_ni_label._label {size}x{size}": lambda m=mask, o=out: _ni_label._label(
                m, structure, o
            ),
        }
        for name, call in calls.items():
            call()
            costs[name] = timeit.timeit(call, number=repeats) / repeats * 1e6
    return costs


def repeated_frontiers(steps: int, seed: int = 0) -> dict[str, int]:
    """Labellings in a rollout, and how many saw the previous labelling's frontier mask."""
    env = frontier_marl.FrontierExploreEnv(preset="thesis-20x20")
    rng = np.random.default_rng(seed)
    state: dict[str, object] = {"previous": None, "calls": 0, "same": 0}
    original = frontiers.ndimage.label

    def counting_label(mask: np.ndarray, *args: object, **kwargs: object) -> object:
        previous = state["previous"]
        state["calls"] = int(state["calls"]) + 1  # type: ignore[call-overload]
        if isinstance(previous, np.ndarray) and np.array_equal(previous, mask):
            state["same"] = int(state["same"]) + 1  # type: ignore[call-overload]
        state["previous"] = mask.copy()
        return original(mask, *args, **kwargs)

    frontiers.ndimage.label = counting_label
    try:
        _, info = env.reset(seed=seed)
        for _ in range(steps):
            action = int(rng.choice(np.flatnonzero(info["action_mask"])))
            _, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                _, info = env.reset()
    finally:
        frontiers.ndimage.label = original
    return {"steps": steps, "labellings": int(state["calls"]), "same_frontier": int(state["same"])}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    report = {"us_per_call": label_costs(), "rollout": repeated_frontiers(args.steps)}
    for name, cost in report["us_per_call"].items():
        print(f"{name:>24}: {cost:6.1f} µs per call (warm)")
    rollout = report["rollout"]
    print(
        f"{rollout['steps']} steps: {rollout['labellings']} labellings, "
        f"{rollout['same_frontier']} of them on the previous labelling's frontier"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0
