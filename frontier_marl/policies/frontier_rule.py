"""``frontier-rule``: the best hand-set linear slot scorer, as a heuristic.

Each valid slot is scored by the dot product of its explorer features
(:mod:`frontier_marl.sim.features`) with the fixed weights of :data:`FRONTIER_RULE_WEIGHTS`,
and the robot takes the slot of highest score; it keeps that target until it reaches it
(``commit = "until-reached"``). In words: the shortest known-free path first (``path``,
weight -1, which fixes the scale), then a route through every nearby frontier (``tour``),
frontiers that open onto little unknown space before those that open onto much (``unknown_near``,
so small pockets are finished before the robot leaves them), long frontier pieces before
specks (``size`` up, ``fill`` down), and, where the sensor is long, cost-utility's gain per
path length (``utility``, weighed by the sensor range). The weights were set by hand
(docs/experiments/2026-12-03-explorer-fill.md) and then checked by the cross-entropy method,
which moved none of them by more than 0.14 (docs/experiments/2026-12-04-floorplan-utility.md):
they are the linear ``explorer`` model's weights until 2026-12-04, now fixed here, with no
model file and no torch.

The rule reads the explorer observation layout (:data:`FRONTIER_RULE_SETTINGS`: 12 slots, the
unknown-cell gain, the tour, unknown-near, fill and utility features); wherever it runs
(``frontier-marl benchmark``, ``baselines``, ``gif``), its env takes these settings on the
same world, as a learned model's does.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from frontier_marl.policies.base import Info, Policy
from frontier_marl.policies.linear_scorer import explorer_slots, feature_names, weight_vector

#: The weight of each explorer feature (lengths in units of 32 cells, see the features).
FRONTIER_RULE_WEIGHTS: dict[str, float] = {
    "path": -1.0,
    "distance": 0.06796253472566605,
    "d_row": -0.01341044157743454,
    "d_col": -0.10755819082260132,
    "size": 0.7301007509231567,
    "gain": -0.02826240099966526,
    "isolation": 0.06616952270269394,
    "extra_path": -0.13011384010314941,
    "current": -0.18931502103805542,
    "live": -0.06221187487244606,
    "tour": -0.5922187566757202,
    "unknown_near": -0.5773216485977173,
    "fill": -0.3985895812511444,
    "utility": 1.0059990882873535,
}

#: The observation settings the rule reads (a model's own observation settings, but the reward,
#: which decides nothing: the env keeps its own).
FRONTIER_RULE_SETTINGS: dict[str, Any] = {
    "features": "explorer",
    "n_slots": 12,
    "gain": "unknown",
    "commit": "until-reached",
    "tour": True,
    "turn": False,
    "unknown_near": True,
    "near_ranges": None,
    "fill": True,
    "utility": True,
    "teammates": "none",
    "action_mask": False,
    "agent_position": True,
    "centroid": "absolute",
    "info_gain": False,
    "normalize": False,
    "sort_by_distance": False,
}


class FrontierRule(Policy):
    """The valid slot of highest ``features @ weights`` (ties: the lower slot), computed in
    float32 as the linear model it replaces did. Each robot decides alone."""

    name = "frontier-rule"
    env_settings: ClassVar[dict[str, Any]] = FRONTIER_RULE_SETTINGS

    def __init__(self, weights: dict[str, float] | None = None) -> None:
        self.weights = dict(FRONTIER_RULE_WEIGHTS if weights is None else weights)
        self._vector: np.ndarray | None = None

    def attach(self, env: Any) -> None:
        names = feature_names(env.config)
        self._vector = weight_vector(self.weights, names, "frontier-rule").astype(np.float32)

    def act(self, obs: Any, info: Info) -> int:
        if self._vector is None:
            raise RuntimeError("frontier-rule needs attach(env) before it acts")
        slots, mask = explorer_slots(obs)
        scores = slots.astype(np.float32) @ self._vector
        valid = mask.astype(bool)
        if not valid.any():
            return 0
        return int(np.argmax(np.where(valid, scores, -np.inf)))
