"""``frontier-rule``: the hand-set linear scorer as a heuristic, with no model file."""

from __future__ import annotations

import numpy as np
import pytest

import frontier_marl
from frontier_marl.evaluation.benchmark import families as map_families
from frontier_marl.evaluation.benchmark import run as bench
from frontier_marl.policies import make_policy
from frontier_marl.policies.frontier_rule import (
    FRONTIER_RULE_SETTINGS,
    FRONTIER_RULE_WEIGHTS,
    FrontierRule,
)
from frontier_marl.policies.linear_scorer import feature_names


def test_the_rule_takes_the_valid_slot_of_highest_weighted_features() -> None:
    env = frontier_marl.parallel_env(preset="rooms-32", **FRONTIER_RULE_SETTINGS)
    rule = make_policy("frontier-rule")
    rule.attach(env)
    names = feature_names(env.config)
    slots = np.zeros((12, len(names)), dtype=np.float32)
    path = names.index("path")
    slots[:3, path] = [0.5, 0.25, 0.1]  # the nearest is slot 2 ...
    mask = np.array([1, 1, 0] + [0] * 9, dtype=np.int8)  # ... but it is not valid
    assert rule.act({"slots": slots, "action_mask": mask}, {}) == 1
    slots[0, names.index("utility")] = 1.0  # +1.006 outweighs 0.25 of extra path
    assert rule.act({"slots": slots, "action_mask": mask}, {}) == 0


def test_the_rule_needs_its_layout_and_its_env() -> None:
    rule = FrontierRule()
    with pytest.raises(RuntimeError, match="attach"):
        rule.act({"slots": np.zeros((12, 14)), "action_mask": np.ones(12)}, {})
    rule.attach(frontier_marl.parallel_env(**FRONTIER_RULE_SETTINGS))
    with pytest.raises(ValueError, match="the explorer observation"):
        rule.act(np.zeros(10), {})
    with pytest.raises(ValueError, match="needs features = 'explorer'"):
        rule.attach(frontier_marl.parallel_env())
    with pytest.raises(ValueError, match="unknown feature"):
        FrontierRule({**FRONTIER_RULE_WEIGHTS, "tuor": 1.0}).attach(
            frontier_marl.parallel_env(**FRONTIER_RULE_SETTINGS)
        )


def test_the_rule_decides_as_the_linear_model_with_its_weights_did() -> None:
    """A linear slot model (a MaskedDQN whose scorer holds these weights, as the linear
    ``explorer`` did until the map-aware model replaced it) and the rule play the same episodes
    to the same cell counts."""
    pytest.importorskip("stable_baselines3")
    from frontier_marl.policies.base import ModelPolicy
    from frontier_marl.policies.linear_scorer import weight_vector
    from frontier_marl.training.cem import linear_model

    family = map_families.family("rooms-32")
    (world,) = map_families.variant_configs(family, {}, 1)
    rule = bench.heuristic("frontier-rule")
    cfg = rule.config(world)
    weights = weight_vector(FRONTIER_RULE_WEIGHTS, feature_names(cfg), "rule")
    model = linear_model(cfg, weights)
    scorer = bench.Contender("linear", False, lambda: ModelPolicy(model), rule.config)
    runs = [bench.run_family(family, c, [world], 3, split="validation") for c in (rule, scorer)]
    travelled = [[e.travelled for e in run.episodes] for run in runs]
    assert travelled[0] == travelled[1]
    assert all(e.end_reason == "threshold" for e in runs[0].episodes)


def test_the_benchmark_counts_the_rule_among_the_heuristics() -> None:
    family = map_families.family("random-20")
    policies = bench.contenders(["nearest-path", "frontier-rule"])
    assert all(p.heuristic for p in policies)
    rows = bench.run_benchmark([family], policies, 2, split="validation")
    assert {row["best_heuristic"] for row in rows} <= {"nearest-path", "frontier-rule"}
    assert rows[1]["config"]["n_slots"] == 12 and rows[0]["config"]["n_slots"] == 256
