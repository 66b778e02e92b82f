"""The ``explorer`` observation: per-slot features that do not depend on the map's size.

``{"slots": (n_slots, F) float32, "action_mask": (n_slots,) int8}``; padding slots are all
zeros. Lengths are in cells divided by :data:`CELLS` (32), so the same robot situation gives the
same features on a 20x20 grid and on a 64x64 floor plan. Per slot, in order
(:data:`EXPLORER_FEATURES`):

``path``        known-free shortest path from the robot to the slot's target
``distance``    Euclidean distance from the robot to the cluster's centroid
``d_row``, ``d_col``   the target relative to the robot
``size``        frontier cells of the cluster / 16
``gain``        the information gain / 64 (unknown cells around it with ``gain="unknown"``)
``isolation``   Euclidean distance from the centroid to the nearest other slot's centroid
``extra_path``  ``path`` minus the shortest ``path`` of all slots (0 for the nearest)
``current``     1 if the slot's target is the cell the robot is heading to
``live``        the number of live slots / n_slots (the same on every slot)

With ``tour=True``, one more (:data:`TOUR_FEATURE`), after those:

``tour``        Euclidean length of the nearest-neighbour tour that starts at the slot's target
                and visits every other live slot's target (:func:`tour_lengths`): how well
                going there first fits a route through all the nearby frontiers

With ``turn=True``, one more (:data:`TURN_FEATURE`), after those:

``turn``        1 - cos of the angle between the robot's motion over its last
                :data:`~frontier_marl.sim.motion.TRAIL_STEPS` steps and the direction to the
                slot's target (:func:`turn_costs`): 0 straight ahead, 2 straight back; 0
                when the robot has not moved in those steps or stands on the target

With ``unknown_near=True``, one more (:data:`UNKNOWN_NEAR_FEATURE`), after those:

``unknown_near``  the unknown cells of the belief in the square of side ``2 * NEAR + 1``
                  (:data:`NEAR` = 12 cells, or ``near_ranges`` sensor ranges:
                  :func:`near_half_side`) centred on the slot's target, as a fraction of
                  the square's cells (:func:`unknown_near`); cells beyond the map count as
                  known, so a frontier hemmed in by the map's edge or by known walls scores
                  low, one that opens onto a large unexplored region high

With ``fill=True``, one more (:data:`FILL_FEATURE`), after those:

``fill``        the cluster's frontier cells / the env's ``max_cluster_cells`` (its split size,
                2r + 2 by default): 1 for a full piece of a long frontier, near 0 for a speck
                of a few cells; unlike ``size``, it reads alike on a coarse grid and on a finer
                grid of the same floor plan (where the sensor and the pieces span more cells
                and shadows leave more specks) (:func:`cluster_fill`)

With ``utility=True``, one more (:data:`UTILITY_FEATURE`), after those:

``utility``     cost-utility's log utility, ``log(1 + gain) - log(1 + path)`` (lengths in
                cells), weighed by ``(r / UTILITY_RANGE) ** 4`` (:func:`log_utility`): about
                nothing at the coarse grids' r = 3-5 and dominant at the floor plans' r = 35,
                where the gain behind a frontier tells whole rooms from shadows

With teammates observed (``teammates`` other than ``none``), three more per slot
(:data:`TEAM_FEATURES`), whatever the team's size:

``mate_distance``         Euclidean distance from the nearest teammate to the slot's target
``mate_heading``          1 if a teammate heads to the slot's target (``positions+targets``)
``mate_target_distance``  distance from the target to the nearest teammate's target, capped at
                          :data:`FAR` (also when no teammate heads anywhere)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from gymnasium import spaces

from frontier_marl.core.compiled import compiled
from frontier_marl.core.grid import UNKNOWN
from frontier_marl.core.slots import SlotArrays

if TYPE_CHECKING:
    from frontier_marl.config import ObservationConfig

CELLS = 32.0  # the length unit of the features, in cells
EXPLORER_FEATURES = (
    "path", "distance", "d_row", "d_col", "size", "gain", "isolation", "extra_path", "current",
    "live",
)  # fmt: skip
TOUR_FEATURE = "tour"
TURN_FEATURE = "turn"
UNKNOWN_NEAR_FEATURE = "unknown_near"
FILL_FEATURE = "fill"
UTILITY_FEATURE = "utility"
UTILITY_RANGE = 12.0  # the sensor range, in cells, at which the utility feature weighs 1
NEAR = 12  # the half-side of unknown_near's square, in cells
TEAM_FEATURES = ("mate_distance", "mate_heading", "mate_target_distance")
FAR = 2.0  # mate_target_distance when no teammate target is nearer (in CELLS units)
_BOUND = 1024.0  # far above any value on a 4096 x 4096 grid


def slot_feature_names(observation: ObservationConfig) -> list[str]:
    """The names of the explorer layout's per-slot features under ``observation``, in the
    order the encoder writes them."""
    names = list(EXPLORER_FEATURES)
    names += [TOUR_FEATURE] if observation.tour else []
    names += [TURN_FEATURE] if observation.turn else []
    names += [UNKNOWN_NEAR_FEATURE] if observation.unknown_near else []
    names += [FILL_FEATURE] if observation.fill else []
    names += [UTILITY_FEATURE] if observation.utility else []
    return names + (list(TEAM_FEATURES) if observation.teammates != "none" else [])


def explorer_space(n_slots: int, n_features: int = len(EXPLORER_FEATURES)) -> spaces.Dict:
    """The explorer layout's observation space (the same for every map size)."""
    return spaces.Dict(
        {
            "slots": spaces.Box(-_BOUND, _BOUND, (n_slots, n_features), np.float32),
            "action_mask": spaces.Box(0, 1, (n_slots,), dtype=np.int8),
        }
    )


