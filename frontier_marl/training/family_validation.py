"""Validation on benchmark families: T99 against nearest-path on validation episodes.

A run with ``train.families`` and ``train.validate_every`` scores its greedy policy on the
first ``validation_episodes`` validation episodes (seeds 800,000+, never the held-out ones) of
every family: per episode the relative T99 difference to nearest-path on the same episode,
``T99 / T99_nearest - 1``, with an episode that did not reach 99 % counted as +100 %; the
score is minus their mean over all families' episodes (higher is better, 0 = parity), so the
best policy is the one that travels least relative to the best heuristic.

A team model (``agents`` > 1) is scored the same way on its makespan to 99 %, against
utility-discount (the best team heuristic with 4 robots, docs/benchmark.md), every robot acting
from its own observation.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig, config_to_dict, make_config
from frontier_marl.evaluation.benchmark.families import (
    OBSERVATION_KEYS,
    family,
    variant_configs,
    world_settings,
)
from frontier_marl.evaluation.benchmark.run import Contender, default_commit, heuristic, run_family
from frontier_marl.evaluation.records import level_key
from frontier_marl.policies.base import ModelPolicy

FAILURE = 1.0  # the relative T99 difference an episode that never reached 99 % counts as
REFERENCE = "nearest-path"
TEAM_REFERENCE = "utility-discount"


def _t99(result: Any) -> list[float | None]:
    """Per episode, T99 (one robot) or the makespan to 99 % (a team)."""
    key = level_key(0.99)
    if result.n_agents > 1:
        return [episode.makespan_to_coverage.get(key) for episode in result.episodes]
    return [episode.cells_to_coverage.get(key) for episode in result.episodes]


class FamilyValidator:
    """``validator(model)`` -> a validation record whose ``score`` is minus the mean relative
    difference to the reference heuristic: T99 against nearest-path for one robot, the
    makespan against utility-discount for ``agents`` robots (see the module docstring)."""

    def __init__(
        self, families: Sequence[str], episodes: int, model_config: EnvConfig, agents: int = 1
    ) -> None:
        self.families = [family(name) for name in families]
        self.episodes = episodes
        self.worlds = [variant_configs(fam, None, agents) for fam in self.families]
        own = config_to_dict(model_config)
        self._own = {key: own[key] for key in OBSERVATION_KEYS}
        self.reference_name = REFERENCE if agents == 1 else TEAM_REFERENCE
        self.metric = "t99" if agents == 1 else "makespan99"
        reference = heuristic(self.reference_name, default_commit(agents))
        self.reference = [
            _t99(run_family(fam, reference, worlds, episodes, split="validation"))
            for fam, worlds in zip(self.families, self.worlds, strict=True)
        ]

    def _contender(self, model: Any) -> Contender:
        def config(world: EnvConfig) -> EnvConfig:
            return make_config(None, **{**world_settings(world), **self._own})

        policy = ModelPolicy(model, name="validation", deterministic=True)
        return Contender("validation", False, lambda: policy, config)

    def __call__(self, model: Any) -> dict[str, Any]:
        contender = self._contender(model)
        per_family: dict[str, float] = {}
        differences: list[float] = []
        for fam, worlds, reference in zip(self.families, self.worlds, self.reference, strict=True):
            result = run_family(fam, contender, worlds, self.episodes, split="validation")
            family_differences = [
                FAILURE if t99 is None or base is None else t99 / base - 1.0
                for t99, base in zip(_t99(result), reference, strict=True)
            ]
            per_family[fam.name] = float(np.mean(family_differences))
            differences += family_differences
        mean = float(np.mean(differences))
        record = {"score": -mean, "vs_reference": mean}
        if self.metric == "t99":
            record["t99_vs_nearest_path"] = mean  # the name earlier summaries use
        return {
            **record,
            "reference": self.reference_name,
            "metric": self.metric,
            "by_family": per_family,
            "episodes": self.episodes,
            "split": "validation",
        }
