"""What an incremental step could skip (issue 34 §1: "incremental distance fields ... and
bounded-window updates are the known ways down; measure which pays"). Not a test: run it by
hand.

    python benchmarks/incremental_potential.py --worlds 8 --steps 3000

Random valid slots in :func:`frontier_marl.vector_env`, one robot, on thesis-20x20 and on
64x64 rooms. After every step of a world that did not end, it counts against the state before
the step:

* the cells whose distance from the robot changed (known-free cells, -1 where unreachable):
  the least an incremental distance field must rewrite, against the cells reachable before or
  after (what a full BFS writes). A 4-connected grid is bipartite, so a source moved by one
  cell changes every reachable cell's distance by exactly one: when the robot moves, nothing
  can be skipped;
* the cells whose belief changed, and the box around them widened by one cell (a frontier
  cell's status depends on its 8 neighbours): the window a bounded frontier-mask update would
  recompute, against the whole map;
* the cells whose frontier status changed;
* the box around all frontier cells after the step: what a labelling of each world's frontier
  box instead of its whole map would read.

These are counts, not timings: they do not depend on the machine's load. To weigh them, it
also times (CPU time, the state after the counted steps, every world treated as changed) a
vector step and the compiled kernels every world whose belief changed runs in it: the
frontier masks, ``scipy.ndimage.label`` over their tiles, the clusters and gains from the
labels, every robot's slots (one distance field each), and the explored fractions. Their sum
per world is a floor under a world-step that keeps this clustering and these slots.
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import numpy as np

import frontier_marl
from frontier_marl.core.frontiers import frontier_mask
from frontier_marl.core.grid import FREE
from frontier_marl.core.planning import distance_field
from frontier_marl.core.world_kernels import (
    all_slots,
    basis_code,
    explored_fractions,
    recluster,
    stale_masks,
)
from frontier_marl.experiments.speed.bench_batches import ROOMS_64
from frontier_marl.experiments.speed.bench_vector_env import CONFIG01, random_valid

SETTINGS: dict[str, dict[str, Any]] = {
    "thesis-20x20": CONFIG01,
    "rooms 64x64": {**ROOMS_64, "max_steps": 2048},
}


def robot_fields(belief: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """(N, H, W) distance field of each world's robot over its known-free cells."""
    return np.stack(
        [
            distance_field(b, FREE, int(p[0, 0]), int(p[0, 1]))
            for b, p in zip(belief, positions, strict=True)
        ]
    )


def window_area(changed: np.ndarray) -> int:
    """Cells of the box around ``changed`` (H, W) widened by one cell, clipped to the map
    (0 when nothing changed)."""
    return box_area(changed, margin=1)


def box_area(cells: np.ndarray, margin: int = 0) -> int:
    """Cells of the box around the true cells of ``cells`` (H, W), widened by ``margin``
    and clipped to the map (0 when there are none)."""
    rows, cols = np.nonzero(cells)
    if len(rows) == 0:
        return 0
    height, width = cells.shape
    top, bottom = max(rows.min() - margin, 0), min(rows.max() + 1 + margin, height)
    left, right = max(cols.min() - margin, 0), min(cols.max() + 1 + margin, width)
    return int((bottom - top) * (right - left))


def potential(kwargs: dict[str, Any], worlds: int, steps: int, seed: int = 0) -> dict[str, float]:
    """Per world-step means of what an incremental step would have to touch (module doc)."""
    env = frontier_marl.vector_env(worlds, info="mask", **kwargs)
    rng = np.random.default_rng(seed)
    _, infos = env.reset(seed=seed)
    w = env.mdp.worlds
    cells = w.belief.shape[1] * w.belief.shape[2]
    totals = dict.fromkeys(
        (
            "reachable",
            "distance_changed",
            "moved",
            "window",
            "belief_changed",
            "frontier_changed",
            "frontier_box",
        ),  # fmt: skip
        0.0,
    )
    counted = 0
    for _ in range(steps):
        belief, positions = w.belief.copy(), w.positions.copy()
        fields = robot_fields(belief, positions)
        masks = np.stack([frontier_mask(b) for b in belief])
        _, _, terminated, truncated, infos = env.step(random_valid(infos["action_mask"], rng))
        going = ~(np.asarray(terminated) | np.asarray(truncated))
        new_fields = robot_fields(w.belief, w.positions)
        for i in np.flatnonzero(going):
            changed = w.belief[i] != belief[i]
            totals["reachable"] += int(((new_fields[i] >= 0) | (fields[i] >= 0)).sum())
            totals["distance_changed"] += int((new_fields[i] != fields[i]).sum())
            totals["moved"] += bool((w.positions[i] != positions[i]).any())
            totals["window"] += window_area(changed)
            totals["belief_changed"] += int(changed.sum())
            frontier = frontier_mask(w.belief[i])
            totals["frontier_changed"] += int((frontier != masks[i]).sum())
            totals["frontier_box"] += box_area(frontier)
            counted += 1
    means = {key: value / counted for key, value in totals.items()}
    step_us = _step_time(env, infos, rng, steps)
    kernels = kernel_times(env.mdp, max(steps, 2000))
    return {
        "world_steps": counted,
        "map_cells": cells,
        **means,
        "distance_changed_share": means["distance_changed"] / means["reachable"],
        "window_share": means["window"] / cells,
        "frontier_changed_share": means["frontier_changed"] / cells,
        "frontier_box_share": means["frontier_box"] / cells,
        "step_cpu_us": step_us,
        "kernel_cpu_us": kernels,
    }


