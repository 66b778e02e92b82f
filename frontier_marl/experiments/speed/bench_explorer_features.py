"""What the explorer's slot features cost in the env step (docs/performance.md).

Decisions per second of the batched vector env (one process, one core, random valid slots,
only ``step``/``reset`` timed) on a benchmark family's world, for the thesis's observation and
for the explorer layout with its optional features added one by one, each also as a ratio to
the thesis layout measured in the same run (each after a short untimed warm-up)::

    python benchmarks/bench_explorer_features.py --families rooms-64,rooms-96-fine \\
        --worlds 64 --seconds 5 --json out.json
"""

from __future__ import annotations

import argparse
import json
import platform
from pathlib import Path
from typing import Any

import frontier_marl
from frontier_marl.config import config_to_dict
from frontier_marl.evaluation.benchmark.families import family, variant_configs
from frontier_marl.experiments.speed.bench_vector_env import rate_batched

#: The observation layouts compared, each the previous one plus one feature.
LAYOUTS: dict[str, dict[str, Any]] = {
    "thesis": {"features": "thesis"},
    "explorer": {"features": "explorer"},
    "+ tour": {"features": "explorer", "tour": True},
    "+ unknown_near": {"features": "explorer", "tour": True, "unknown_near": True},
    "+ fill": {"features": "explorer", "tour": True, "unknown_near": True, "fill": True},
}


def decisions_per_second(kwargs: dict[str, Any], worlds: int, seconds: float) -> float:
    """Random valid decisions per second of ``worlds`` batched worlds built from ``kwargs``
    (:func:`~frontier_marl.experiments.speed.bench_vector_env.rate_batched`)."""
    return float(rate_batched(kwargs, worlds, seconds))


def warm_up(kwargs: dict[str, Any]) -> None:
    """Reset and step two worlds once, so that compiling stays out of the timed figures."""
    env = frontier_marl.vector_env(2, info="mask", **kwargs)
    _, infos = env.reset(seed=0)
    env.step(infos["action_mask"].argmax(axis=1))
    env.close()


def family_world(name: str) -> dict[str, Any]:
    """The env keyword arguments of family ``name``'s benchmark world, with 12 slots."""
    world = config_to_dict(variant_configs(family(name))[0])
    return {**world, "n_slots": 12}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", default="rooms-64,rooms-96-fine")
    parser.add_argument("--worlds", type=int, default=64, help="batched worlds")
    parser.add_argument("--seconds", type=float, default=5.0, help="timed seconds per figure")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    if args.worlds < 1 or args.seconds <= 0:
        parser.error("--worlds must be >= 1 and --seconds > 0")
    rows = []
    for name in args.families.split(","):
        world = family_world(name)
        base = None
        for label, layout in LAYOUTS.items():
            warm_up({**world, **layout})
            rate = decisions_per_second({**world, **layout}, args.worlds, args.seconds)
            base = base or rate
            rows.append({"family": name, "layout": label, "decisions_per_s": rate})
            print(f"{name:14s} {label:16s} {rate:9.0f} decisions/s  ({rate / base:.2f}x thesis)")
    if args.json is not None:
        machine = {"processor": platform.processor(), "python": platform.python_version()}
        options = {"worlds": args.worlds, "seconds": args.seconds, "machine": machine}
        args.json.write_text(json.dumps({"options": options, "rows": rows}, indent=1))
    return 0
