"""Observation encoders: one robot's slot table and position -> the observation the agent sees.

Layout (the thesis's Table 4.1 axes, see :class:`~frontier_marl.config.ObservationConfig`):

* ``clusters``: a flat float32 vector of ``n_slots * F`` values, slot-major. Per slot, in order:
  the centroid encoding (``absolute``: row, col; ``relative``: drow, dcol = centroid - robot;
  ``distance``: Euclidean distance; ``none``: nothing), then the information gain if enabled.
  Padding slots are all zeros.
* Without the agent position (and without ``action_mask``) the observation *is* that vector
  (a ``Box``, for SB3's ``MlpPolicy``). Otherwise it is a ``Dict`` with keys ``clusters``,
  ``agent_position`` (row, col) when enabled, and ``action_mask`` (int8, 1 = live slot; slot 0
  alone when no cluster is live, the robot then idles) when enabled (for SB3's
  ``MultiInputPolicy``).
* ``teammates`` (Dict only): the other robots' (row, col) positions in agent order, each
  followed by its current target cell for ``positions+targets`` (zeros when it has none).
* With ``normalize``, rows are divided by the height, columns by the width, distances by the
  diagonal and gains by their upper bound, so every value lies in [-1, 1].
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from frontier_marl.config import EnvConfig
from frontier_marl.core.compiled import compiled
from frontier_marl.core.slots import SlotArrays, SlotTable
from frontier_marl.sim.features import (
    cluster_fill,
    explorer_features,
    explorer_space,
    log_utility,
    near_half_side,
    slot_feature_names,
    team_features,
    tour_lengths,
    turn_costs,
    unknown_near,
)

#: The centroid encodings' codes in :func:`thesis_features`.
_CENTROID_CODES = {"none": 0, "absolute": 1, "relative": 2, "distance": 3}


class ObservationEncoder:
    """Builds the observation space once and encodes slot tables into it."""

    def __init__(self, cfg: EnvConfig) -> None:
        obs = cfg.observation
        self.cfg = cfg
        self.n_slots = cfg.n_slots
        self.centroid = obs.centroid
        self.info_gain = obs.info_gain
        self.agent_position = obs.agent_position
        self.action_mask = obs.action_mask
        self.is_dict = obs.is_dict
        self.teammates = obs.teammates
        self.normalize = obs.normalize
        self.features = obs.features
        if self.features == "explorer":
            self.tour, self.turn, self.unknown_near = obs.tour, obs.turn, obs.unknown_near
            self.fill, self.utility = obs.fill, obs.utility
            self.near = near_half_side(obs.near_ranges, cfg.perception_range)
            self.features_per_slot = len(slot_feature_names(obs))
            self.space: spaces.Space[Any] = explorer_space(self.n_slots, self.features_per_slot)
            return
        height, width = cfg.height, cfg.width
        cells = cfg.max_cluster_cells
        gain_high = min(float(cells if cfg.gain == "size" else 8 * cells), float(height * width))
        low, high, scale = [], [], []
        if self.centroid == "absolute":
            low += [0.0, 0.0]
            high += [height - 1.0, width - 1.0]
            scale += [float(height), float(width)]
        elif self.centroid == "relative":
            low += [-(height - 1.0), -(width - 1.0)]
            high += [height - 1.0, width - 1.0]
            scale += [float(height), float(width)]
        elif self.centroid == "distance":
            low += [0.0]
            high += [math.hypot(height - 1, width - 1)]
            scale += [math.hypot(height, width)]
        if self.info_gain:
            low += [0.0]
            high += [gain_high]
            scale += [gain_high]
        self.features_per_slot = len(low)
        self._scale = np.array(scale if obs.normalize else [1.0] * len(scale), dtype=np.float64)
        self._position_scale = (
            np.array([height, width], dtype=np.float64) if obs.normalize else np.ones(2)
        )
        low_arr = np.tile(np.array(low) / self._scale, self.n_slots).astype(np.float32)
        high_arr = np.tile(np.array(high) / self._scale, self.n_slots).astype(np.float32)
        cluster_space = spaces.Box(low_arr, high_arr, dtype=np.float32)
        if not self.is_dict:
            self.space = cluster_space
            return
        entries: dict[str, spaces.Space[Any]] = {"clusters": cluster_space}
        if self.agent_position:
            pos_high = (np.array([height - 1, width - 1]) / self._position_scale).astype(np.float32)
            entries["agent_position"] = spaces.Box(
                np.zeros(2, np.float32), pos_high, dtype=np.float32
            )
        if self.action_mask:
            entries["action_mask"] = spaces.Box(0, 1, (self.n_slots,), dtype=np.int8)
        if self.teammates != "none":
            per_mate = 4 if self.teammates == "positions+targets" else 2
            cell_high = np.array([height - 1, width - 1]) / self._position_scale
            mate_high = np.tile(cell_high, (cfg.n_agents - 1) * per_mate // 2).astype(np.float32)
            entries["teammates"] = spaces.Box(np.zeros_like(mate_high), mate_high, dtype=np.float32)
        self.space = spaces.Dict(entries)

    def encode(
        self,
        slots: SlotTable,
        position: np.ndarray,
        teammates: np.ndarray | None = None,
        heading: np.ndarray | None = None,
        motion: np.ndarray | None = None,
        belief: np.ndarray | None = None,
    ) -> np.ndarray | dict[str, np.ndarray]:
        """The observation of a robot at ``position`` with slot table ``slots``.

        ``teammates`` is (N-1, 2) or (N-1, 4): the other robots' (row, col) positions, and
        targets for ``positions+targets``; needed only when the layout includes teammates.
        ``heading``: the cell the robot is heading to (row -1: none), for the explorer layout.
        ``motion``: its displacement over its last steps (:mod:`frontier_marl.sim.motion`), for
        the ``turn`` feature (default: none). ``belief``: the (H, W) belief map, needed by the
        ``unknown_near`` feature.
        """
        batch = self.encode_batch(
            SlotArrays.stack([slots]),
            np.asarray(position)[None],
            None if teammates is None else np.asarray(teammates).reshape(1, -1),
            None if heading is None else np.asarray(heading).reshape(1, 2),
            None if motion is None else np.asarray(motion).reshape(1, 2),
            None if belief is None else np.asarray(belief)[None],
        )
        if isinstance(batch, dict):
            return {key: value[0] for key, value in batch.items()}
        return batch[0]

    def encode_batch(
        self,
        slots: SlotArrays,
        positions: np.ndarray,
        teammates: np.ndarray | None = None,
        heading: np.ndarray | None = None,
        motion: np.ndarray | None = None,
        beliefs: np.ndarray | None = None,
    ) -> np.ndarray | dict[str, np.ndarray]:
        """The observations of M robots at once: ``slots`` with ``(M, n_slots, ...)`` fields,
        ``positions`` (M, 2), ``teammates`` (M, (N-1) x 2 or 4) flattened per robot,
        ``heading`` (M, 2) the cells they head to (row -1: none; default none), ``motion``
        (M, 2) their displacements over their last steps (default: none), ``beliefs``
        (B, H, W) the shared belief maps of the B worlds the robots act in, world after world
        (needed by ``unknown_near``). Returns the
        ``(M, ...)`` array, or a dict of them, in :attr:`space`'s layout."""
        if self.features == "explorer":
            if heading is None:
                heading = np.full_like(positions, -1)
            parts = [explorer_features(slots, positions, heading)]
            if self.tour:
                parts.append(tour_lengths(slots))
            if self.turn:
                if motion is None:
                    motion = np.zeros_like(positions)
                parts.append(turn_costs(slots, positions, motion))
            if self.unknown_near:
                if beliefs is None:
                    raise ValueError("the unknown_near feature needs the robots' belief maps")
                parts.append(unknown_near(slots, beliefs, self.near))
            if self.fill:
                parts.append(cluster_fill(slots, self.cfg.max_cluster_cells))
            if self.utility:
                parts.append(log_utility(slots, self.cfg.perception_range))
            if self.teammates != "none":
                if teammates is None:
                    raise ValueError("this layout observes teammates: pass their rows")
                width = 4 if self.teammates == "positions+targets" else 2
                rows = np.asarray(teammates, dtype=np.float64).reshape(len(positions), -1, width)
                parts.append(team_features(slots, rows))
            features = np.concatenate(parts, axis=-1)  # one copy, not one per feature
            return {"slots": features, "action_mask": np.array(slots.mask, dtype=np.int8)}
        count = len(positions)
        flat = np.empty((count, self.n_slots * self.features_per_slot), dtype=np.float32)
        thesis_features(
            _CENTROID_CODES[self.centroid], self.info_gain, slots.centroid, slots.valid,
            slots.distance, slots.gain, positions, self._scale, flat,
        )  # fmt: skip
        if not self.is_dict:
            return flat
        out: dict[str, np.ndarray] = {"clusters": flat}
        if self.agent_position:
            out["agent_position"] = (
                (positions / self._position_scale).astype(np.float32)
                if self.normalize
                else positions.astype(np.float32)
            )
        if self.action_mask:
            out["action_mask"] = np.array(slots.mask, dtype=np.int8)
        if self.teammates != "none":
            if teammates is None:
                raise ValueError("this observation layout needs the teammates' positions")
            scale = np.tile(self._position_scale, teammates.shape[1] // 2)
            out["teammates"] = (teammates / scale).astype(np.float32)
        return out


@compiled
def thesis_features(
    centroid_code: int,
    info_gain: bool,
    centroid: np.ndarray,
    valid: np.ndarray,
    distance: np.ndarray,
    gain: np.ndarray,
    positions: np.ndarray,
    scale: np.ndarray,
    out: np.ndarray,
) -> None:
    """The thesis layout's ``clusters`` vectors of M robots into ``out`` (float32 (M, S F)):
    per slot the centroid encoding (``centroid_code`` of :data:`_CENTROID_CODES`; relative
    offsets are zero in padding slots), then the gain if ``info_gain``, each value divided by
    its ``scale`` (F,) in float64 and then rounded to float32, as numpy would."""
    features = len(scale)
    for m in range(out.shape[0]):
        for slot in range(centroid.shape[1]):
            column = slot * features
            if centroid_code == 1:
                out[m, column] = centroid[m, slot, 0] / scale[0]
                out[m, column + 1] = centroid[m, slot, 1] / scale[1]
                column += 2
            elif centroid_code == 2:
                if valid[m, slot]:
                    out[m, column] = (centroid[m, slot, 0] - positions[m, 0]) / scale[0]
                    out[m, column + 1] = (centroid[m, slot, 1] - positions[m, 1]) / scale[1]
                else:
                    out[m, column] = 0.0
                    out[m, column + 1] = 0.0
                column += 2
            elif centroid_code == 3:
                out[m, column] = distance[m, slot] / scale[0]
                column += 1
            if info_gain:
                out[m, column] = gain[m, slot] / scale[features - 1]


def observed_heading(heading: np.ndarray, features: str) -> np.ndarray:
    """The teammates' targets as observed: zeros where a robot heads nowhere in the thesis
    layout (its documented encoding), row -1 kept in the explorer layout."""
    return heading if features == "explorer" else np.maximum(heading, 0)


def teammate_rows(table: np.ndarray) -> np.ndarray:
    """Per robot, the rows of its teammates: ``(..., N, F)`` -> ``(..., N, (N-1) x F)``, the
    other robots' rows in agent order, flattened."""
    n = table.shape[-2]
    others = np.array([[j for j in range(n) if j != i] for i in range(n)], dtype=np.int64)
    picked = table[..., others.reshape(-1), :]  # (..., N * (N-1), F)
    return picked.reshape(*table.shape[:-2], n, (n - 1) * table.shape[-1])


def describe_layout(cfg: EnvConfig) -> dict[str, Any]:
    """A JSON-able description of the observation layout, used to check saved models (the
    explorer layout's names neither the map size nor the team size: it fits every one)."""
    enc = ObservationEncoder(cfg)
    if enc.features == "explorer":
        return {
            "features": "explorer",
            "gain": cfg.gain,
            "sort_by_distance": cfg.observation.sort_by_distance,
            "teammates": cfg.observation.teammates,
            "tour": cfg.observation.tour,
            "turn": cfg.observation.turn,
            "unknown_near": cfg.observation.unknown_near,
            "near_ranges": cfg.observation.near_ranges,
            "fill": cfg.observation.fill,
            **({"utility": True} if cfg.observation.utility else {}),
            "n_agents": None,
            "n_slots": enc.n_slots,
            "features_per_slot": enc.features_per_slot,
        }
    return {
        "centroid": enc.centroid,
        "info_gain": enc.info_gain,
        "gain": cfg.gain,
        "agent_position": enc.agent_position,
        "action_mask": enc.action_mask,
        "sort_by_distance": cfg.observation.sort_by_distance,
        "normalize": cfg.observation.normalize,
        "teammates": cfg.observation.teammates,
        "n_agents": cfg.n_agents if cfg.observation.teammates != "none" else None,
        "n_slots": enc.n_slots,
        "features_per_slot": enc.features_per_slot,
        "height": cfg.height,
        "width": cfg.width,
    }