def _step_time(env: Any, infos: dict[str, Any], rng: np.random.Generator, steps: int) -> float:
    """CPU microseconds of one vector step with random valid slots."""
    start = time.process_time()
    for _ in range(steps):
        *_, infos = env.step(random_valid(infos["action_mask"], rng))
    return (time.process_time() - start) / steps * 1e6


def kernel_times(mdp: Any, reps: int) -> dict[str, float]:
    """CPU microseconds per call of each per-world kernel of a step, on ``mdp``'s state with
    every world treated as changed (module doc)."""
    w, s, cfg = mdp.worlds, mdp.slots, mdp.cfg
    n, basis = mdp.n_worlds, basis_code(cfg.reward.threshold_basis)
    every = np.arange(n, dtype=w.stale.dtype)
    counted, fractions = np.full(n, -1, dtype=np.int64), np.zeros(n)

    def masks() -> None:
        w.clustered_version[:] = -1  # every world stale
        stale_masks(
            w.version, w.clustered_version, w.belief, w.stale, w.frontier, w.masks, w.boxes,
            w.packed_shape,
        )  # fmt: skip

    def clusters() -> None:
        w.clustered_version[:] = -1
        recluster(
            w.labels, w.boxes, int(w.packed_shape[1]), every, w.params.max_cluster_cells,
            w.params.gain != "unknown", w.belief, w.cell_rows, w.cell_cols, w.cell_cluster,
            w.n_cells, w.sizes, w.centroids, w.gains, w.n_clusters, w.version,
            w.clustered_version,
        )  # fmt: skip

    def slots() -> None:
        all_slots(
            every.astype(np.int64), w.belief, w.positions, w.cell_rows, w.cell_cols,
            w.cell_cluster, w.n_cells, w.centroids, w.sizes, w.gains, w.n_clusters,
            cfg.observation.sort_by_distance, s.cluster, s.valid, s.centroid, s.target,
            s.distance, s.size, s.gain, s.path_length, s.mask, s.live, mdp.packed,
        )  # fmt: skip

    def explored() -> None:
        counted[:] = -1
        explored_fractions(
            basis, w.belief, w.true_free, w.start_region, w.start_region_size, w.version,
            counted, fractions,
        )  # fmt: skip

    parts = {
        "frontier masks": masks,
        "scipy label": w.label_stale,
        "clusters and gains": clusters,
        "slots (a distance field per robot)": slots,
        "explored fraction": explored,
    }
    times = {}
    for name, part in parts.items():
        part()  # compiled, and its inputs in place
        start = time.process_time()
        for _ in range(reps):
            part()
        times[name] = (time.process_time() - start) / reps * 1e6
    return times


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--worlds", type=int, default=8)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    if args.worlds < 1 or args.steps < 1:
        parser.error("--worlds and --steps must be >= 1")
    report = {}
    for name, kwargs in SETTINGS.items():
        row = report[name] = potential(kwargs, args.worlds, args.steps)
        print(
            f"{name}: {row['world_steps']:,} world-steps; distance field: "
            f"{row['distance_changed']:.0f} of {row['reachable']:.0f} reachable cells change "
            f"({row['distance_changed_share']:.0%}), the robot moved in {row['moved']:.0%}; "
            f"belief: {row['belief_changed']:.1f} cells change, their window is "
            f"{row['window_share']:.1%} of the map; frontier status: "
            f"{row['frontier_changed']:.1f} cells ({row['frontier_changed_share']:.1%}); "
            f"the frontier's box: {row['frontier_box_share']:.0%} of the map",
            flush=True,
        )
        per_world = {k: v / args.worlds for k, v in row["kernel_cpu_us"].items()}
        print(
            f"  CPU per world-step: the step {row['step_cpu_us'] / args.worlds:.2f} us; "
            + ", ".join(f"{k} {v:.2f}" for k, v in per_world.items())
            + f" (sum {sum(per_world.values()):.2f} us)",
            flush=True,
        )
    if args.json:
        with open(args.json, "w") as out:
            json.dump(report, out, indent=2)
    return 0
