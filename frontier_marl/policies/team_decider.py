"""Deciding for a team one robot after another: the protocol of the team lookahead oracle and
of the map-aware team explorer.

A :class:`SequentialTeamDecider` keeps each robot's target while its slot table still offers
it (the target is not reached and still a frontier cell), unless the robot has stood still
short of it for :data:`~frontier_marl.sim.team_rollouts.BLOCKED_STEPS` steps (a teammate in
its way). Every other robot with two or more live slots decides, in robot order, among its
live slots other than its previous target, seeing the targets of the robots that kept theirs
and of those that decided before it: :meth:`SequentialTeamDecider.pick` is what a subclass
gives. It runs in an env whose ``commit`` is ``"none"`` (the env offers every live slot each
step; the keeping is the decider's).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from frontier_marl.core.slots import SlotTable
from frontier_marl.policies.base import Info, Policy, previous_target_slot, slot_table, target_cell
from frontier_marl.sim.team_rollouts import BLOCKED_STEPS


class SequentialTeamDecider(Policy):
    """The protocol of the module's docstring; subclasses give :meth:`pick`."""

    def __init__(self) -> None:
        self._env: Any = None
        self._positions: np.ndarray | None = None  # the robots' cells at the last decision
        self._waits = np.zeros(0, dtype=np.int64)

    def reset(self, seed: int | None = None) -> None:
        self._positions = None

    def attach(self, env: Any) -> None:
        self._env = getattr(env, "unwrapped", env)

    def _attached(self) -> Any:
        if self._env is None:
            raise RuntimeError(f"{self.name} needs attach(env) before it acts")
        return self._env

    def act(self, obs: Any, info: Info) -> int:
        return self.act_team({"robot_0": obs}, {"robot_0": info})["robot_0"]

    def act_team(
        self, observations: Mapping[str, Any], infos: Mapping[str, Info]
    ) -> dict[str, int]:
        env = self._attached()
        robots = list(getattr(env, "possible_agents", ["robot_0"]))
        self._count_waits(env.world.positions, env.mdp.steps, infos, robots)
        goals = np.full((len(robots), 2), -1, dtype=np.int64)
        choices: dict[str, int] = {}
        deciding: list[tuple[str, int | None]] = []  # and the slot of its previous target
        for agent in observations:
            robot = robots.index(agent)
            kept = previous_target_slot(infos[agent])
            table = slot_table(infos[agent])
            if table.live <= 1 or (kept is not None and self._waits[robot] < BLOCKED_STEPS):
                choices[agent] = 0 if kept is None else kept
                if table.live:
                    goals[robot] = table.target[choices[agent]]
            else:
                deciding.append((agent, kept))
        for agent, previous in deciding:
            robot = robots.index(agent)
            self._waits[robot] = 0
            table = slot_table(infos[agent])
            candidates = np.array([s for s in range(table.live) if s != previous])
            choices[agent] = int(self.pick(robot, observations[agent], table, candidates, goals))
            goals[robot] = table.target[choices[agent]]
        return choices

    def pick(
        self, robot: int, obs: Any, table: SlotTable, candidates: np.ndarray, goals: np.ndarray
    ) -> int:
        """The slot ``robot`` takes among ``candidates`` (two or more live slot indices of its
        ``table``), given ``goals`` (K, 2): the targets kept or chosen so far this step (row
        -1: none yet)."""
        raise NotImplementedError

    def _count_waits(
        self, positions: np.ndarray, steps: int, infos: Mapping[str, Info], robots: list[str]
    ) -> None:
        """Count, per robot, the steps in a row it stood still short of its target."""
        if self._positions is None or steps == 0 or len(self._waits) != len(robots):
            self._waits = np.zeros(len(robots), dtype=np.int64)
        else:
            for agent, info in infos.items():
                robot = robots.index(agent)
                target = target_cell(info.get("target"))
                cell = (int(positions[robot, 0]), int(positions[robot, 1]))
                still = cell == (int(self._positions[robot, 0]), int(self._positions[robot, 1]))
                blocked = target is not None and still and cell != target
                self._waits[robot] = self._waits[robot] + 1 if blocked else 0
        self._positions = np.array(positions, copy=True)
