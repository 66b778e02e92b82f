"""How much of the true-map oracle's gain does the belief hold? A lookahead on sampled maps.

The true-map oracle (``oracle-np-12``, :mod:`.headroom`) knows the unknown. This study's
planner does not: at each decision it draws ``K`` maps from the family's own generator, keeps
every cell the robot knows (so each draw is a completion of the belief, though not one drawn
from the exact posterior: outside the known cells the draw ignores them), simulates each of
frontier-rule's valid slots on every completion with nearest-path finishing, and takes the
slot of least mean cost. As K grows this is a one-step Bayesian rollout under a prior of the
family's maps. If it gains much over frontier-rule, the belief and a prior of the family hold
the information a learned scorer should extract; if it gains little, the oracle's headroom
lies mostly in what no belief shows.

    python benchmarks/explorer_completions.py --families random-20,random-30,rooms-32 \\
        --samples 1,8 --episodes 16

``--match R`` draws ``R × K`` maps and keeps the ``K`` that agree most with the belief on the
known cells within ``--band`` cells of the unknown (a crude approximate-Bayesian filter: draws
whose walls continue the ones the robot sees near its frontiers are kept).

Validation episodes only. It reads the generator of the env's family, so it refuses loaded or
static maps (a draw would be the true map).
"""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np
from scipy import ndimage

from frontier_marl.core.grid import OCCUPIED, UNKNOWN
from frontier_marl.evaluation.benchmark.run import Contender, heuristic
from frontier_marl.experiments.explorer_studies.validation_study import run_study, study_parser
from frontier_marl.policies.base import HeuristicPolicy, Info, first_by, slot_table
from frontier_marl.policies.lookahead import (
    LookaheadOracle,
    completion_costs,
    completion_draws,
    require_generated_maps,
)
from frontier_marl.sim.episodes import EpisodeSource


class CompletionLookahead(HeuristicPolicy):
    """The live slot of least :func:`~frontier_marl.policies.lookahead.completion_costs` over
    ``samples`` maps drawn from the env's own generator
    (:func:`~frontier_marl.policies.lookahead.completion_draws`; ties: nearest path, then
    nearest centroid), kept until reached."""

    def __init__(self, samples: int, seed: int = 0, match: int = 1, band: int = 3) -> None:
        super().__init__("until-reached")
        if samples < 1 or match < 1 or band < 1:
            raise ValueError(
                f"samples, match and band must be >= 1, got {samples}, {match} and {band}"
            )
        self.samples = samples
        self.seed = seed
        self.match = match
        self.band = band
        self.name = completions_name(samples, match, band)
        self._env: Any = None
        self._source: EpisodeSource | None = None

    def attach(self, env: Any) -> None:
        require_generated_maps(env.config)
        self._env = env
        self._source = EpisodeSource(env.config)

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if table.live <= 1:
            return 0
        if self._env is None or self._source is None:
            raise RuntimeError(f"{self.name} needs attach(env) before it acts")
        world = self._env.world
        height, width = world.shape
        maps = completion_draws(
            self._source, world.belief, world.positions, self.samples * self.match, self.seed
        )
        if self.match > 1:
            maps = best_matching(maps, world.belief, self.samples, self.band)
        live = table.live
        costs = completion_costs(
            world.batch, world.index, table.target[:live],
            self._env.config.reward.explore_threshold, 4 * height * width, maps,
        )  # fmt: skip
        return first_by(costs, table.path_length[:live], table.distance[:live])


def completions_name(samples: int, match: int, band: int) -> str:
    """``completions-K``, or ``completions-K-of-RK-bB`` for draws kept by their match."""
    return f"completions-{samples}" + (f"-of-{samples * match}-b{band}" if match > 1 else "")


def best_matching(
    maps: list[np.ndarray], belief: np.ndarray, keep: int, band: int
) -> list[np.ndarray]:
    """The ``keep`` of ``maps`` (occupancy grids) that agree with ``belief`` on the most known
    cells within ``band`` cells (8-connected) of an unknown one; ties keep the earlier draw."""
    unknown = belief == UNKNOWN
    near = ndimage.binary_dilation(unknown, np.ones((3, 3), bool), iterations=band) & ~unknown
    wall = belief[near] == OCCUPIED
    agree = [np.count_nonzero(np.asarray(grid, dtype=bool)[near] == wall) for grid in maps]
    order = np.argsort(-np.asarray(agree), kind="stable")[:keep]
    return [maps[i] for i in order]


def contenders(samples: list[int], oracle: bool, match: int = 1, band: int = 3) -> list[Contender]:
    """frontier-rule, the sampled lookahead for each K of ``samples`` (each kept from
    ``match`` × K draws by :func:`best_matching`) and (``oracle``) the true-map oracle, all in
    frontier-rule's env."""
    rule = heuristic("frontier-rule")
    out = [rule]
    for k in samples:
        planner = partial(CompletionLookahead, k, match=match, band=band)
        out.append(Contender(completions_name(k, match, band), False, planner, rule.config))
    if oracle:
        out.append(Contender("oracle-np-12", False, LookaheadOracle, rule.config))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = study_parser(__doc__, "random-20,random-30,rooms-32")
    parser.add_argument("--samples", default="1,8", help="comma-separated K: maps per decision")
    parser.add_argument(
        "--match", type=int, default=1, help="draw this many times K maps, keep the K that match"
    )
    parser.add_argument("--band", type=int, default=3, help="cells near the unknown to match on")
    parser.add_argument("--no-oracle", action="store_true", help="leave the true-map oracle out")
    args = parser.parse_args(argv)
    try:
        samples = [int(k) for k in args.samples.split(",")]
        if min(samples) < 1:
            raise ValueError
    except ValueError:
        parser.error(f"--samples must be integers >= 1, got {args.samples}")
    if args.match < 1 or args.band < 1:
        parser.error(f"--match and --band must be >= 1, got {args.match} and {args.band}")
    return run_study(parser, args, contenders(samples, not args.no_oracle, args.match, args.band))
