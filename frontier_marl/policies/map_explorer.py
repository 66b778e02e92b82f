"""The map-aware learned chooser: among the valid slots, the one of lowest predicted regret.

A :class:`MapExplorer` builds each valid slot's map crops from the env's belief
(:mod:`~frontier_marl.policies.map_crops`), reads its explorer slot features from the
observation, and asks a :class:`~frontier_marl.policies.networks.map_scorer.MapScorer` for
each candidate's relative regret (its expected cost-to-go over the cheapest candidate's, as
learned from true-map rollouts, :mod:`frontier_marl.training.cost_to_go`). It runs with the
observation settings of ``frontier-rule`` (:data:`MAP_EXPLORER_SETTINGS`: the same 12 slots
and features) and keeps a target until it reaches it.

Saved as a folder: ``model.pt`` (the scorer's weights) and ``model.json`` (``"format":
"map-scorer"``, the scorer's shape, the env settings it reads, how it was trained). Loading
needs torch and no training library.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import torch

from frontier_marl.policies.base import Info, Policy
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_SETTINGS, FRONTIER_RULE_WEIGHTS
from frontier_marl.policies.linear_scorer import explorer_slots, feature_names, weight_vector
from frontier_marl.policies.map_crops import crop_shape, slot_crops
from frontier_marl.policies.models import MAP_SCORER_FILE, MAP_SCORER_FORMAT, map_scorer_folder
from frontier_marl.policies.networks.map_scorer import MapScorer

METADATA_FILE = "model.json"
MAP_EXPLORER_SETTINGS: dict[str, Any] = dict(FRONTIER_RULE_SETTINGS)


#: The env settings of a team's map scorer: frontier-rule's slots and features with the three
#: teammate features per slot, every live slot offered each step (the policy keeps targets).
TEAM_MAP_EXPLORER_SETTINGS: dict[str, Any] = {
    **MAP_EXPLORER_SETTINGS,
    "teammates": "positions+targets",
    "commit": "none",
}


def new_scorer(n_features: int, width: int = 32, members: int = 1, team: bool = False) -> MapScorer:
    """A fresh scorer of the crops of :func:`~frontier_marl.policies.map_crops.crop_shape`
    (``team``: with the teammates' channels)."""
    channels, side, _ = crop_shape(team)
    return MapScorer(channels, side, n_features, width, members)


def is_team_scorer(model: MapScorer) -> bool:
    """Whether ``model`` reads a team's crops (the teammates' channels)."""
    return model.channels == crop_shape(team=True)[0]


def save_map_explorer(model: MapScorer, folder: Path, metadata: dict[str, Any]) -> None:
    """``folder/model.pt`` and ``folder/model.json`` (``metadata`` plus the scorer's shape
    and the env settings it reads)."""
    folder.mkdir(parents=True, exist_ok=True)
    torch.save(model.state_dict(), folder / MAP_SCORER_FILE)
    team = is_team_scorer(model)
    shape = {
        "n_features": model.feature_mean.numel(),
        "width": model.width,
        "members": model.members,
        "team": team,
    }
    settings = TEAM_MAP_EXPLORER_SETTINGS if team else MAP_EXPLORER_SETTINGS
    record = {"format": MAP_SCORER_FORMAT, "scorer": shape, "env_settings": settings}
    (folder / METADATA_FILE).write_text(json.dumps({**record, **metadata}, indent=2) + "\n")


def load_scorer(folder: str | Path) -> tuple[MapScorer, dict[str, Any]]:
    """The scorer saved in ``folder`` (or shipped under that name, e.g. ``explorer``) and
    its metadata; ValueError naming a damaged or missing file."""
    folder = map_scorer_folder(folder) or Path(folder)
    try:
        metadata = json.loads((folder / METADATA_FILE).read_text())
        shape = metadata["scorer"]
        members = int(shape.get("members", 1))  # saved before 2026-12-07: one member
        team = bool(shape.get("team", False))
        model = new_scorer(int(shape["n_features"]), int(shape["width"]), members, team)
        model.load_state_dict(torch.load(folder / MAP_SCORER_FILE, map_location="cpu"))
    except (OSError, ValueError, KeyError, RuntimeError) as error:
        raise ValueError(f"cannot load the map explorer in {folder}: {error}") from error
    model.eval()
    return model, metadata


def team_scorer_folder(name: str | Path) -> Path | None:
    """The folder of the team scorer saved at (or shipped as) ``name``; None where there is
    none, or the scorer there is a single robot's."""
    folder = map_scorer_folder(name)
    if folder is None or not load_scorer(folder)[1]["scorer"].get("team", False):
        return None
    return folder


class MapExplorer(Policy):
    """The valid slot of lowest ``predicted regret + rule_weight * rule margin``, where a
    slot's rule margin is how far frontier-rule's score of it falls below the best slot's
    (0 for the rule's own choice): ``rule_weight`` 0 is the scorer alone, a large one the
    rule, between them the scorer overrules the rule only where it predicts a clear gain.
    In a team each robot decides alone, from its own slots and the crops around them (the
    scorer was trained for one robot and sees no teammates)."""

    deterministic = True

    def __init__(self, model: MapScorer, name: str = "explorer", rule_weight: float = 0.0) -> None:
        self.model = model
        self.name = name
        self.rule_weight = float(rule_weight)
        self._env: Any = None
        self._rule: np.ndarray | None = None

    @classmethod
    def load(cls, folder: Path, name: str = "explorer") -> MapExplorer:
        model, metadata = load_scorer(folder)
        return cls(model, name, float(metadata.get("rule_weight", 0.0)))

    def attach(self, env: Any) -> None:
        expected = self.model.feature_mean.numel()
        if len(feature_names(env.config)) != expected:
            raise ValueError(
                f"{self.name} reads {expected} slot features; the env gives "
                f"{len(feature_names(env.config))}: run it with its env settings"
            )
        self._env = env
        names = feature_names(env.config)
        self._rule = weight_vector(FRONTIER_RULE_WEIGHTS, names, "frontier-rule")

    def act(self, obs: Any, info: Info) -> int:
        return self._choose(obs, 0)

    def act_team(
        self, observations: Mapping[str, Any], infos: Mapping[str, Info]
    ) -> dict[str, int]:
        robots = self._attached().possible_agents
        return {
            agent: self._choose(obs, robots.index(agent)) for agent, obs in observations.items()
        }

    def _attached(self) -> Any:
        if self._env is None:
            raise RuntimeError(f"{self.name} needs attach(env) before it acts")
        return self._env

    def slot_scores(self, obs: Any, robot: int) -> tuple[np.ndarray, np.ndarray]:
        """The valid slots of ``robot``'s observation (its index in the env's agents) and
        the score the explorer takes the least of among them (predicted regret plus
        ``rule_weight`` times the rule margin); all zero where one slot or none is valid."""
        env = self._attached()
        slots, mask = explorer_slots(obs)
        valid = np.flatnonzero(mask > 0)
        if len(valid) <= 1:
            return valid, np.zeros(len(valid))
        crops = slot_crops(env, valid, robot)
        features = torch.as_tensor(slots[valid], dtype=torch.float32)[None]
        mask = torch.ones((1, len(valid)), dtype=torch.bool)
        with torch.no_grad():
            regret = self.model(torch.as_tensor(crops), features, mask)[0].numpy()
        regret = regret.astype(np.float64)
        if self.rule_weight:
            rule = slots[valid].astype(np.float64) @ self._rule
            regret = regret + self.rule_weight * (rule.max() - rule)
        return valid, regret

    def _choose(self, obs: Any, robot: int) -> int:
        """The slot ``robot`` (its index in the env's agents) takes, given its observation."""
        valid, scores = self.slot_scores(obs, robot)
        return int(valid[int(np.argmin(scores))]) if len(valid) else 0
