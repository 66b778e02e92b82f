"""A privileged reference: one-step lookahead on the true map, finished by nearest-path.

For each candidate target of one robot, :func:`lookahead_costs` copies the robot's world into a
batch of simulations (one per candidate), walks the robot to that target, then lets
nearest-path finish the map, and returns the cells each simulation travelled until the coverage
level. The simulations sense the true map, so they know what the robot does not: which
frontier will be cleared on the way, which room is a dead end. Choosing the cheapest candidate
is a rollout policy on nearest-path (Bertsekas's rollout: one step of policy improvement).
:class:`LookaheadOracle` is that choice as a benchmark contender
(``lookahead-oracle``): it reads the true map, so it is a bound on what choosing among the same
clusters can gain, not a heuristic; :mod:`frontier_marl.training.imitation` labels decisions
with its costs for a student that sees only its own observation.

The base policy of the simulations keeps a target while it is still a frontier cell and then
picks the next one: by default the nearest cluster by known-free path (ties: nearest
centroid, :class:`NearestPathBase`), one cell per move; any :class:`RolloutBase` can take its
place: :class:`LinearScorerBase` finishes them with a linear slot scorer such as
frontier-rule (:mod:`frontier_marl.experiments.explorer_studies.rollout_probe`, and the
cost-to-go labels with ``regression.finisher = "frontier-rule"``).
"""

from __future__ import annotations

import hashlib
from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.core.grid import OCCUPIED, UNKNOWN
from frontier_marl.core.slots import SlotArrays
from frontier_marl.core.worlds import Worlds, reachable_region
from frontier_marl.policies.base import HeuristicPolicy, Info, first_by, slot_table
from frontier_marl.sim.branching import branch
from frontier_marl.sim.episodes import EpisodeSource
from frontier_marl.sim.observations import ObservationEncoder
from frontier_marl.sim.rollouts import NearestPathBase, RolloutBase, rollout_costs

__all__ = [
    "LinearScorerBase",
    "LookaheadOracle",
    "NearestPathBase",
    "RolloutBase",
    "completed_clones",
    "completion_costs",
    "completion_draws",
    "lookahead_costs",
    "require_generated_maps",
]


def lookahead_costs(
    source: Worlds,
    index: int,
    targets: np.ndarray,
    coverage: float,
    max_cells: int,
    base: RolloutBase | None = None,
    prune: bool = False,
) -> np.ndarray:
    """Cells travelled by robot 0 of world ``index`` until ``coverage`` of the reachable free
    region is known, if it first walks to ``targets[m]`` (M, 2) and ``base`` (default:
    :class:`NearestPathBase`) finishes; ``max_cells`` caps each simulation (a simulation that
    stalls costs ``max_cells``). The M simulations are clones of the world rolled out together
    (:func:`~frontier_marl.sim.branching.branch`,
    :func:`~frontier_marl.sim.rollouts.rollout_costs`). ``prune``: only the cheapest targets'
    costs are exact, the others read ``max_cells`` (enough for an argmin, and faster)."""
    if source.n_agents != 1:
        raise ValueError(f"the lookahead teacher drives one robot, got {source.n_agents}")
    targets = np.asarray(targets, dtype=np.int64).reshape(-1, 2)
    base = NearestPathBase() if base is None else base
    sims = branch(source, index, len(targets), base.gain)
    sims.goals[:, 0] = targets
    start = int(source.travelled[index, 0])
    return rollout_costs(sims, start, coverage, max_cells, base, prune)


def completion_costs(
    source: Worlds,
    index: int,
    targets: np.ndarray,
    coverage: float,
    max_cells: int,
    maps: list[np.ndarray],
) -> np.ndarray:
    """:func:`lookahead_costs` (nearest-path finishing) averaged over ``maps`` in place of the
    true map: per target (M, 2), the mean over the maps (grids of the world's shape) of the
    cells robot 0 of world ``index`` walks until ``coverage`` of its reachable free region is
    known, if the cells it does not know are the map's (the known ones stay as its belief has
    them), it walks to the target first and nearest-path finishes. It reads no true map."""
    targets = np.asarray(targets, dtype=np.int64).reshape(-1, 2)
    m, samples = len(targets), len(maps)
    base = NearestPathBase()
    sims = completed_clones(source, index, m, maps, base.gain)
    sims.goals[:, 0] = np.tile(targets, (samples, 1))
    start = int(source.travelled[index, 0])
    costs = rollout_costs(sims, start, coverage, max_cells, base)
    return costs.reshape(samples, m).mean(axis=0)


