"""Joint heuristics: one decision for the whole team from every robot's slot table.

The joint heuristics decide for the whole team at once (:meth:`Policy.act_team`). They read
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

Both take ``commit`` as the single-robot heuristics do: with ``until-progress``, after a step in
which no robot revealed a cell, every robot whose previous target is still offered keeps it,
and the others are decided jointly among the remaining clusters; with ``on-cycle``, every robot
that stands again on a cell it stood on since any robot last revealed a cell keeps its target
until one does.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy.optimize import linear_sum_assignment

from frontier_marl.policies.base import (
    CycleWatch,
    Info,
    Policy,
    check_commit,
    previous_target_slot,
    slot_table,
)


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

    def __init__(self, commit: str = "none") -> None:
        self._config: Any = None
        self.commit = check_commit(commit)
        self._watch = CycleWatch()

    def reset(self, seed: int | None = None) -> None:
        self._watch.clear()

    def attach(self, env: Any) -> None:
        self._config = getattr(getattr(env, "unwrapped", env), "config", None)

    @staticmethod
    def options(infos: Sequence[Info]) -> list[list[_Option]]:
        """Per robot (in the given order), its live clusters with their path lengths."""
        out = []
        for agent, info in enumerate(infos):
            table = slot_table(info)
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
        team = [infos[agent] for agent in agents]
        options = self.options(team)
        kept: list[int | None] = [None] * len(team)
        if self.commit == "until-reached" or (
            self.commit == "until-progress" and not any(info["new_cells"] for info in team)
        ):
            kept = [previous_target_slot(info) for info in team]
        elif self.commit == "on-cycle":
            progressed = any(info["new_cells"] for info in team)
            kept = [
                self._watch.kept(agent, info, progressed)
                for agent, info in zip(agents, team, strict=True)
            ]
        chosen = self._choose_around(options, kept)
        return {
            agent: (0 if pick is None else pick.slot)
            for agent, pick in zip(agents, chosen, strict=True)
        }

    def _choose_around(
        self, options: list[list[_Option]], kept: list[int | None]
    ) -> list[_Option | None]:
        """:meth:`choose_team` for the robots without a kept slot, the kept robots' clusters
        taken out of their options (unless that leaves a robot nothing)."""
        if all(slot is None for slot in kept):
            return self.choose_team(options)
        fixed = {i: options[i][slot] for i, slot in enumerate(kept) if slot is not None}
        taken = {o.cluster for o in fixed.values()}
        free = [i for i in range(len(options)) if i not in fixed]
        rest = [
            [
                _Option(j, o.cluster, o.slot, o.length, o.target)  # numbered within ``rest``
                for o in ([o for o in options[i] if o.cluster not in taken] or options[i])
            ]
            for j, i in enumerate(free)
        ]
        chosen: list[_Option | None] = [None] * len(options)
        for i, pick in zip(free, self.choose_team(rest) if free else [], strict=True):
            chosen[i] = pick
        for i, pick in fixed.items():
            chosen[i] = pick
        return chosen

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

    def __init__(
        self, beta: float = 1.0, sensor_range: float | None = None, commit: str = "none"
    ) -> None:
        super().__init__(commit)
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
