"""What a map-aware scorer sees of the belief around each candidate: egocentric crops at
several scales.

For each candidate (a slot's target cell) :func:`candidate_crops` cuts :data:`SIDE` x
:data:`SIDE` windows centred on the target at each scale of :data:`SCALES` (a window cell at
scale ``s`` averages ``s x s`` map cells), with the channels of :data:`CHANNELS`, each a
fraction in [0, 1]:

``unknown``   unknown cells of the shared belief
``obstacle``  known obstacles, and everything beyond the map's edge
``frontier``  frontier cells (known free cells next to unknown ones)
``cluster``   the candidate's own frontier cluster
``distance``  the robot's known-free path length to each cell, / :data:`DISTANCE_SCALE`,
              capped at 1 (1 where the robot cannot go on known cells)

A team's scorer also sees its teammates (:data:`TEAM_CHANNELS`, given the teammates' targets):

``mates``          the teammates' cells
``mate_targets``   the teammates' targets
``mate_distance``  the known-free path length from the nearest teammate, as ``distance``

The crops depend on the map's size only through what they show, so one scorer reads a 20x20
grid and a 96x96 floor plan alike; at scale 9 an 11 x 11 window spans 99 cells. Everything is
numpy (no torch): the training data and the policy build the crops with this one function.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN
from frontier_marl.core.planning import distance_field

SIDE = 11
SCALES = (1, 3, 9)
CHANNELS = ("unknown", "obstacle", "frontier", "cluster", "distance")
TEAM_CHANNELS = (*CHANNELS, "mates", "mate_targets", "mate_distance")
DISTANCE_SCALE = 64.0  # cells: the distance channel reads 1 from here on
_HALF = SIDE // 2
#: What each plane of :func:`map_planes` and then :func:`teammate_planes` reads beyond the
#: map's edge: known obstacle, no frontier, unreachable; no teammate, unreachable.
_OUTSIDE = np.array([0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0])


def crop_shape(team: bool = False) -> tuple[int, int, int]:
    """(channels, side, side) of one candidate's crops: every channel (of a team's scorer:
    :data:`TEAM_CHANNELS`) at every scale."""
    return len(TEAM_CHANNELS if team else CHANNELS) * len(SCALES), SIDE, SIDE


def map_planes(belief: np.ndarray, frontier: np.ndarray, position: tuple[int, int]) -> np.ndarray:
    """(4, H, W) float planes shared by every candidate: unknown, obstacle, frontier, distance
    (``frontier`` is a bool (H, W) mask; ``position`` the robot's cell)."""
    unknown = belief == UNKNOWN
    free = belief == FREE
    dist = distance_field(free, True, int(position[0]), int(position[1])).astype(np.float64)
    return np.stack([unknown, belief == OCCUPIED, frontier, _scaled(dist)]).astype(np.float64)


def teammate_planes(belief: np.ndarray, cells: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """(3, H, W) float planes of a robot's teammates: their ``cells`` (K, 2), their
    ``targets`` (K, 2; row -1: none) and the known-free path length from the nearest of them
    (as the ``distance`` plane; 1 everywhere without teammates)."""
    planes = np.zeros((3, *belief.shape))
    nearest = np.full(belief.shape, np.inf)
    free = belief == FREE
    for row, col in np.asarray(cells, dtype=np.int64).reshape(-1, 2):
        planes[0, row, col] = 1.0
        dist = distance_field(free, True, int(row), int(col)).astype(np.float64)
        nearest = np.minimum(nearest, np.where(dist >= 0, dist, np.inf))
    for row, col in np.asarray(targets, dtype=np.int64).reshape(-1, 2):
        if row >= 0:
            planes[1, row, col] = 1.0
    planes[2] = _scaled(np.where(np.isfinite(nearest), nearest, -1.0))
    return planes


def _scaled(dist: np.ndarray) -> np.ndarray:
    """Path lengths (-1: unreachable) / :data:`DISTANCE_SCALE`, capped at 1 (1: unreachable)."""
    return np.where(dist >= 0, np.minimum(dist / DISTANCE_SCALE, 1.0), 1.0)


def candidate_crops(
    planes: np.ndarray,
    targets: np.ndarray,
    cluster_cells: list[np.ndarray],
) -> np.ndarray:
    """(M, channels, SIDE, SIDE) float32 crops of M candidates: ``planes`` from
    :func:`map_planes` (and, for a team's scorer, :func:`teammate_planes` after them),
    ``targets`` (M, 2) cells, ``cluster_cells[m]`` the (K, 2) cells of candidate m's
    cluster; the channels in the order of :data:`CHANNELS` (:data:`TEAM_CHANNELS`)."""
    targets = np.asarray(targets, dtype=np.int64).reshape(-1, 2)
    count = len(targets)
    shared = _window_means(planes, targets)  # (M, S, P, SIDE, SIDE)
    cluster = _cluster_windows(cluster_cells, targets)  # (M, S, SIDE, SIDE)
    stacked = np.concatenate(
        [shared[:, :, :3], cluster[:, :, None], shared[:, :, 3:]], axis=2
    )  # channel order of CHANNELS, then the teammates'
    channels, side, _ = crop_shape(team=len(planes) == len(TEAM_CHANNELS) - 1)
    return stacked.reshape(count, channels, side, side).astype(np.float32)


def slot_crops(
    env: Any, slots: np.ndarray, robot: int = 0, mate_targets: np.ndarray | None = None
) -> np.ndarray:
    """(M, channels, SIDE, SIDE) crops of the given slots of ``robot`` in a ParallelEnv (its
    shared belief, frontier clusters and slot table), quantised to 1/255 as they are stored
    for training. With ``mate_targets`` (K, 2: every robot's target, row -1 for none; the
    robot's own row is ignored) the crops of a team's scorer, the teammates' channels
    included."""
    world = env.world
    table = env.mdp.slot_tables()[robot]
    clusters = world.clusters()
    frontier = np.zeros(world.shape, dtype=bool)
    frontier[clusters.cell_rows, clusters.cell_cols] = True
    planes = map_planes(world.belief, frontier, tuple(world.positions[robot]))
    if mate_targets is not None:
        mates = np.delete(np.arange(len(world.positions)), robot)
        team = teammate_planes(world.belief, world.positions[mates], mate_targets[mates])
        planes = np.concatenate([planes, team])
    cells = [clusters.cells_of(int(table.cluster[slot])) for slot in slots]
    crops = candidate_crops(planes, table.target[slots], cells)
    return (np.round(crops * 255.0) / 255.0).astype(np.float32)


def _window_means(planes: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """(M, S, P, SIDE, SIDE) mean of each plane over each window cell; the part of a window
    beyond the map reads the plane's :data:`_OUTSIDE` value. Every plane value is a multiple
    of 1 / :data:`DISTANCE_SCALE` (a power of two), so the summed areas are exact and any order
    of summation gives the same means."""
    height, width = planes.shape[1:]
    tables = _summed_areas(planes)  # (P, H + 1, W + 1)
    outside = _OUTSIDE[: len(planes), None, None, None]
    offsets = np.arange(SIDE) - _HALF
    out = np.empty((len(targets), len(SCALES), len(planes), SIDE, SIDE))
    for k, scale in enumerate(SCALES):
        low = offsets * scale - scale // 2  # window start per crop row, relative to the target
        rows = targets[:, 0, None] + low  # (M, SIDE)
        cols = targets[:, 1, None] + low
        top, bottom = np.clip(rows, 0, height), np.clip(rows + scale, 0, height)
        left, right = np.clip(cols, 0, width), np.clip(cols + scale, 0, width)
        top, bottom = top[:, :, None], bottom[:, :, None]
        left, right = left[:, None, :], right[:, None, :]
        inside = (bottom - top) * (right - left)  # (M, SIDE, SIDE) map cells in each window
        sums = (
            tables[:, top, left]
            - tables[:, top, right]
            - tables[:, bottom, left]
            + tables[:, bottom, right]
            + outside * (scale * scale - inside)
        )  # (P, M, SIDE, SIDE)
        out[:, k] = np.moveaxis(sums, 0, 1) / (scale * scale)
    return out


def _summed_areas(planes: np.ndarray) -> np.ndarray:
    """Summed-area tables with a leading zero row and column: ``t[r, c]`` sums rows < r,
    columns < c."""
    count, height, width = planes.shape
    tables = np.zeros((count, height + 1, width + 1))
    np.cumsum(planes, axis=1, out=tables[:, 1:, 1:])
    np.cumsum(tables[:, 1:, 1:], axis=2, out=tables[:, 1:, 1:])
    return tables


def _cluster_windows(cluster_cells: list[np.ndarray], targets: np.ndarray) -> np.ndarray:
    """(M, S, SIDE, SIDE) fraction of each window cell's map cells that are in candidate m's
    cluster, at every scale, counted in one ``bincount``."""
    count, n_scales = len(targets), len(SCALES)
    cells = [np.asarray(c, dtype=np.int64).reshape(-1, 2) for c in cluster_cells]
    owner = np.repeat(np.arange(count), [len(c) for c in cells])
    shifted = np.concatenate([*cells, np.zeros((0, 2), np.int64)]) - targets[owner]
    counts = np.zeros(count * n_scales * SIDE * SIDE)
    for k, scale in enumerate(SCALES):
        index = np.floor_divide(shifted + scale // 2 + _HALF * scale, scale)
        inside = ((index >= 0) & (index < SIDE)).all(axis=1)
        flat = ((owner[inside] * n_scales + k) * SIDE + index[inside, 0]) * SIDE
        counts += np.bincount(flat + index[inside, 1], minlength=len(counts))
    scale_area = np.array(SCALES, dtype=np.float64)[None, :, None, None] ** 2
    return counts.reshape(count, n_scales, SIDE, SIDE) / scale_area
