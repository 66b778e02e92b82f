"""The decision process: the package's only implementation of a step, for N worlds at once.

:class:`BatchMDP` holds N episodes of ``cfg.n_agents`` robots in shared arrays
(:class:`~frontier_marl.core.worlds.Worlds`) and steps them together: actions become targets,
one compiled call walks every robot, the frontier masks of all worlds whose belief changed are
labelled by one ``scipy.ndimage.label`` call, one compiled call builds every robot's slots, one
applies the reward table and the episode ends, and the observation encoder runs on whole
arrays. A step is two compiled calls on either side of the labelling
(:mod:`frontier_marl.sim.step_kernels`). World ``i`` draws its episodes from its own
``numpy.random.Generator``. The vector env
and the SB3 batched adapter use it directly; the single env's
:class:`~frontier_marl.sim.engine.ExplorationMDP` is a batch of one.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from frontier_marl.config import EnvConfig
from frontier_marl.core.slots import SLOT_COLUMNS, SlotArrays, commit_to_previous
from frontier_marl.core.world_kernels import basis_code
from frontier_marl.core.worlds import Worlds
from frontier_marl.sim.episodes import EpisodeSource, world_params
from frontier_marl.sim.motion import MotionTrail
from frontier_marl.sim.observations import ObservationEncoder, observed_heading, teammate_rows
from frontier_marl.sim.rewards import BatchOutcome, OscillationHistory, table_constants
from frontier_marl.sim.step_kernels import after_labelling, before_labelling

Observations = np.ndarray | dict[str, np.ndarray]
_EVERY = slice(None)


class BatchMDP:
    """Frontier-selection MDP of ``n_worlds`` worlds with ``cfg.n_agents`` robots each.

    After :meth:`step` the step's results are in arrays indexed ``[world, robot]``:
    ``targets``, ``padding``, ``oscillation``, ``new_cells`` and ``outcome`` (fresh rewards;
    flags and end-reason codes in arrays the next step overwrites), and ``explored`` (N,) holds
    each world's explored fraction on the reward's threshold basis. Worlds whose episode ended
    stay ``done`` until :meth:`reset_worlds`.
    """

    def __init__(self, cfg: EnvConfig, n_worlds: int) -> None:
        if isinstance(n_worlds, bool) or not isinstance(n_worlds, int | np.integer):
            raise TypeError(f"num_envs must be an integer >= 1, got {n_worlds!r}")
        if n_worlds < 1:
            raise ValueError(f"num_envs must be an integer >= 1, got {n_worlds}")
        n, k = int(n_worlds), cfg.n_agents
        self.cfg = cfg
        self.n_worlds, self.n_agents, self.n_slots = n, k, cfg.n_slots
        self.encoder = ObservationEncoder(cfg)
        self.worlds = Worlds(cfg.shape, n, k, world_params(cfg))
        self.source = EpisodeSource(cfg)
        self.rngs: list[np.random.Generator] = [np.random.default_rng() for _ in range(n)]
        self.slots = SlotArrays.empty(n, k, cfg.n_slots)
        self.packed = np.empty((n, k, cfg.n_slots, len(SLOT_COLUMNS)))  # the slots, packed
        self._oscillation = OscillationHistory(n, k, cfg.reward.oscillation_window)
        self._trail = MotionTrail(n, k) if cfg.observation.turn else None
        self.steps = np.zeros(n, dtype=np.int64)
        self.steps_without_progress = np.zeros(n, dtype=np.int64)
        self.done = np.ones(n, dtype=bool)
        self.explored = self.worlds.explored_fraction(cfg.reward.threshold_basis)  # (N,), read-only
        # the explored fractions as a step counts them, and the belief versions counted at
        self._fractions, self._counted = np.zeros(n), np.full(n, -1, dtype=np.int64)
        self.targets = np.full((n, k, 2), -1, dtype=np.int64)
        self.heading = np.full((n, k, 2), -1, dtype=np.int64)  # current targets, -1: none
        self.padding = np.zeros((n, k), dtype=bool)
        self.oscillation = np.zeros((n, k), dtype=bool)
        self.new_cells = np.zeros((n, k), dtype=np.int64)
        # the step's outcome: fresh rewards every step (they are handed out), the rest reused
        self._ends = self.outcome = BatchOutcome(
            np.zeros((n, k)), np.zeros(n, bool), np.zeros(n, bool), np.zeros(n, np.int64)
        )
        # the step's own buffers: the chosen targets, padding and oscillation flags, and the
        # cells walked before it
        chosen_flags = (np.empty((n, k), dtype=bool), np.empty((n, k), dtype=bool))
        self._chosen = (np.empty((n, k, 2), dtype=np.int64), *chosen_flags)
        self._before = np.empty((n, k), dtype=np.int64)
        self._travel = cfg.reward.kind == "travel"  # the only reward that reads the cells walked
        self._kept = (self.targets, self.heading, self.padding, self.oscillation)  # see settle
        self._make_views()

    def _make_views(self) -> None:
        """Every robot's slots, position and heading as ``(N K, ...)`` views, and the
        arguments of the step's compiled calls, made once (and again after a copy: a copied
        view would no longer see its array)."""
        self._every_row = self.slots.rows(_EVERY)
        self._positions = self.worlds.positions.reshape(-1, 2)
        self._heading = self.heading.reshape(-1, 2)
        cfg, w, slots = self.cfg, self.worlds, self.slots
        travel = (self._travel, self._before, self.steps, self.steps_without_progress)
        chosen = self._chosen
        offsets, between = w.params.sensor.rays
        self._before_args = (
            slots.live, slots.target, self._oscillation.history, *chosen, *travel,
            w.true, w.belief, w.seen, w.positions, w.travelled, w.goals, w.plan_cells,
            w.plan_meta, w.version, w.params.cells_per_step, offsets, between, w.new_cells,
            w.walked, w.walked_len, w.reached, *w.search,
            w.clustered_version, w.stale, w.frontier, w.masks, w.boxes, w.packed_shape,
        )  # fmt: skip
        constants, _, padding_truncates, no_progress_limit, max_steps = table_constants(cfg.reward)
        self._after_args = (
            slots.live, *chosen, *travel,
            w.start_region, w.start_region_size, w.true_free, w.belief, w.positions, w.travelled,
            w.version, w.reached,
            w.labels, w.boxes, w.packed_shape, w.stale, w.params.max_cluster_cells,
            w.params.gain != "unknown",
            w.cell_rows, w.cell_cols, w.cell_cluster, w.n_cells, w.sizes, w.centroids, w.gains,
            w.n_clusters, w.clustered_version,
            cfg.observation.sort_by_distance, slots.cluster, slots.valid, slots.centroid,
            slots.target, slots.distance, slots.size, slots.gain, slots.path_length, slots.mask,
            self.packed,
            basis_code(cfg.reward.threshold_basis), self._counted, self._fractions,
            constants, padding_truncates, no_progress_limit, max_steps,
            cfg.reward.explore_threshold, self._ends.terminated, self._ends.truncated,
            self._ends.reason, self.done, *self._kept,
        )  # fmt: skip

    def __getstate__(self) -> dict[str, Any]:
        views = ("_every_row", "_positions", "_heading", "_before_args", "_after_args")
        return {k: v for k, v in self.__dict__.items() if k not in views}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._make_views()

    # ------------------------------------------------------------------ episodes
    def reset_worlds(self, worlds: np.ndarray) -> None:
        """Start a new episode in each world of ``worlds`` (indices), from its own generator."""
        for i in worlds.tolist():
            true_grid, starts, start_region = self.source.draw(self.rngs[i])
            self.worlds.place(i, true_grid, starts, start_region)
        self._oscillation.clear(worlds)
        if self._trail is not None:
            self._trail.clear(worlds, self.worlds.positions[worlds])
        self.steps[worlds] = 0
        self.steps_without_progress[worlds] = 0
        self.done[worlds] = False
        self.targets[worlds] = -1
        self.heading[worlds] = -1
        self.padding[worlds] = False
        self.oscillation[worlds] = False
        self.new_cells[worlds] = 0
        self.worlds.slots(self.slots, worlds, self.cfg.observation.sort_by_distance, self.packed)
        self.explored = self.worlds.explored_fraction(self.cfg.reward.threshold_basis)

    # ------------------------------------------------------------------ transition
    def step(self, actions: np.ndarray, active: np.ndarray) -> None:
        """One decision per robot of the ``active`` worlds (bool (N,)): ``actions`` (N, K)
        holds valid slot indices (checked by the caller). Inactive worlds (ended, or waiting
        while others play forced steps) keep their state: they do not move and get no reward
        or end flag."""
        if self._trail is not None:
            self._trail.push(self.worlds.positions, active)
        actions = np.asarray(actions, dtype=np.int64)
        new_cells = np.empty_like(self.new_cells)  # fresh: the last step's stay readable
        stale = before_labelling(actions, active, new_cells, *self._before_args)
        if stale:
            self.worlds.label_stale()
        ends = self._ends
        ends.rewards = np.empty_like(ends.rewards)
        explored = np.empty(self.n_worlds)
        after_labelling(active, new_cells, stale, explored, ends.rewards, *self._after_args)
        if self.cfg.observation.commit != "none":
            slots = self.slots
            slots.mask[:] = commit_to_previous(
                slots.mask,
                slots.target,
                slots.valid,
                self._chosen[0],
                new_cells > 0,
                self.cfg.observation.commit,
            )
        self.new_cells, self.outcome, self.explored = new_cells, ends, explored

    def play_forced(self) -> None:
        """Step every live world whose robots each have exactly one valid slot (a commitment,
        or a single cluster) with that slot, until every live world offers a choice or has
        ended. ``outcome`` then holds the rewards summed since the last decision and the ends
        reached on the way."""
        total = self.outcome
        rewards, reason = total.rewards.copy(), total.reason.copy()
        terminated, truncated = total.terminated.copy(), total.truncated.copy()
        while True:
            forced = ~self.done & (self.slots.mask.sum(axis=2) == 1).all(axis=1)
            if not forced.any():
                break
            self.step(self.slots.mask.argmax(axis=2), forced)
            step = self.outcome
            rewards += step.rewards
            terminated |= step.terminated
            truncated |= step.truncated
            reason = np.where(step.reason != 0, step.reason, reason)
        self.outcome = BatchOutcome(rewards, terminated, truncated, reason)

    # ------------------------------------------------------------------ views
    def observations(self, worlds: np.ndarray | None = None) -> Observations:
        """The robots' observations of ``worlds`` (indices; default: every world),
        ``(len(worlds), K, ...)`` per key."""
        batch = self.robot_observations(worlds)
        shape = (-1, self.n_agents)
        if isinstance(batch, dict):
            return {key: value.reshape(*shape, *value.shape[1:]) for key, value in batch.items()}
        return batch.reshape(*shape, *batch.shape[1:])

    def robot_observations(self, worlds: np.ndarray | None = None) -> Observations:
        """The observations of the robots of ``worlds`` (indices; default: every world), world
        after world, ``(len(worlds) K, ...)`` per key."""
        if worlds is None:  # the common case: views made once, no indexing
            chosen, rows, positions, heading = (
                _EVERY,
                self._every_row,
                self._positions,
                self._heading,
            )
        else:
            chosen, rows = worlds, self.slots.rows(worlds)
            positions = self.worlds.positions[worlds].reshape(-1, 2)
            heading = self.heading[worlds].reshape(-1, 2)
        mates = self._teammates(chosen)
        motion = (
            None
            if self._trail is None
            else self._trail.motion(chosen, self.worlds.positions[chosen])
        )
        return self.encoder.encode_batch(
            rows,
            positions,
            None if mates is None else mates.reshape(len(positions), -1),
            heading,
            None if motion is None else motion.reshape(-1, 2),
            self._beliefs(chosen),
        )

    def _beliefs(self, worlds: np.ndarray | slice) -> np.ndarray | None:
        """The shared belief maps of ``worlds``, for the ``unknown_near`` feature."""
        if not self.cfg.observation.unknown_near:
            return None
        return self.worlds.belief[worlds]

    def _teammates(self, worlds: np.ndarray | slice) -> np.ndarray | None:
        layout = self.cfg.observation.teammates
        if layout == "none":
            return None
        positions = self.worlds.positions[worlds].astype(np.float64)
        if layout == "positions":
            return teammate_rows(positions)
        heading = observed_heading(self.heading[worlds], self.cfg.observation.features)
        return teammate_rows(np.concatenate([positions, heading], axis=2))

    def explored_fraction(self, basis: str) -> np.ndarray:
        """Per world, the explored fraction on ``basis`` (``all``, ``free``, ``reachable``)."""
        return self.worlds.explored_fraction(basis)
