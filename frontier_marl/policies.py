"""Frontier-selection policies behind one interface: heuristics, and adapters for learned models.

A :class:`Policy` picks one cluster slot per robot. It works with the single-robot Gymnasium
env (:meth:`Policy.act`) and with every robot of the PettingZoo ParallelEnv
(:meth:`Policy.act_team`)::

    policy = make_policy("greedy-distance")
    policy.reset(seed=0)
    obs, infos = par_env.reset(seed=0)
    actions = policy.act_team(obs, infos)          # {"robot_0": slot, ...}

The heuristics read only a robot's step info: its typed slot table ``info["slots"]`` (cluster,
target, Euclidean centroid ``distance``, known-free ``path_length``, size and ``gain`` per
slot; see :class:`~frontier_marl.core.slots.SlotTable`) and ``action_mask``, never hidden env
state:

* ``greedy-distance``: the nearest cluster (smallest Euclidean centroid ``distance``; ties:
  lowest slot).
* ``greedy-gain``: the largest information ``gain`` (ties: nearest, then lowest slot).
* ``cost-utility``: the largest ``gain / path length``, the path length being the 4-connected
  shortest path (what A* returns) from the robot to the cluster's target over the known-free
  cells of the belief (a length of 0 counts as 1). Ties: nearest, then lowest slot.
* ``random``: uniform over the valid slots of ``action_mask``, from its own seeded generator.
* ``first-slot``: always slot 0, the thesis's degenerate policy as a baseline (greedy distance
  when slots are sorted; the top-most of the selected clusters when unsorted).

Two *joint* heuristics decide for the whole team at once (:meth:`Policy.act_team`). They read
each robot's slot table. Clusters are matched across robots by their ``cluster`` index, which
is the same for every robot because the belief is shared. Path costs are the slots' known-free
path lengths.

* ``coordinated-assignment``: an optimal assignment of robots to distinct clusters
  (``scipy.optimize.linear_sum_assignment`` on the robots x clusters path-cost matrix, a robot
  being able to take only the clusters in its own slots). Among all assignments it first
  maximises the number of robots that get a cluster of their own (pairs a robot cannot take
  cost more than every feasible assignment together), then minimises the summed path length.
  A robot left without a cluster (the team has more robots than distinct clusters it can
  reach) takes its nearest cluster by path: a duplicate, but only where every cluster it
  could take is already taken. With one robot: its nearest cluster by path length.
* ``utility-discount``: the coordination of Burgard et al. (2005, IEEE T-RO 21(3)). Every
  cluster's target t starts with utility ``U_t = 1``; the cost of robot i for t is its path
  length normalised by the largest path length of any robot to any of its clusters,
  ``V_it = L_it / max L`` (in [0, 1]). Robots are served one at a time: the pair (i, t) with
  the largest ``U_t - beta * V_it`` (over robots still without a target and their own slots;
  ties: smaller path, then agent order, then slot) is fixed, then every target t' loses
  ``P(||t - t'||)`` of its utility, ``P(d) = max(0, 1 - d / r)`` (a linear visibility
  probability, Euclidean distance between target cells, ``r`` the sensor range: the env's
  ``perception_range``, read by :meth:`Policy.attach`, or ``sensor_range=``). ``beta = 1``. A
  claimed target drops to utility 0 for the others, so duplicates are discouraged but not
  forbidden. With one robot: its nearest cluster by path length, as ``coordinated-assignment``.

With no live cluster every heuristic returns slot 0 (the env's idle action).

Learned models plug in through :class:`CallablePolicy` (any ``obs -> action`` callable) or
:class:`ModelPolicy` (anything with SB3's ``predict(obs, deterministic=...)``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from frontier_marl.core.slots import SlotTable

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


def _slots(info: Info) -> SlotTable:
    try:
        return info["slots"]
    except (KeyError, TypeError) as exc:
        raise ValueError(
            "info must hold the robot's 'slots' table (the env's step info with info='full')"
        ) from exc


def _first(*keys: np.ndarray) -> int:
    """The index that sorts first by ``keys`` (the first key most significant; ties: lowest)."""
    return int(np.lexsort((np.arange(len(keys[0])), *reversed(keys)))[0])


class GreedyDistance(HeuristicPolicy):
    """Nearest cluster: smallest centroid distance; ties go to the lowest slot."""

    name = "greedy-distance"

    def choose(self, info: Info) -> int:
        table = _slots(info)
        if not table.live:
            return 0
        return int(np.argmin(table.distance[: table.live]))


class GreedyGain(HeuristicPolicy):
    """Largest information gain; ties go to the nearest, then the lowest slot."""

    name = "greedy-gain"

    def choose(self, info: Info) -> int:
        table = _slots(info)
        if not table.live:
            return 0
        live = table.live
        return _first(-table.gain[:live], table.distance[:live])


class FirstSlot(HeuristicPolicy):
    """Always slot 0, the thesis's degenerate "reward hacking" policy as a baseline.

    With distance-sorted slots this is greedy distance; unsorted (the default), slot 0 is the
    first of the selected clusters in raster order, i.e. the top-most of the nearest ones.
    """

    name = "first-slot"

    def choose(self, info: Info) -> int:
        return 0


class CostUtility(HeuristicPolicy):
    """Largest ``gain / path length`` (known-free path; a length of 0 counts as 1); ties go to
    the nearest, then the lowest slot."""

    name = "cost-utility"

    @staticmethod
    def utilities(table: SlotTable) -> np.ndarray:
        """``gain / max(path length, 1)`` of each live slot."""
        live = table.live
        return table.gain[:live] / np.maximum(table.path_length[:live], 1)

    def choose(self, info: Info) -> int:
        table = _slots(info)
        if not table.live:
            return 0
        return _first(-self.utilities(table), table.distance[: table.live])


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
        valid = np.flatnonzero(np.asarray(info["action_mask"]))
        if len(valid) == 0:
            return 0
        return int(valid[self._rng.integers(len(valid))])


class _Option:
    """One (robot, cluster) pair a joint heuristic may choose."""

    __slots__ = ("agent", "cluster", "slot", "length", "target")

    def __init__(
        self, agent: int, cluster: int, slot: int, length: int, target: tuple[int, int]
    ) -> None:
        self.agent, self.cluster, self.slot = agent, cluster, slot
        self.length, self.target = length, target


class TeamHeuristic(Policy):
    """Base of the joint heuristics: robots x clusters path lengths from the slot tables.

    :meth:`act` treats one robot as a team of one.
    """

    def __init__(self) -> None:
        self._config: Any = None

    def attach(self, env: Any) -> None:
        self._config = getattr(getattr(env, "unwrapped", env), "config", None)

    @staticmethod
    def options(infos: Sequence[Info]) -> list[list[_Option]]:
        """Per robot (in the given order), its live clusters with their path lengths."""
        out = []
        for agent, info in enumerate(infos):
            table = _slots(info)
            live = table.live
            rows = zip(
                table.cluster[:live].tolist(),
                table.path_length[:live].tolist(),
                table.target[:live].tolist(),
                strict=True,
            )
            out.append(
                [
                    _Option(agent, cluster, slot, length, (row, col))
                    for slot, (cluster, length, (row, col)) in enumerate(rows)
                ]
            )
        return out

    def act(self, obs: Any, info: Info) -> int:
        return self.act_team({"robot_0": obs}, {"robot_0": info})["robot_0"]

    def act_team(
        self, observations: Mapping[str, Any], infos: Mapping[str, Info]
    ) -> dict[str, int]:
        agents = list(observations)
        options = self.options([infos[agent] for agent in agents])
        chosen = self.choose_team(options)
        return {
            agent: (0 if pick is None else pick.slot)
            for agent, pick in zip(agents, chosen, strict=True)
        }

    def choose_team(self, options: list[list[_Option]]) -> list[_Option | None]:
        """One option (or ``None``: idle on slot 0) per robot."""
        raise NotImplementedError


def _nearest(options: Sequence[_Option]) -> _Option | None:
    """The option with the shortest path (ties: lowest slot)."""
    return min(options, key=lambda o: (o.length, o.slot), default=None)


class CoordinatedAssignment(TeamHeuristic):
    """Robots to distinct clusters by ``linear_sum_assignment`` on path lengths (see the
    module docstring for the rule)."""

    name = "coordinated-assignment"

    def choose_team(self, options: list[list[_Option]]) -> list[_Option | None]:
        from scipy.optimize import linear_sum_assignment

        n = len(options)
        if n == 1:
            return [_nearest(options[0])]
        clusters = sorted({o.cluster for mine in options for o in mine})
        if not clusters:
            return [None] * n
        column = {cluster: j for j, cluster in enumerate(clusters)}
        lengths = [o.length for mine in options for o in mine]
        # A pair a robot cannot take costs more than any whole feasible assignment, so the
        # solver first maximises the number of feasible pairs, then minimises their sum.
        forbidden = float(sum(lengths) + 1)
        cost = np.full((n, len(clusters)), forbidden)
        by_pair: dict[tuple[int, int], _Option] = {}
        for agent, mine in enumerate(options):
            for o in mine:
                j = column[o.cluster]
                if o.length < cost[agent, j]:
                    cost[agent, j] = o.length
                    by_pair[(agent, j)] = o
        rows, cols = linear_sum_assignment(cost)
        chosen: list[_Option | None] = [None] * n
        for agent, j in zip(rows.tolist(), cols.tolist(), strict=True):
            chosen[agent] = by_pair.get((agent, j))
        for agent in range(n):
            if chosen[agent] is None:  # every cluster it can reach is taken: share the nearest
                chosen[agent] = _nearest(options[agent])
        return chosen


class UtilityDiscount(TeamHeuristic):
    """Burgard et al. (2005): sequential choice of ``argmax U_t - beta * V_it``, each claimed
    target discounting the utility of the targets within sensor range of it (see the module
    docstring for the formula).

    Args:
        beta: weight of the normalised path cost against the utility (Burgard's beta).
        sensor_range: ``r`` of the visibility probability; ``None`` takes the attached env's
            ``perception_range``.
    """

    name = "utility-discount"

    def __init__(self, beta: float = 1.0, sensor_range: float | None = None) -> None:
        super().__init__()
        if not np.isfinite(beta) or beta < 0:
            raise ValueError(f"beta must be a finite number >= 0, got {beta!r}")
        if sensor_range is not None and not (np.isfinite(sensor_range) and sensor_range > 0):
            raise ValueError(f"sensor_range must be a number > 0 or None, got {sensor_range!r}")
        self.beta = float(beta)
        self.sensor_range = sensor_range

    def _range(self) -> float:
        if self.sensor_range is not None:
            return float(self.sensor_range)
        if self._config is not None:
            return float(self._config.perception_range)
        raise ValueError(
            "utility-discount needs a sensor range: pass sensor_range= or attach(env) first"
        )

    @staticmethod
    def visibility(distance: np.ndarray | float, sensor_range: float) -> np.ndarray:
        """``P(d) = max(0, 1 - d / r)``: the share of a target's utility removed by a claim
        at distance ``d``."""
        return np.clip(1.0 - np.asarray(distance, dtype=float) / sensor_range, 0.0, None)

    def choose_team(self, options: list[list[_Option]]) -> list[_Option | None]:
        n = len(options)
        flat = [o for mine in options for o in mine]
        chosen: list[_Option | None] = [None] * n
        if not flat:
            return chosen
        if n == 1:
            return [_nearest(options[0])]
        sensor_range = self._range()
        scale = float(max(max(o.length for o in flat), 1))
        targets: dict[int, tuple[int, int]] = {o.cluster: o.target for o in flat}
        utility = dict.fromkeys(targets, 1.0)
        waiting = {agent for agent in range(n) if options[agent]}
        while waiting:
            best = max(
                (o for agent in waiting for o in options[agent]),
                key=lambda o: (
                    utility[o.cluster] - self.beta * o.length / scale,
                    -o.length,
                    -o.agent,
                    -o.slot,
                ),
            )
            chosen[best.agent] = best
            waiting.discard(best.agent)
            claimed = np.asarray(best.target, dtype=float)
            for cluster, target in targets.items():
                distance = float(np.hypot(*(np.asarray(target, dtype=float) - claimed)))
                utility[cluster] -= float(self.visibility(distance, sensor_range))
        return chosen


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
POLICIES: dict[str, type[Policy]] = {
    "greedy-distance": GreedyDistance,
    "greedy-gain": GreedyGain,
    "cost-utility": CostUtility,
    "random": RandomValid,
    "first-slot": FirstSlot,
    "coordinated-assignment": CoordinatedAssignment,
    "utility-discount": UtilityDiscount,
}

#: The heuristics that decide for the whole team jointly.
TEAM_POLICIES: tuple[str, ...] = ("coordinated-assignment", "utility-discount")


def make_policy(name: str, seed: int | None = None) -> Policy:
    """A fresh heuristic by name; ``seed`` seeds the random policy (ignored by the others)."""
    if name not in POLICIES:
        raise ValueError(f"policy must be one of {list(POLICIES)}, got {name!r}")
    policy = POLICIES[name]()
    policy.reset(seed)
    return policy
