"""Does a claim discount make the single-robot map scorer a team policy?

``explorer`` was trained for one robot and sees no teammates: in a team each robot picks
alone, and robots crowd the same frontier. This study gives it the classic coordination of
Burgard et al.: the robots that must decide pick one after another (the lowest score first),
and every target already claimed (that of a robot with one valid slot, held to its target by
the commit rule or left one frontier, or a target chosen earlier in the round) adds
``discount × max(0, 1 − d / reach)`` to the score of a slot whose target lies ``d`` cells from
it. It plays validation episodes beside the team heuristics, the shipped ``team-explorer``
and ``explorer`` alone:

    python benchmarks/explorer_team_claims.py --families random-30,rooms-64 --agents 4 \\
        --variants 0.3:5,1:5,0.3:5:2,1:10,3:10 --episodes 16

A variant is ``discount:reach`` or ``discount:reach:rule_weight`` (reach in cells; the
default rule weight is the model's own).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import partial
from typing import Any

import numpy as np

from frontier_marl.evaluation.benchmark.run import (
    Contender,
    contenders,
    default_commit,
    heuristic,
)
from frontier_marl.evaluation.model_refs import ScorerMaker
from frontier_marl.experiments.explorer_studies.validation_study import run_study, study_parser
from frontier_marl.policies.base import Info
from frontier_marl.policies.map_explorer import MapExplorer
from frontier_marl.policies.models import map_scorer_folder

BASELINES = ("utility-discount", "coordinated-assignment", "team-explorer", "explorer")


class ClaimingExplorer(MapExplorer):
    """The map scorer with claimed targets discounted (the module's docstring); ties go to
    the nearer path, then the lower robot index."""

    def __init__(self, explorer: MapExplorer, discount: float, reach: float, name: str) -> None:
        if discount < 0 or reach <= 0:
            raise ValueError(f"discount must be >= 0 and reach > 0, got {discount} and {reach}")
        super().__init__(explorer.model, name, explorer.rule_weight)
        self.discount = discount
        self.reach = reach

    def act_team(
        self, observations: Mapping[str, Any], infos: Mapping[str, Info]
    ) -> dict[str, int]:
        env = self._attached()
        robots = list(env.possible_agents)
        tables = env.mdp.slot_tables()
        claimed: list[np.ndarray] = []  # a robot with one valid slot claims its target
        choices: dict[str, int] = {}
        pending: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}
        for agent, obs in observations.items():
            r = robots.index(agent)
            valid, scores = self.slot_scores(obs, r)
            if len(valid) <= 1:
                choices[agent] = int(valid[0]) if len(valid) else 0
                if len(valid):
                    claimed.append(tables[r].target[valid[0]])
            else:
                table = tables[r]
                pending[agent] = (valid, scores, table.target[valid], table.path_length[valid])
        while pending:  # the lowest discounted score of any robot still to decide goes first
            best: tuple[tuple[float, int, int], str, int] | None = None
            for agent, (_, scores, targets, lengths) in pending.items():
                total = scores + self.discount * self._crowding(targets, claimed)
                i = int(np.lexsort((lengths, total))[0])
                key = (float(total[i]), int(lengths[i]), robots.index(agent))
                if best is None or key < best[0]:
                    best = (key, agent, i)
            assert best is not None  # pending is not empty
            _, agent, i = best
            valid, _, targets, _ = pending.pop(agent)
            choices[agent] = int(valid[i])
            claimed.append(targets[i])
        return choices

    def _crowding(self, targets: np.ndarray, claimed: list[np.ndarray]) -> np.ndarray:
        """Per target, the sum over claimed targets of ``max(0, 1 − distance / reach)``."""
        out = np.zeros(len(targets))
        for target in claimed:
            distance = np.hypot(*(targets.astype(np.float64) - target).T)
            out += np.maximum(0.0, 1.0 - distance / self.reach)
        return out


Variant = tuple[float, float, float | None]


def variant_name(variant: Variant) -> str:
    """``claims-dD-rR``, with ``-wW`` where the variant sets the rule weight."""
    discount, reach, weight = variant
    return f"claims-d{discount:g}-r{reach:g}" + ("" if weight is None else f"-w{weight:g}")


def make_claiming(variant: Variant) -> ClaimingExplorer:
    """The shipped ``explorer`` with the claims of ``variant`` (picklable through
    :func:`functools.partial`)."""
    discount, reach, weight = variant
    folder = map_scorer_folder("explorer")
    if folder is None:
        raise ValueError("the shipped explorer is not a map scorer: this study needs one")
    explorer = ScorerMaker(str(folder), "explorer")()  # loaded once per process
    if weight is not None:
        explorer.rule_weight = weight
    return ClaimingExplorer(explorer, discount, reach, variant_name(variant))


def parse_variant(text: str) -> Variant:
    """``discount:reach[:rule_weight]`` (ValueError naming the variant otherwise)."""
    parts = text.split(":")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        numbers = [float(part) for part in parts]
    except ValueError:
        raise ValueError(f"variant {text!r} is not discount:reach[:rule_weight]") from None
    if not all(math.isfinite(x) and x >= 0 for x in numbers) or numbers[1] == 0:
        raise ValueError(f"variant {text!r}: discount and rule weight >= 0, reach > 0")
    return numbers[0], numbers[1], numbers[2] if len(numbers) == 3 else None


def variant_contender(variant: Variant) -> Contender:
    """The claiming explorer of ``variant`` in frontier-rule's env."""
    maker = partial(make_claiming, variant)
    return Contender(variant_name(variant), False, maker, heuristic("frontier-rule").config)


def main(argv: list[str] | None = None) -> int:
    parser = study_parser(__doc__, "random-30,rooms-64")
    parser.add_argument("--agents", type=int, default=4, help="robots per team (2 or more)")
    parser.add_argument("--variants", default="0.3:5,1:5", help="discount:reach[:rule_weight],...")
    args = parser.parse_args(argv)
    try:
        variants = [parse_variant(text) for text in args.variants.split(",")]
    except ValueError as exc:
        parser.error(str(exc))
    if len(set(variants)) < len(variants):
        parser.error(f"--variants repeats a variant: {args.variants}")
    if args.agents < 2:
        parser.error(f"--agents must be 2 or more, got {args.agents}")
    baselines = contenders(BASELINES, default_commit(args.agents))
    policies = baselines + [variant_contender(v) for v in variants]
    return run_study(parser, args, policies, agents=args.agents)