def completed_clones(
    source: Worlds, index: int, count: int, maps: list[np.ndarray], gain: str
) -> Worlds:
    """``count`` clones of world ``index`` of ``source`` per map of ``maps`` (map after map),
    each clone's true map the drawn one with the world's known cells as its belief has them,
    and its reachable region recomputed from the robots' cells."""
    sims = branch(source, index, count * len(maps), gain)
    belief = source.belief[index]
    known = belief != UNKNOWN
    for k, drawn in enumerate(maps):
        grid = np.array(drawn, dtype=bool)
        grid[known] = belief[known] == OCCUPIED
        region = reachable_region(grid, source.positions[index])
        rows = slice(k * count, (k + 1) * count)
        sims.true[rows] = grid
        sims.start_region[rows] = region
        sims.start_region_size[rows] = np.count_nonzero(region)
        sims.true_free[rows] = np.count_nonzero(~grid)
    return sims


def completion_draws(
    source: EpisodeSource, belief: np.ndarray, positions: np.ndarray, samples: int, seed: int = 0
) -> list[np.ndarray]:
    """``samples`` layouts from ``source``'s generator for :func:`completion_costs`, drawn
    from a generator seeded by ``seed``, the belief and the robots' cells (the same state
    draws the same maps in any process). A loaded or static map is refused: its draw would be
    the true map."""
    require_generated_maps(source.cfg)
    digest = hashlib.blake2b(np.ascontiguousarray(belief).tobytes() + positions.tobytes())
    rng = np.random.default_rng([seed, int.from_bytes(digest.digest()[:8], "little")])
    return [source.true_grid(rng) for _ in range(samples)]


def require_generated_maps(cfg: EnvConfig) -> None:
    """ValueError unless ``cfg`` draws a fresh generated map per episode (map completions
    drawn from a loaded or static map would be the true map)."""
    if cfg.map_path is not None or cfg.map_mode != "dynamic":
        raise ValueError(
            "map completions are drawn from the env's generator: they need dynamic generated "
            "maps (a loaded or static map would be the true map)"
        )


class LinearScorerBase:
    """A rollout base policy (:class:`~frontier_marl.policies.lookahead.RolloutBase`): the
    linear slot scorer ``weights`` on the observation of ``cfg`` (the model's own; the
    simulations keep no heading, so the ``current`` feature reads 0)."""

    def __init__(self, cfg: EnvConfig, weights: np.ndarray) -> None:
        self.encoder = ObservationEncoder(cfg)
        self.weights = weights
        self.n_slots = cfg.n_slots
        self.gain = cfg.gain

    def goals(self, sims: Worlds, slots: SlotArrays, deciding: np.ndarray) -> np.ndarray:
        rows = slots.rows(deciding)
        positions = sims.positions[deciding, 0]
        observed = self.encoder.encode_batch(rows, positions, beliefs=sims.belief[deciding])
        scores = np.where(rows.valid, observed["slots"].astype(np.float64) @ self.weights, -np.inf)
        best = np.argmax(scores, axis=1)
        goals = rows.target[np.arange(len(deciding)), best].astype(np.int64)
        goals[~rows.valid.any(axis=1)] = -1
        return goals


class LookaheadOracle(HeuristicPolicy):
    """The cheapest live slot by :func:`lookahead_costs` with rollout ``base`` (default
    nearest-path; ties: nearest path, then nearest centroid), kept until reached (``commit =
    "until-reached"``). One robot only; it reads the attached env's world, true map included,
    and its coverage level (``explore_threshold`` of the reachable free cells).

    Only the argmin is needed, so the simulations are pruned (branch and bound, ``prune`` of
    :func:`lookahead_costs`), the candidates simulated nearest by path first: a cheap one
    found early stops the others sooner. The choice is the one exact costs give."""

    name = "lookahead-oracle"

    def __init__(self, base: RolloutBase | None = None) -> None:
        super().__init__("until-reached")
        self.base = base
        self._env: Any = None

    def attach(self, env: Any) -> None:
        agents = len(getattr(env, "possible_agents", ["robot_0"]))
        if agents != 1:
            raise ValueError(f"lookahead-oracle drives one robot, the env has {agents}")
        self._env = env

    def choose(self, info: Info) -> int:
        table = slot_table(info)
        if table.live <= 1:
            return 0
        if self._env is None:
            raise RuntimeError("lookahead-oracle needs attach(env) before it acts")
        world = self._env.world
        height, width = world.shape
        live = table.live
        coverage = self._env.config.reward.explore_threshold
        order = np.argsort(table.path_length[:live], kind="stable")  # likely cheap ones first
        costs = np.empty(live, dtype=np.int64)
        costs[order] = lookahead_costs(
            world.batch, world.index, table.target[:live][order], coverage, 4 * height * width,
            self.base, prune=True,
        )  # fmt: skip
        return first_by(costs, table.path_length[:live], table.distance[:live])