def explorer_features(slots: SlotArrays, positions: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """(M, n_slots, F) features of M robots: ``slots`` with (M, n_slots) fields, ``positions``
    and ``heading`` (M, 2), heading row -1 where a robot heads nowhere."""
    valid = slots.valid
    count, n_slots = valid.shape
    path = np.where(valid, slots.path_length, 0).astype(np.float64)
    relative = slots.target - positions[:, None, :]
    centroid = slots.centroid
    apart = np.linalg.norm(centroid[:, :, None, :] - centroid[:, None, :, :], axis=-1)
    others = valid[:, :, None] & valid[:, None, :] & ~np.eye(n_slots, dtype=bool)
    isolation = np.where(others, apart, np.inf).min(axis=2)
    isolation = np.where(np.isfinite(isolation), isolation, 0.0)
    nearest = np.where(valid, path, np.inf).min(axis=1, keepdims=True)
    current = (slots.target == heading[:, None, :]).all(axis=-1) & (heading[:, None, 0] >= 0)
    live = valid.sum(axis=1, keepdims=True) / n_slots
    features = np.stack(
        [
            path / CELLS,
            slots.distance / CELLS,
            relative[..., 0] / CELLS,
            relative[..., 1] / CELLS,
            slots.size / 16.0,
            slots.gain / 64.0,
            isolation / CELLS,
            np.where(valid, path - nearest, 0.0) / CELLS,
            current,
            np.broadcast_to(live, valid.shape),
        ],
        axis=-1,
    )
    features[~valid] = 0.0
    return features.astype(np.float32).reshape(count, n_slots, len(EXPLORER_FEATURES))


def tour_lengths(slots: SlotArrays) -> np.ndarray:
    """(M, n_slots, 1) :data:`TOUR_FEATURE` of M robots, in :data:`CELLS` units (0 on padding
    slots): from each live slot's target, the greedy nearest-neighbour tour (Euclidean,
    ties to the lower slot) through the targets of every other live slot."""
    length = _tours(slots.target.astype(np.float64), slots.valid)
    return (length / CELLS).astype(np.float32)[..., None]


@compiled
def _tours(target: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(M, S) nearest-neighbour tour lengths in cells from each live slot of M robots; ``target``
    (M, S, 2) float, ``valid`` (M, S) bool."""
    count, n_slots = valid.shape
    length = np.zeros((count, n_slots))
    visited = np.zeros(n_slots, dtype=np.bool_)
    for m in range(count):
        for start in range(n_slots):
            if not valid[m, start]:
                continue
            for s in range(n_slots):
                visited[s] = not valid[m, s]
            visited[start] = True
            at, total = start, 0.0
            while True:
                nearest, best = -1, np.inf
                for s in range(n_slots):
                    if not visited[s]:
                        d_row = target[m, at, 0] - target[m, s, 0]
                        d_col = target[m, at, 1] - target[m, s, 1]
                        gap = np.sqrt(d_row * d_row + d_col * d_col)
                        if gap < best:  # strict: ties go to the lower slot
                            nearest, best = s, gap
                if nearest < 0:
                    break
                total += best
                visited[nearest] = True
                at = nearest
            length[m, start] = total
    return length


def turn_costs(slots: SlotArrays, positions: np.ndarray, motion: np.ndarray) -> np.ndarray:
    """(M, n_slots, 1) :data:`TURN_FEATURE` of M robots at ``positions`` (M, 2) that moved by
    ``motion`` (M, 2) cells over their last steps (0 on padding slots)."""
    ahead = slots.target - positions[:, None, :]  # (M, S, 2)
    to_target = np.linalg.norm(ahead, axis=-1)
    moved = np.linalg.norm(motion, axis=-1)[:, None]  # (M, 1)
    dot = (ahead * motion[:, None, :]).sum(axis=-1)
    scale = to_target * moved
    cosine = np.divide(dot, scale, out=np.ones_like(scale, dtype=np.float64), where=scale > 0)
    turn = np.where(slots.valid, 1.0 - cosine, 0.0)
    return turn.astype(np.float32)[..., None]


@compiled
def unknown_tables(beliefs: np.ndarray) -> np.ndarray:
    """(M, H + 1, W + 1) summed-area tables of the unknown cells of M beliefs (M, H, W):
    ``table[m, r, c]`` counts the unknown cells of rows < r and columns < c."""
    count, height, width = beliefs.shape
    table = np.zeros((count, height + 1, width + 1), dtype=np.int32)
    for m in range(count):
        for r in range(height):
            row = 0
            for c in range(width):
                row += beliefs[m, r, c] == UNKNOWN
                table[m, r + 1, c + 1] = table[m, r, c + 1] + row
    return table


def near_half_side(near_ranges: float | None, perception_range: int) -> int:
    """unknown_near's half-side in cells: :data:`NEAR` (``near_ranges`` None), else
    ``near_ranges`` sensor ranges, rounded, at least one cell."""
    return NEAR if near_ranges is None else max(1, round(near_ranges * perception_range))


def unknown_near(slots: SlotArrays, beliefs: np.ndarray, near: int = NEAR) -> np.ndarray:
    """(M, n_slots, 1) :data:`UNKNOWN_NEAR_FEATURE` of M robots (0 on padding slots):
    ``beliefs`` (B, H, W) are the B worlds' shared beliefs, the robots world after world (M / B
    robots each); ``near``: the square's half-side in cells."""
    worlds, height, width = beliefs.shape
    count = slots.valid.shape[0]
    if count % worlds:
        raise ValueError(f"{count} robots cannot share {worlds} belief maps evenly")
    table = unknown_tables(beliefs)  # one per world, not per robot
    rows, cols = slots.target[..., 0], slots.target[..., 1]
    top, bottom = np.clip(rows - near, 0, height), np.clip(rows + near + 1, 0, height)
    left, right = np.clip(cols - near, 0, width), np.clip(cols + near + 1, 0, width)
    world = (np.arange(count) // (count // worlds))[:, None]
    unknown = (
        table[world, bottom, right]
        - table[world, top, right]
        - table[world, bottom, left]
        + table[world, top, left]
    )
    fraction = np.where(slots.valid, unknown / (2 * near + 1) ** 2, 0.0)
    return fraction.astype(np.float32)[..., None]


def cluster_fill(slots: SlotArrays, max_cluster_cells: int) -> np.ndarray:
    """(M, n_slots, 1) :data:`FILL_FEATURE` of M robots: each slot's cluster size over
    ``max_cluster_cells`` (0 on padding slots)."""
    fill = np.where(slots.valid, slots.size / max_cluster_cells, 0.0)
    return fill.astype(np.float32)[..., None]


def log_utility(slots: SlotArrays, perception_range: int) -> np.ndarray:
    """(M, n_slots, 1) :data:`UTILITY_FEATURE` of M robots: ``(log(1 + gain) - log(1 +
    path length)) * (perception_range / UTILITY_RANGE) ** 4`` per slot (0 on padding slots)."""
    path = np.where(slots.valid, slots.path_length, 0)
    utility = np.log1p(np.where(slots.valid, slots.gain, 0)) - np.log1p(path)
    weight = (perception_range / UTILITY_RANGE) ** 4
    return np.where(slots.valid, weight * utility, 0.0).astype(np.float32)[..., None]


def team_features(slots: SlotArrays, teammates: np.ndarray) -> np.ndarray:
    """(M, n_slots, 3) :data:`TEAM_FEATURES` of M robots: ``teammates`` (M, T, 2) positions or
    (M, T, 4) positions and targets (row -1: heading nowhere) of each robot's T teammates."""
    target = slots.target.astype(np.float64)  # (M, S, 2)
    positions = teammates[:, None, :, 0:2]  # (M, 1, T, 2)
    mate_distance = np.linalg.norm(target[:, :, None, :] - positions, axis=-1).min(axis=2)
    heading = np.zeros_like(mate_distance)
    near = np.full_like(mate_distance, FAR)
    if teammates.shape[-1] == 4:
        goals = teammates[:, None, :, 2:4]
        going = goals[..., 0] >= 0  # (M, 1, T)
        apart = np.linalg.norm(target[:, :, None, :] - goals, axis=-1)  # (M, S, T)
        heading = ((apart == 0) & going).any(axis=2).astype(np.float64)
        nearest = np.where(going, apart, np.inf).min(axis=2) / CELLS
        near = np.minimum(nearest, FAR)
    features = np.stack([mate_distance / CELLS, heading, near], axis=-1)
    features[~slots.valid] = 0.0
    return features.astype(np.float32)
