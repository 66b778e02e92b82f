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
DISTANCE_SCALE = 64.0  # cells: the distance channel reads 1 from here on
_HALF = SIDE // 2
_PAD = (_HALF + 1) * max(SCALES)  # margin that every window fits in


def crop_shape() -> tuple[int, int, int]:
    """(channels, side, side) of one candidate's crops: every channel at every scale."""
    return len(CHANNELS) * len(SCALES), SIDE, SIDE


def map_planes(belief: np.ndarray, frontier: np.ndarray, position: tuple[int, int]) -> np.ndarray:
    """(4, H, W) float planes shared by every candidate: unknown, obstacle, frontier, distance
    (``frontier`` is a bool (H, W) mask; ``position`` the robot's cell)."""
    unknown = belief == UNKNOWN
    free = belief == FREE
    dist = distance_field(free, True, int(position[0]), int(position[1])).astype(np.float64)
    scaled = np.where(dist >= 0, np.minimum(dist / DISTANCE_SCALE, 1.0), 1.0)
    return np.stack([unknown, belief == OCCUPIED, frontier, scaled]).astype(np.float64)


def candidate_crops(
    planes: np.ndarray,
    targets: np.ndarray,
    cluster_cells: list[np.ndarray],
) -> np.ndarray:
    """(M, channels, SIDE, SIDE) float32 crops of M candidates: ``planes`` from
    :func:`map_planes`, ``targets`` (M, 2) cells, ``cluster_cells[m]`` the (K, 2) cells of
    candidate m's cluster."""
    targets = np.asarray(targets, dtype=np.int64).reshape(-1, 2)
    count = len(targets)
    shared = _window_means(planes, targets)  # (M, S, 4, SIDE, SIDE)
    cluster = np.zeros((count, len(SCALES), SIDE, SIDE))
    for m, cells in enumerate(cluster_cells):
        for k, scale in enumerate(SCALES):
            cluster[m, k] = _binned(np.asarray(cells).reshape(-1, 2), targets[m], scale)
    stacked = np.concatenate(
        [shared[:, :, :3], cluster[:, :, None], shared[:, :, 3:]], axis=2
    )  # channel order of CHANNELS
    channels, side, _ = crop_shape()
    return stacked.reshape(count, channels, side, side).astype(np.float32)


def slot_crops(env: Any, slots: np.ndarray, robot: int = 0) -> np.ndarray:
    """(M, channels, SIDE, SIDE) crops of the given slots of ``robot`` in a ParallelEnv (its
    shared belief, frontier clusters and slot table), quantised to 1/255 as they are stored
    for training."""
    world = env.world
    table = env.mdp.slot_tables()[robot]
    clusters = world.clusters()
    frontier = np.zeros(world.shape, dtype=bool)
    frontier[clusters.cell_rows, clusters.cell_cols] = True
    planes = map_planes(world.belief, frontier, tuple(world.positions[robot]))
    cells = [clusters.cells_of(int(table.cluster[slot])) for slot in slots]
    crops = candidate_crops(planes, table.target[slots], cells)
    return (np.round(crops * 255.0) / 255.0).astype(np.float32)


def _window_means(planes: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """(M, S, P, SIDE, SIDE) mean of each plane over each window cell (beyond the map: the
    outside values of :func:`_padded`)."""
    tables = _summed_areas(_padded(planes))  # (P, H + 2 pad + 1, W + 2 pad + 1)
    offsets = np.arange(SIDE) - _HALF
    out = np.empty((len(targets), len(SCALES), len(planes), SIDE, SIDE))
    for k, scale in enumerate(SCALES):
        low = offsets * scale - scale // 2 + _PAD  # window start per crop row, padded coords
        rows = targets[:, 0, None] + low  # (M, SIDE)
        cols = targets[:, 1, None] + low
        top, bottom = rows[:, :, None], rows[:, :, None] + scale
        left, right = cols[:, None, :], cols[:, None, :] + scale
        sums = (
            tables[:, top, left]
            - tables[:, top, right]
            - tables[:, bottom, left]
            + tables[:, bottom, right]
        )  # (P, M, SIDE, SIDE)
        out[:, k] = np.moveaxis(sums, 0, 1) / (scale * scale)
    return out


def _padded(planes: np.ndarray) -> np.ndarray:
    """The planes with a margin of :data:`_PAD` cells: beyond the map is known obstacle, no
    frontier, unreachable."""
    outside = np.array([0.0, 1.0, 0.0, 1.0])[:, None, None]
    count, height, width = planes.shape
    out = np.broadcast_to(outside, (count, height + 2 * _PAD, width + 2 * _PAD)).copy()
    out[:, _PAD : _PAD + height, _PAD : _PAD + width] = planes
    return out


def _summed_areas(planes: np.ndarray) -> np.ndarray:
    """Summed-area tables with a leading zero row and column: ``t[r, c]`` sums rows < r,
    columns < c."""
    count, height, width = planes.shape
    tables = np.zeros((count, height + 1, width + 1))
    tables[:, 1:, 1:] = planes.cumsum(axis=1).cumsum(axis=2)
    return tables


def _binned(cells: np.ndarray, target: np.ndarray, scale: int) -> np.ndarray:
    """(SIDE, SIDE) fraction of each window cell's map cells that are in ``cells``."""
    grid = np.zeros((SIDE, SIDE))
    shifted = cells - target + scale // 2 + _HALF * scale
    index = np.floor_divide(shifted, scale)
    inside = ((index >= 0) & (index < SIDE)).all(axis=1)
    np.add.at(grid, (index[inside, 0], index[inside, 1]), 1.0)
    return grid / (scale * scale)
