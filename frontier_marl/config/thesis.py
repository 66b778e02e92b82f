"""Every figure of the thesis that the project reproduces or compares against, in one place.

The thesis's facts are restated in docs/thesis-mapping.md; this module is the only copy of its
numbers in the code, and everything that prints, checks or plots a thesis figure imports it.
"""

from __future__ import annotations

from typing import Any

#: The heuristic baselines (the thesis's Table 6.5): (preset, map mode, policy) -> (mean, std)
#: of the total episode reward over 30 episodes, one robot. The 20 x 20 (r = 3) static rows
#: are SPEC's (section 6), the calibration targets. The two 30 x 30 (r = 5) rows are quoted
#: from the thesis's Table 6.5 in issue 31 (section 4), not in SPEC: a check, never fitted.
#: The thesis's other four cells (20 x 20 dynamic, greedy gain on 30 x 30) are not known here.
HEURISTIC_BASELINES: dict[tuple[str, str, str], tuple[float, float]] = {
    ("thesis-20x20", "static", "greedy-distance"): (16.48, 1.78),
    ("thesis-20x20", "static", "greedy-gain"): (15.01, 1.12),
    ("thesis-30x30", "static", "greedy-distance"): (36.39, 1.27),
    ("thesis-30x30", "dynamic", "greedy-distance"): (35.15, 3.57),
}

#: The final DQN hyperparameters (SB3 ``DQN``); everything else is SB3's default.
DQN_HYPERPARAMETERS: dict[str, Any] = {
    "learning_rate": 5e-5,
    "exploration_fraction": 0.7,
    "exploration_final_eps": 0.05,
    "batch_size": 64,
    "buffer_size": 50_000,
    "target_update_interval": 500,
    "train_freq": 4,
}

#: The DQN results, 20 x 20, static map, 30 deterministic evaluation episodes, by experiment
#: name. ``mean``/``std``/``terminations`` are ``None`` where the thesis gives no number.
DQN_RESULTS: dict[str, dict[str, Any]] = {
    "config01": {
        "mean": 15.55,
        "std": 2.45,
        "terminations": 25,
        "episodes": 30,
        "action_shares": [0.506, 0.254, 0.212, 0.028],
        "steps": 1_000_000,
        "note": "genuine policy; TD loss bounded ~0.01-0.2",
    },
    "config04": {
        "mean": 16.91,
        "std": 0.57,
        "terminations": None,
        "episodes": 30,
        "note": "degenerate: almost always action 0; TD loss diverged to ~1e6",
    },
    "config05": {
        "mean": None,
        "std": None,
        "terminations": None,
        "episodes": 30,
        "note": "collapse to near-zero reward",
    },
    "config10": {
        "mean": 16.66,
        "std": 0.75,
        "terminations": 28,
        "episodes": 30,
        "note": "degenerate: 95.1 % action 0",
    },
}

#: The bar for a genuine reproduction of configuration 1: the thesis's mean minus one std.
CONFIG01_MIN_MEAN: float = round(
    DQN_RESULTS["config01"]["mean"] - DQN_RESULTS["config01"]["std"], 2
)


def heuristic_baseline(preset: str, map_mode: str, policy: str) -> tuple[float, float] | None:
    """The thesis's (mean, std) for this heuristic setting, or ``None`` where it gives none."""
    return HEURISTIC_BASELINES.get((preset, map_mode, policy))


def dqn_result_text(config: str) -> str:
    """The thesis's DQN result for ``config`` as one short cell (``""`` where it has none)."""
    figure = DQN_RESULTS.get(config)
    if figure is None:
        return ""
    if figure["mean"] is None:
        return f"({figure['note']})"
    text = f"{figure['mean']:.2f} ± {figure['std']:.2f}"
    if figure.get("terminations") is not None:
        text += f", {figure['terminations']}/{figure['episodes']}"
    return text
