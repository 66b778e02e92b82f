"""The team map scorer as a correction to ``team-explorer``'s Q-values.

The shipped ``team-explorer`` (a DQN slot scorer) plays inside the sequential team protocol
(:class:`~frontier_marl.policies.team_decider.SequentialTeamDecider`, that of the team oracle
and of the team map scorer): each deciding robot ranks its candidates by ``weight`` times
team-explorer's Q margin (its best candidate's Q-value less the candidate's) plus the team map
scorer's predicted regret. Without ``--scorer`` it is team-explorer's Q alone in that
protocol (``team-explorer-q``); a large weight gives the same choices, weight 0 the scorer
alone. It plays validation episodes beside the team heuristics and the shipped
``team-explorer``::

    python benchmarks/team_anchor.py --scorer runs/team-map --weights 0,0.1,1,10 \\
        --families random-30,rooms-64 --agents 4 --episodes 16

The scorer's labels can come from the states this policy visits: ``team_map_scorer.py
--learner team-explorer`` labels with team-explorer's Q taking the decisions the oracle does
not.
"""

from __future__ import annotations

import math
from functools import partial
from typing import Any

import numpy as np
import torch

from frontier_marl.core.slots import SlotTable
from frontier_marl.evaluation.benchmark.contenders import (
    Contender,
    contenders,
    default_commit,
    loaded_model,
    own_world,
)
from frontier_marl.evaluation.model_refs import cached_scorer
from frontier_marl.experiments.explorer_studies.validation_study import run_study, study_parser
from frontier_marl.policies.linear_scorer import explorer_slots, feature_names
from frontier_marl.policies.map_explorer import TEAM_MAP_EXPLORER_SETTINGS, team_scorer_folder
from frontier_marl.policies.team_decider import SequentialTeamDecider
from frontier_marl.policies.team_map_explorer import TeamMapExplorer

BASELINES = ("utility-discount", "coordinated-assignment", "team-explorer")
ANCHOR = "team-explorer"  # the shipped model whose Q-values anchor the choice


class AnchoredTeamExplorer(SequentialTeamDecider):
    """Each deciding robot's candidate of least ``weight × Q margin + predicted regret`` (the
    module's docstring); without a scorer, of greatest Q. Runs in the env settings of a team's
    map scorer (:data:`TEAM_MAP_EXPLORER_SETTINGS`), whose slot features hold
    team-explorer's."""

    deterministic = True

    def __init__(
        self, scorer: str | None = None, weight: float = 0.0, name: str = "team-explorer-q"
    ) -> None:
        super().__init__()
        if not (math.isfinite(weight) and weight >= 0):
            raise ValueError(f"the Q margin's weight must be a number >= 0, got {weight}")
        loaded = loaded_model(ANCHOR)
        self.q_network = loaded.model.q_net
        self.anchor_features = feature_names(loaded.env_config())
        self.scorer = None if scorer is None else TeamMapExplorer(cached_scorer(scorer)[0])
        self.weight = weight
        self.name = name
        self._columns: list[int] = []

    def attach(self, env: Any) -> None:
        super().attach(env)
        names = feature_names(self._attached().config)
        missing = sorted(set(self.anchor_features) - set(names))
        if missing:
            raise ValueError(f"{self.name}: the env's slot features lack {ANCHOR}'s {missing}")
        self._columns = [names.index(name) for name in self.anchor_features]
        if self.scorer is not None:
            self.scorer.attach(env)

    def q_values(self, obs: Any) -> np.ndarray:
        """team-explorer's Q-value of every slot of ``obs``."""
        slots, mask = explorer_slots(obs)
        observation = {
            "slots": torch.as_tensor(slots[:, self._columns], dtype=torch.float32)[None],
            "action_mask": torch.as_tensor(mask, dtype=torch.float32)[None],
        }
        with torch.no_grad():
            return self.q_network(observation)[0].numpy().astype(np.float64)

    def pick(
        self, robot: int, obs: Any, table: SlotTable, candidates: np.ndarray, goals: np.ndarray
    ) -> int:
        q = self.q_values(obs)[candidates]
        score = q.max() - q
        if self.scorer is not None:
            regret = self.scorer.regrets(robot, obs, candidates, goals).astype(np.float64)
            score = self.weight * score + regret
        return int(candidates[int(np.argmin(score))])


def anchored(scorer: str | None, weight: float) -> Contender:
    """The contender of :class:`AnchoredTeamExplorer` (``scorer`` a team scorer's folder)."""
    name = "team-explorer-q" if scorer is None else f"anchored-w{weight:g}"
    make = partial(AnchoredTeamExplorer, scorer, weight, name)
    return Contender(name, False, make, partial(own_world, TEAM_MAP_EXPLORER_SETTINGS))


def main(argv: list[str] | None = None) -> int:
    parser = study_parser(__doc__, "random-30,rooms-64")
    parser.add_argument("--agents", type=int, default=4, help="robots per team (2 or more)")
    parser.add_argument("--scorer", default=None, help="a team map scorer's folder")
    parser.add_argument("--weights", default="0.1,1,10", help="weights of the Q margin")
    args = parser.parse_args(argv)
    if args.agents < 2:
        parser.error(f"--agents must be 2 or more, got {args.agents}")
    policies = contenders(BASELINES, default_commit(args.agents)) + [anchored(None, 0.0)]
    if args.scorer is not None:
        folder = team_scorer_folder(args.scorer)
        if folder is None:
            parser.error(f"--scorer {args.scorer}: no saved team scorer there")
        try:
            weights = [float(text) for text in args.weights.split(",")]
        except ValueError:
            parser.error(f"--weights must be numbers, got {args.weights!r}")
        if not all(math.isfinite(w) and w >= 0 for w in weights) or len(set(weights)) < len(
            weights
        ):
            parser.error(f"--weights must be distinct numbers >= 0, got {args.weights!r}")
        policies += [anchored(str(folder.resolve()), weight) for weight in weights]
    return run_study(parser, args, policies, agents=args.agents)
