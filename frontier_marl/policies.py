"""Frontier-selection policies behind one interface: heuristics, and adapters for learned models.

A :class:`Policy` picks one cluster slot per robot. It works with the single-robot Gymnasium
env (:meth:`Policy.act`) and with every robot of the PettingZoo ParallelEnv
(:meth:`Policy.act_team`)::

    policy = make_policy("greedy-distance")
    policy.reset(seed=0)
    obs, infos = par_env.reset(seed=0)
    actions = policy.act_team(obs, infos)          # {"robot_0": slot, ...}

The heuristics read only a robot's step info (``clusters`` with slot, centroid, target, size,
gain and distance per live slot; ``action_mask``; ``position``), never hidden env state:

* ``greedy-distance``: the nearest cluster (smallest Euclidean centroid ``distance``; ties:
  lowest slot).
* ``greedy-gain``: the largest information ``gain`` (ties: nearest, then lowest slot).
* ``cost-utility``: the largest ``gain / path length``, the path length being the 4-connected
  shortest path (what A* returns) from the robot to the cluster's target over the known-free
  cells of the robot's own map (the belief grid). Ties: nearest, then lowest slot. The belief
  is not part of the standard info, so the policy takes it from ``info["belief"]`` when present,
  else from the env passed to :meth:`Policy.attach` (``env.unwrapped.world.belief``: the map
  the robots have built, i.e. what they know, not hidden state). :func:`frontier_marl.
  evaluation.evaluate` attaches the env automatically.
* ``random``: uniform over the valid slots of ``action_mask``, from its own seeded generator.

With no live cluster every heuristic returns slot 0 (the env's idle action).

Learned models plug in through :class:`CallablePolicy` (any ``obs -> action`` callable) or
:class:`ModelPolicy` (anything with SB3's ``predict(obs, deterministic=...)``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from frontier_marl.core.grid import FREE
from frontier_marl.core.planning import bfs_distances

Info = Mapping[str, Any]


class Policy:
    """Base class: one decision per robot from its observation and step info.

    Subclasses override :meth:`act` (one robot) or :meth:`act_team` (all robots at once, for
    joint policies). ``deterministic`` tells evaluators whether two runs with the same seeds
    give the same actions.
    """

    name: str = "policy"
    deterministic: bool = True

    def reset(self, seed: int | None = None) -> None:
        """Start a new episode; ``seed`` reseeds any internal randomness."""

    def attach(self, env: Any) -> None:
        """Give the policy the env it is about to act in (default: ignored)."""

    def act(self, obs: Any, info: Info) -> int:
        """The slot chosen by one robot."""
        raise NotImplementedError

    def act_team(
        self, observations: Mapping[str, Any], infos: Mapping[str, Info]
    ) -> dict[str, int]:
        """One slot per robot (the keys of ``observations``), each robot deciding alone."""
        return {agent: self.act(obs, infos[agent]) for agent, obs in observations.items()}

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r})"


class HeuristicPolicy(Policy):
    """A policy that applies :meth:`choose` to each robot's info independently."""

    def act(self, obs: Any, info: Info) -> int:
        return int(self.choose(info))

    def choose(self, info: Info) -> int:
        raise NotImplementedError


def _clusters(info: Info) -> list[Mapping[str, Any]]:
    try:
        return list(info["clusters"])
    except (KeyError, TypeError) as exc:
        raise ValueError("info must hold a 'clusters' list (the env's step info)") from exc


class GreedyDistance(HeuristicPolicy):
    """Nearest cluster: smallest centroid distance; ties go to the lowest slot."""

    name = "greedy-distance"

    def choose(self, info: Info) -> int:
        clusters = _clusters(info)
        if not clusters:
            return 0
        best = min(clusters, key=lambda c: (float(c["distance"]), int(c["slot"])))
        return int(best["slot"])


class GreedyGain(HeuristicPolicy):
    """Largest information gain; ties go to the nearest, then the lowest slot."""

    name = "greedy-gain"

    def choose(self, info: Info) -> int:
        clusters = _clusters(info)
        if not clusters:
            return 0
        best = min(
            clusters, key=lambda c: (-float(c["gain"]), float(c["distance"]), int(c["slot"]))
        )
        return int(best["slot"])


