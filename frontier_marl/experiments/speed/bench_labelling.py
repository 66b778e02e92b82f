"""What the clustering's ``scipy.ndimage.label`` costs, and how often it could be skipped.

    python benchmarks/bench_labelling.py                # ~20 s
    python benchmarks/bench_labelling.py --steps 5000 --json labelling.json

Times ``ndimage.label`` (as the core calls it: 8-connectivity, 20x20 and 5x5 random masks) and
SciPy's Cython ``_ni_label._label`` underneath it, warm; one call on a batch of random frontier
masks (4 % of the cells, so each crop is about the whole map) labelled as the core labels
them, as one 2-D image with a blank row below each world
(:func:`~frontier_marl.core.frontiers.label_packed`), against the same masks
stacked as a 3-D array with a structure that does not connect the worlds; then plays a
random-valid-slot policy on thesis-20x20 and counts the labellings whose frontier mask equals
the previous labelling's (the only ones a cache could skip).
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


#: (worlds, side) of the batches :func:`tiled_vs_stacked` labels.
BATCHES = ((1, 20), (8, 20), (64, 20), (8, 64), (64, 64))


def tiled_vs_stacked(repeats: int = 100) -> dict[str, dict[str, float]]:
    """Per batch of :data:`BATCHES`: warm µs per labelling of its masks tiled (as the core
    labels them: crops of the whole map, each with a blank row below it, as one 2-D image) and
    stacked in 3-D, and the ratio stacked / tiled (the same labels, checked)."""
    rng = np.random.default_rng(0)
    stacked_structure = np.zeros((3, 3, 3), dtype=bool)
    stacked_structure[1] = ndimage.generate_binary_structure(2, 2)
    report = {}
    for worlds, side in BATCHES:
        tiled = np.zeros((worlds, side + 1, side), dtype=bool)
        tiled[:, :side] = rng.random((worlds, side, side)) < 0.04
        stacked = np.ascontiguousarray(tiled[:, :side])
        tiled_labels = np.empty(tiled.shape, np.int32)
        stacked_labels = np.empty(stacked.shape, np.int32)

        def tiled_call(
            masks: np.ndarray = tiled, out: np.ndarray = tiled_labels, side: int = side
        ) -> None:
            frontiers.label_packed(
                masks.reshape(-1), out.reshape(-1), len(masks) * (side + 1), side, 8
            )

        def stacked_call(masks: np.ndarray = stacked, out: np.ndarray = stacked_labels) -> None:
            ndimage.label(masks, structure=stacked_structure, output=out)

        tiled_call()
        stacked_call()
        if not np.array_equal(tiled_labels[:, :side], stacked_labels):
            raise AssertionError("the tiled labelling numbers the clusters differently")
        tiled_us = stacked_us = np.inf
        for _ in range(5):  # alternated rounds, the best of each: the machine's noise is one-sided
            tiled_us = min(tiled_us, timeit.timeit(tiled_call, number=repeats) / repeats * 1e6)
            stacked_us = min(
                stacked_us, timeit.timeit(stacked_call, number=repeats) / repeats * 1e6
            )
        report[f"{worlds} x {side}x{side}"] = {
            "tiled_us": tiled_us,
            "stacked_us": stacked_us,
            "ratio": stacked_us / tiled_us,
        }
    return report


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
    report = {
        "us_per_call": label_costs(),
        "tiled_vs_stacked": tiled_vs_stacked(),
        "rollout": repeated_frontiers(args.steps),
    }
    for name, cost in report["us_per_call"].items():
        print(f"{name:>24}: {cost:6.1f} µs per call (warm)")
    for batch, row in report["tiled_vs_stacked"].items():
        print(
            f"{batch:>24}: tiled {row['tiled_us']:7.1f} µs, stacked in 3-D "
            f"{row['stacked_us']:7.1f} µs ({row['ratio']:.2f}x)"
        )
    rollout = report["rollout"]
    print(
        f"{rollout['steps']} steps: {rollout['labellings']} labellings, "
        f"{rollout['same_frontier']} of them on the previous labelling's frontier"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0
