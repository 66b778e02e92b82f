"""The map-aware team chooser: each robot that must decide takes its candidate of lowest
predicted regret, seeing its teammates.

A :class:`TeamMapExplorer` decides one robot after another
(:class:`~frontier_marl.policies.team_decider.SequentialTeamDecider`); a deciding robot's
candidates are scored by a :class:`~frontier_marl.policies.networks.map_scorer.MapScorer` of
the team's crops (:func:`~frontier_marl.policies.map_crops.slot_crops` with the teammates'
channels: their cells, their targets, kept or just chosen, and the path length from the
nearest of them) and the slot features of
:data:`~frontier_marl.policies.map_explorer.TEAM_MAP_EXPLORER_SETTINGS` (frontier-rule's, with
three teammate features per slot). The scorer is fitted to each candidate's makespan to go on
the true map (:mod:`frontier_marl.training.team_cost_to_go`). Saved like the single-robot map
scorer (:func:`~frontier_marl.policies.map_explorer.save_map_explorer`, ``"team": true`` in its
shape); loading needs torch only.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch

from frontier_marl.core.slots import SlotTable
from frontier_marl.policies.linear_scorer import explorer_slots, feature_names
from frontier_marl.policies.map_crops import slot_crops
from frontier_marl.policies.networks.map_scorer import MapScorer
from frontier_marl.policies.team_decider import SequentialTeamDecider


class TeamMapExplorer(SequentialTeamDecider):
    """The candidate of lowest predicted regret (ties: the lower slot) for each robot that must
    decide (the module's docstring)."""

    deterministic = True

    def __init__(self, model: MapScorer, name: str = "team-map-explorer") -> None:
        super().__init__()
        self.model = model
        self.name = name

    def attach(self, env: Any) -> None:
        expected = self.model.feature_mean.numel()
        names = feature_names(getattr(env, "unwrapped", env).config)
        if len(names) != expected:
            raise ValueError(
                f"{self.name} reads {expected} slot features; the env gives {len(names)}: "
                "run it with its env settings"
            )
        super().attach(env)

    def pick(
        self, robot: int, obs: Any, table: SlotTable, candidates: np.ndarray, goals: np.ndarray
    ) -> int:
        return int(candidates[int(np.argmin(self.regrets(robot, obs, candidates, goals)))])

    def regrets(
        self, robot: int, obs: Any, candidates: np.ndarray, goals: np.ndarray
    ) -> np.ndarray:
        """The predicted regret of each of ``candidates`` (slot indices) of ``robot``, given
        every robot's target so far (``goals``, K x 2, row -1: none)."""
        crops = slot_crops(self._attached(), candidates, robot, goals)
        slots, _ = explorer_slots(obs)
        features = torch.as_tensor(slots[candidates], dtype=torch.float32)[None]
        mask = torch.ones((1, len(candidates)), dtype=torch.bool)
        with torch.no_grad():
            return self.model(torch.as_tensor(crops), features, mask)[0].numpy()