class CostUtility(HeuristicPolicy):
    """Largest ``gain / path length`` (path over the known-free cells of the robot's map).

    The map comes from ``info["belief"]`` if the info has it, else from the attached env's
    ``unwrapped.world.belief``. A path length of 0 (robot on the target) counts as 1; a
    target with no known-free path (never the case for the env's live slots) is skipped.
    """

    name = "cost-utility"

    def __init__(self) -> None:
        self._belief_source: Callable[[], np.ndarray] | None = None

    def attach(self, env: Any) -> None:
        unwrapped = getattr(env, "unwrapped", env)
        if "world" not in dir(unwrapped):  # dir(): the property raises before reset()
            raise ValueError(
                f"cost-utility needs an env with a .world (the robots' map); got {type(env)}"
            )
        self._belief_source = lambda: unwrapped.world.belief

    def _belief(self, info: Info) -> np.ndarray:
        if "belief" in info:
            return np.asarray(info["belief"])
        if self._belief_source is None:
            raise ValueError(
                "cost-utility needs the robot's map: put it in info['belief'] "
                "or call policy.attach(env) first"
            )
        return np.asarray(self._belief_source())

    def path_lengths(self, info: Info) -> dict[int, int]:
        """Shortest known-free path length from the robot to each live slot's target
        (-1 where unreachable)."""
        clusters = _clusters(info)
        if not clusters:
            return {}
        belief = self._belief(info)
        row, col = (int(v) for v in info["position"])
        distances = bfs_distances(belief == FREE, (row, col))
        lengths = {}
        for c in clusters:
            t_row, t_col = (int(v) for v in c["target"])
            lengths[int(c["slot"])] = int(distances[t_row, t_col])
        return lengths

    def utilities(self, info: Info) -> dict[int, float]:
        """``gain / max(path length, 1)`` per live slot; ``-inf`` where unreachable."""
        lengths = self.path_lengths(info)
        out = {}
        for c in _clusters(info):
            length = lengths[int(c["slot"])]
            out[int(c["slot"])] = (
                float(c["gain"]) / max(length, 1) if length >= 0 else float("-inf")
            )
        return out

    def choose(self, info: Info) -> int:
        clusters = _clusters(info)
        if not clusters:
            return 0
        utility = self.utilities(info)
        best = min(
            clusters,
            key=lambda c: (-utility[int(c["slot"])], float(c["distance"]), int(c["slot"])),
        )
        return int(best["slot"])


class RandomValid(HeuristicPolicy):
    """Uniform over the valid slots of ``action_mask`` (slot 0 when none is valid).

    One generator serves every robot (drawn in agent order); :meth:`reset` reseeds it.
    """

    name = "random"
    deterministic = False

    def __init__(self, seed: int | None = None) -> None:
        self._rng = np.random.default_rng(seed)

    def reset(self, seed: int | None = None) -> None:
        if seed is not None:
            self._rng = np.random.default_rng(seed)

    def choose(self, info: Info) -> int:
        if "action_mask" in info:
            valid = np.flatnonzero(np.asarray(info["action_mask"]))
        else:
            valid = np.array([int(c["slot"]) for c in _clusters(info)], dtype=np.int64)
        if len(valid) == 0:
            return 0
        return int(valid[self._rng.integers(len(valid))])


class CallablePolicy(Policy):
    """Wraps any ``obs -> action`` callable (e.g. a trained network) as a :class:`Policy`."""

    def __init__(self, fn: Callable[[Any], Any], name: str = "callable") -> None:
        self.fn = fn
        self.name = name

    def act(self, obs: Any, info: Info) -> int:
        return _as_slot(self.fn(obs))


class ModelPolicy(Policy):
    """Wraps a model with SB3's ``predict(obs, deterministic=...) -> (action, state)``."""

    def __init__(self, model: Any, name: str = "model", deterministic: bool = True) -> None:
        if not hasattr(model, "predict"):
            raise ValueError(f"model must have a predict() method, got {type(model).__name__}")
        self.model = model
        self.name = name
        self.deterministic = deterministic

    def act(self, obs: Any, info: Info) -> int:
        action, _ = self.model.predict(obs, deterministic=self.deterministic)
        return _as_slot(action)


def _as_slot(action: Any) -> int:
    value = np.asarray(action)
    if value.size != 1:
        raise ValueError(f"a policy must return one slot index, got shape {value.shape}")
    return int(value.reshape(()).item())


#: Heuristic name (as used on the command line) -> class.
POLICIES: dict[str, type[HeuristicPolicy]] = {
    "greedy-distance": GreedyDistance,
    "greedy-gain": GreedyGain,
    "cost-utility": CostUtility,
    "random": RandomValid,
}


def make_policy(name: str, seed: int | None = None) -> HeuristicPolicy:
    """A fresh heuristic by name; ``seed`` seeds the random policy (ignored by the others)."""
    if name not in POLICIES:
        raise ValueError(f"policy must be one of {list(POLICIES)}, got {name!r}")
    policy = POLICIES[name]()
    policy.reset(seed)
    return policy
