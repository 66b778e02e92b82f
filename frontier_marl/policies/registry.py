"""Every heuristic by its command-line name, and :func:`make_policy`."""

from __future__ import annotations

import inspect
from typing import Any

from frontier_marl.policies.base import Policy
from frontier_marl.policies.frontier_rule import FrontierRule
from frontier_marl.policies.heuristics import (
    CostUtility,
    FirstSlot,
    GreedyDistance,
    GreedyGain,
    NearestPath,
    RandomValid,
)
from frontier_marl.policies.team import CoordinatedAssignment, UtilityDiscount

#: Heuristic name (as used on the command line) -> class.
POLICIES: dict[str, type[Policy]] = {
    "greedy-distance": GreedyDistance,
    "greedy-gain": GreedyGain,
    "cost-utility": CostUtility,
    "nearest-path": NearestPath,
    "random": RandomValid,
    "first-slot": FirstSlot,
    "frontier-rule": FrontierRule,
    "coordinated-assignment": CoordinatedAssignment,
    "utility-discount": UtilityDiscount,
}

#: The heuristics that decide for the whole team jointly.
TEAM_POLICIES: tuple[str, ...] = ("coordinated-assignment", "utility-discount")


def env_settings(name: str) -> dict[str, Any]:
    """The env settings heuristic ``name`` reads (its observation layout), applied on top of
    the world it runs in; empty for a heuristic that reads the slot table alone."""
    return dict(getattr(POLICIES[name], "env_settings", {}))


def make_policy(name: str, seed: int | None = None, **options: Any) -> Policy:
    """A fresh heuristic by name; ``seed`` seeds the random policy (ignored by the others);
    ``options`` go to its constructor (e.g. ``commit="until-progress"``)."""
    if name not in POLICIES:
        raise ValueError(f"policy must be one of {list(POLICIES)}, got {name!r}")
    cls = POLICIES[name]
    accepted = set(inspect.signature(cls).parameters)
    unknown = sorted(set(options) - accepted)
    if unknown:
        raise ValueError(
            f"policy {name!r} has no option {unknown[0]!r} (options: {sorted(accepted) or 'none'})"
        )
    policy = cls(**options)
    policy.reset(seed)
    return policy
