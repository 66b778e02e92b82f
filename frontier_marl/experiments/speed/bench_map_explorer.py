"""Inference speed of the map-aware explorer: decisions per second on one core.

    python benchmarks/bench_map_explorer.py                        # rooms-64, a fresh scorer
    python benchmarks/bench_map_explorer.py --model runs/explorer/best --json out.json

Plays the first ``--episodes`` validation episodes of ``--family`` with a
:class:`~frontier_marl.policies.map_explorer.MapExplorer` (torch and numba on one thread) and
times its ``act`` on every real decision (two or more valid slots; a single valid slot costs no
inference), split into the crops (:func:`~frontier_marl.policies.map_crops.slot_crops`) and
the rest (the network and the choice). The scorer's weights do not change its speed, so
without ``--model`` a freshly initialised scorer of the shipped shape is timed. One untimed
episode first warms numba's and torch's caches.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch

from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.evaluation.benchmark.families import family, variant_configs
from frontier_marl.policies import map_explorer
from frontier_marl.policies.linear_scorer import explorer_slots, feature_names
from frontier_marl.policies.map_explorer import MapExplorer, load_scorer, new_scorer
from frontier_marl.training.cost_regression import scorer_config


class _TimedCrops:
    """Wraps :func:`slot_crops` as the explorer calls it, summing its seconds."""

    def __init__(self) -> None:
        self.original = map_explorer.slot_crops
        self.seconds = 0.0

    def __call__(self, env: Any, slots: np.ndarray, robot: int = 0) -> np.ndarray:
        start = time.perf_counter()
        crops = self.original(env, slots, robot)
        self.seconds += time.perf_counter() - start
        return crops


def play(policy: MapExplorer, cfg: Any, seed: int) -> tuple[int, int, float]:
    """(real decisions, candidates scored, seconds in ``act``) of one episode."""
    env = FrontierParallelEnv(config=cfg)
    observations, infos = env.reset(seed=seed)
    policy.attach(env)
    decisions = candidates = 0
    seconds = 0.0
    while env.agents:
        obs = observations["robot_0"]
        valid = int(np.count_nonzero(explorer_slots(obs)[1]))
        start = time.perf_counter()
        action = policy.act(obs, infos["robot_0"])
        elapsed = time.perf_counter() - start
        if valid > 1:
            decisions, candidates, seconds = decisions + 1, candidates + valid, seconds + elapsed
        observations, _, _, _, infos = env.step({"robot_0": action})
    env.close()
    return decisions, candidates, seconds


def measure(family_name: str, episodes: int, model_folder: Path | None) -> dict[str, Any]:
    """Decisions per second of the map explorer on ``episodes`` validation episodes."""
    torch.set_num_threads(1)
    fam = family(family_name)
    (world,) = variant_configs(fam, None, 1)
    cfg = scorer_config(world)
    if model_folder is None:
        torch.manual_seed(0)
        model = new_scorer(len(feature_names(cfg)))
        model.eval()
    else:
        model, _ = load_scorer(model_folder)
    policy = MapExplorer(model, "explorer", 0.5)
    seeds = fam.seeds(episodes + 1, split="validation")
    timer = _TimedCrops()
    map_explorer.slot_crops = timer
    try:
        play(policy, cfg, seeds[0])  # warm-up
        timer.seconds = 0.0
        totals = np.zeros(3)
        for seed in seeds[1:]:
            totals += play(policy, cfg, seed)
    finally:
        map_explorer.slot_crops = timer.original
    decisions, candidates, seconds = totals
    if not decisions:
        raise ValueError(f"{episodes} episodes of {family_name} had no decision among two slots")
    return {
        "family": family_name,
        "episodes": episodes,
        "decisions": int(decisions),
        "candidates_per_decision": candidates / decisions,
        "decisions_per_s": decisions / seconds,
        "crops_share": timer.seconds / seconds,
        "torch_threads": torch.get_num_threads(),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--family", default="rooms-64")
    parser.add_argument("--episodes", type=int, default=3)
    parser.add_argument("--model", type=Path, default=None, help="a saved map explorer folder")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    report = measure(args.family, args.episodes, args.model)
    print(
        f"{report['family']}: {report['decisions_per_s']:.0f} decisions/s on one core "
        f"({report['decisions']} decisions, {report['candidates_per_decision']:.1f} candidates "
        f"each; crops {report['crops_share']:.0%} of the time)"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    return 0
