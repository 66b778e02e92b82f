"""The search behind :mod:`frontier_marl.experiments.calibrate`: the thesis's figures, the
score of a setting and the fit test, the evaluator that runs both heuristics on a setting (with
a cache), coordinate descent, and the choice of settings with distinct outcomes.
"""

from __future__ import annotations

import itertools
import json
import time
from collections.abc import Iterable
from typing import Any

from frontier_marl.config.thesis import HEURISTIC_BASELINES
from frontier_marl.evaluation import evaluate
from frontier_marl.policies import make_policy

THESIS = {
    policy: figure
    for (preset, mode, policy), figure in HEURISTIC_BASELINES.items()
    if (preset, mode) == ("thesis-20x20", "static")
}
POLICIES = tuple(THESIS)

#: Fixed geometry of the calibrated setting (not searched).
FIXED: dict[str, Any] = {
    "height": 20,
    "width": 20,
    "perception_range": 3,
    "n_agents": 1,
    "map_generator": "random",
}

STD_WEIGHT = 0.25
ORDER_PENALTY = 10.0
SLOTS_PENALTY = 1.0


def setting_key(setting: dict[str, Any]) -> str:
    return json.dumps({k: setting[k] for k in sorted(setting)}, sort_keys=True)


def score_of(row: dict[str, Any]) -> float:
    """The calibration score of an evaluated setting (:mod:`frontier_marl.experiments.calibrate`
    states it)."""
    gd, gg = row["greedy-distance"], row["greedy-gain"]
    mean_err = abs(gd["mean"] - THESIS["greedy-distance"][0]) + abs(
        gg["mean"] - THESIS["greedy-gain"][0]
    )
    std_err = abs(gd["std"] - THESIS["greedy-distance"][1]) + abs(
        gg["std"] - THESIS["greedy-gain"][1]
    )
    score = mean_err + STD_WEIGHT * std_err
    if gd["mean"] <= gg["mean"]:
        score += ORDER_PENALTY
    if row["setting"]["n_slots"] != 4:
        score += SLOTS_PENALTY
    return round(score, 6)


def fits(row: dict[str, Any], tolerance: float) -> bool:
    gd, gg = row["greedy-distance"], row["greedy-gain"]
    return (
        abs(gd["mean"] - THESIS["greedy-distance"][0]) <= tolerance
        and abs(gg["mean"] - THESIS["greedy-gain"][0]) <= tolerance
        and gd["mean"] > gg["mean"]
    )


class Evaluator:
    """Evaluates settings (both heuristics), caching by setting and counting CPU time."""

    def __init__(
        self,
        episodes: int,
        seed: int,
        map_seed: int,
        reward: str,
        options: dict[str, dict[str, Any]] | None = None,
    ) -> None:
        self.episodes, self.seed, self.map_seed, self.reward = episodes, seed, map_seed, reward
        self.options = options or {}  # policy name -> make_policy options
        self.cache: dict[str, dict[str, Any]] = {}
        self.cpu_seconds = 0.0

    def env_kwargs(self, setting: dict[str, Any], **extra: Any) -> dict[str, Any]:
        return {
            "preset": "thesis-20x20",
            **FIXED,
            "map_mode": "static",
            "map_seed": self.map_seed,
            "reward": self.reward,
            **setting,
            **extra,
        }

    def run(
        self, setting: dict[str, Any], *, seed: int | None = None, stage: str = "", **extra: Any
    ) -> dict[str, Any]:
        seed = self.seed if seed is None else seed
        key = setting_key({**setting, **extra, "_seed": seed})
        if key in self.cache:
            return self.cache[key]
        start = time.process_time()
        row: dict[str, Any] = {"setting": dict(setting), "stage": stage}
        if extra or seed != self.seed:
            row["variant"] = {**extra, "seed": seed}
        kwargs = self.env_kwargs(setting, **extra)
        for name in POLICIES:
            policy = make_policy(name, **self.options.get(name, {}))
            result = evaluate(kwargs, policy, episodes=self.episodes, seed=seed)
            row[name] = {
                "mean": round(result.mean_reward, 4),
                "std": round(result.std_reward, 4),
                "terminations": result.terminations,
                "end_reasons": result.end_reasons,
                "mean_steps": round(result.stat("steps")[0], 2),
            }
        row["cpu_s"] = round(time.process_time() - start, 3)
        self.cpu_seconds += row["cpu_s"]
        row["score"] = score_of(row)
        self.cache[key] = row
        return row


def grid_points(space: dict[str, list[Any]]) -> Iterable[dict[str, Any]]:
    names = list(space)
    for values in itertools.product(*(space[n] for n in names)):
        yield dict(zip(names, values, strict=True))


def _values(spec: Any, current: Any) -> list[Any]:
    if isinstance(spec, tuple) and spec[0] == "around":
        _, step, half = spec
        n = round(half / step)
        return [round(current + i * step, 4) for i in range(-n, n + 1)]
    return list(spec)


def _valid(name: str, value: Any) -> bool:
    if name == "obstacle_prob":
        return 0.0 <= value <= 0.9
    if name == "explore_threshold":
        return 0.0 < value <= 1.0
    return True


def coordinate_descent(
    ev: Evaluator,
    start: dict[str, Any],
    space: dict[str, Any],
    passes: int,
    min_gain: float,
    label: str,
    log: Any,
) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Refine ``start`` one parameter at a time; returns the best row and the moves made."""
    best = ev.run(start, stage=label)
    moves = []
    for pass_no in range(1, passes + 1):
        changed = False
        for name, spec in space.items():
            current = best["setting"][name]
            candidates = [v for v in _values(spec, current) if _valid(name, v)]
            rows = [ev.run({**best["setting"], name: v}, stage=label) for v in candidates]
            challenger = min(rows, key=lambda r: r["score"])
            if challenger["score"] <= best["score"] - min_gain:
                moves.append(
                    {
                        "pass": pass_no,
                        "parameter": name,
                        "from": current,
                        "to": challenger["setting"][name],
                        "score_from": best["score"],
                        "score_to": challenger["score"],
                    }
                )
                log(
                    f"  [{label}] pass {pass_no}: {name} {current} -> "
                    f"{challenger['setting'][name]}  score {best['score']:.3f} -> "
                    f"{challenger['score']:.3f}"
                )
                best = challenger
                changed = True
        if not changed:
            break
    return best, moves


def _outcome(row: dict[str, Any]) -> tuple[float, ...]:
    """The four figures rounded to 0.1: settings with the same outcome count once."""
    return tuple(round(row[p][k], 1) for p in POLICIES for k in ("mean", "std"))


def distinct(rows: Iterable[dict[str, Any]], count: int) -> list[dict[str, Any]]:
    """The first ``count`` rows (in the given order) whose outcomes differ."""
    chosen: list[dict[str, Any]] = []
    seen: set[tuple[float, ...]] = set()
    for row in rows:
        if len(chosen) == count:
            break
        if _outcome(row) not in seen:
            seen.add(_outcome(row))
            chosen.append(row)
    return chosen


def summary_line(row: dict[str, Any]) -> str:
    gd, gg = row["greedy-distance"], row["greedy-gain"]
    return (
        f"GD {gd['mean']:6.2f} ± {gd['std']:4.2f} ({gd['terminations']:2d} term.)  "
        f"GG {gg['mean']:6.2f} ± {gg['std']:4.2f} ({gg['terminations']:2d} term.)  "
        f"score {row['score']:.3f}"
    )


def setting_text(setting: dict[str, Any]) -> str:
    return " ".join(f"{k}={v}" for k, v in setting.items())
