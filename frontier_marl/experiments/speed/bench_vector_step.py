"""Where one step of the batched env goes (docs/performance.md, issue 34 §1's profile). Not a
test: run it by hand.

    python benchmarks/bench_vector_step.py --worlds 8 --steps 5000 --json out.json

The env of the DQN share row: :func:`frontier_marl.vector_env` with configuration 1's settings,
``info="mask"``, the flat layout and same-step autoreset (what the SB3 adapter steps), random
valid slots. Each part is timed by a wall-clock timer wrapped around its call (each wrapper
adds a Python call, so the whole runs a little slower than unwrapped); the parts nest as
printed, and "the rest" of a part is its time outside the parts listed under it.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from contextlib import ExitStack
from typing import Any
from unittest.mock import patch

import numpy as np

import frontier_marl
from frontier_marl.experiments.speed.bench_vector_env import CONFIG01, random_valid
from frontier_marl.sim import batch_engine

#: (part, its parent, what to wrap: "mdp."/"worlds."/"env."/"encoder." for a method,
#: "engine." for a function of batch_engine's imports). The compiled calls on either side of
#: the labelling cannot be split further from Python.
PARTS = (
    ("step", None, "env.step"),
    ("mdp.step", "step", "mdp.step"),
    ("before the labelling (decide, walk, sensing, masks)", "mdp.step", "engine.before_labelling"),
    ("labelling (scipy label)", "mdp.step", "worlds.label_stale"),
    (
        "after the labelling (clusters, slots, explored fraction, rewards)",
        "mdp.step",
        "engine.after_labelling",
    ),
    ("observations", "step", "mdp.robot_observations"),
    ("encoder", "observations", "encoder.encode_batch"),
    ("autoresets", "step", "mdp.reset_worlds"),
)


def breakdown(worlds: int, steps: int, seed: int = 0) -> dict[str, Any]:
    """Mean microseconds per vector step of every part of :data:`PARTS`, after 200 untimed
    steps."""
    env = frontier_marl.vector_env(
        worlds, info="mask", obs_layout="flat", autoreset_mode="same-step", **CONFIG01
    )
    owners = {
        "env": env, "mdp": env.mdp, "worlds": env.mdp.worlds, "encoder": env.mdp.encoder,
        "engine": batch_engine,
    }  # fmt: skip
    spent: dict[str, float] = dict.fromkeys([part for part, _, _ in PARTS], 0.0)
    with ExitStack() as wrappers:  # each part timed until the end of the block
        for part, _, where in PARTS:
            owner_name, attribute = where.split(".")
            owner = owners[owner_name]
            timed = _timed(getattr(owner, attribute), part, spent)
            wrappers.enter_context(patch.object(owner, attribute, timed))
        rng = np.random.default_rng(seed)
        _, infos = env.reset(seed=seed)
        for measured in (False, True):
            for key in spent:
                spent[key] = 0.0
            for _ in range(steps if measured else 200):
                _, _, _, _, infos = env.step(random_valid(infos["action_mask"], rng))
    per_step = {part: seconds / steps * 1e6 for part, seconds in spent.items()}
    rest = dict(per_step)
    for part, parent, _ in PARTS:
        if parent is not None:
            rest[parent] -= per_step[part]
    return {"worlds": worlds, "steps": steps, "us_per_step": per_step, "rest_us": rest}


def _timed(function: Callable[..., Any], part: str, spent: dict[str, float]) -> Callable[..., Any]:
    def timed(*args: Any, **kwargs: Any) -> Any:
        start = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            spent[part] += time.perf_counter() - start

    return timed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--worlds", type=int, default=8)
    parser.add_argument("--steps", type=int, default=5000)
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    report = breakdown(args.worlds, args.steps)
    depth = {None: -1}
    for part, parent, _ in PARTS:
        depth[part] = depth[parent] + 1
        line = f"{'  ' * depth[part]}{part}: {report['us_per_step'][part]:.1f} us"
        if any(p == part for _, p, _ in PARTS):
            line += f" (the rest: {report['rest_us'][part]:.1f})"
        print(line)
    if args.json:
        with open(args.json, "w") as out:
            json.dump(report, out, indent=2)
    return 0
