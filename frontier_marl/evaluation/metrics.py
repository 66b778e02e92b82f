"""Exploration metrics: coverage-versus-travel curves, cells to reach a coverage level, overlap.

A *coverage curve* is an ``(L, 2)`` float array of ``(cells travelled, coverage)`` points in
step order: the team's total travelled cells and the fraction of the reachable free region
known, recorded at reset and after every decision step. Both columns never decrease.
A *makespan curve* has the same form with the longest single robot path in the first column
(the team's elapsed time in cell moves, since robots move at the same time); the same
functions (:func:`cells_to_coverage`, :func:`mean_curve`) apply to it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def coverage_curve(travelled: Sequence[float], coverage: Sequence[float]) -> np.ndarray:
    """Stack matching ``travelled`` and ``coverage`` sequences into an ``(L, 2)`` curve."""
    travelled_arr = np.asarray(travelled, dtype=float)
    coverage_arr = np.asarray(coverage, dtype=float)
    if travelled_arr.shape != coverage_arr.shape or travelled_arr.ndim != 1:
        raise ValueError(
            "travelled and coverage must be 1-D sequences of equal length, got shapes "
            f"{travelled_arr.shape} and {coverage_arr.shape}"
        )
    return np.stack([travelled_arr, coverage_arr], axis=1)


def makespan_curve(robot_travelled: np.ndarray, coverage: Sequence[float]) -> np.ndarray:
    """Coverage versus the longest single robot path so far (coverage versus time: robots move
    at the same time, one cell per move).

    ``robot_travelled`` is ``(L, N)``: each robot's travelled cells at each recorded point.
    """
    per_robot = np.asarray(robot_travelled, dtype=float)
    if per_robot.ndim != 2 or per_robot.shape[1] == 0:
        raise ValueError(f"robot_travelled must have shape (L, N >= 1), got {per_robot.shape}")
    return coverage_curve(per_robot.max(axis=1), coverage)


def _check_curve(curve: np.ndarray) -> np.ndarray:
    curve = np.asarray(curve, dtype=float)
    if curve.ndim != 2 or curve.shape[1] != 2 or len(curve) == 0:
        raise ValueError(f"curve must have shape (L >= 1, 2), got {curve.shape}")
    return curve


def cells_to_coverage(curve: np.ndarray, level: float) -> float | None:
    """Cells travelled when coverage first reaches ``level``; ``None`` if it never does."""
    if not 0.0 < level <= 1.0:
        raise ValueError(f"level must be in (0, 1], got {level!r}")
    curve = _check_curve(curve)
    # A tiny tolerance so that e.g. 0.9 of 100 cells counts at exactly 90 known cells.
    hits = np.flatnonzero(curve[:, 1] >= level - 1e-12)
    return None if len(hits) == 0 else float(curve[hits[0], 0])


def resample_curve(curve: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Coverage at each travelled value of ``grid``: the last point at or before it (a step
    function); before the first point, the first coverage; after the last, the final one."""
    curve = _check_curve(curve)
    grid = np.asarray(grid, dtype=float)
    index = np.searchsorted(curve[:, 0], grid, side="right") - 1
    return curve[np.clip(index, 0, len(curve) - 1), 1]


def mean_curve(
    curves: Sequence[np.ndarray], points: int = 200
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean and (population) std of coverage over episodes on a common travelled grid.

    Each episode's coverage is held at its final value after its end. Returns
    ``(grid, mean, std)``, each of length ``points``.
    """
    if len(curves) == 0:
        raise ValueError("curves must not be empty")
    if points < 2:
        raise ValueError(f"points must be >= 2, got {points}")
    checked = [_check_curve(c) for c in curves]
    top = max(float(c[-1, 0]) for c in checked)
    grid = np.linspace(0.0, max(top, 1.0), points)
    values = np.stack([resample_curve(c, grid) for c in checked])
    return grid, values.mean(axis=0), values.std(axis=0)


def mean_std(values: Sequence[float]) -> tuple[float, float]:
    """Mean and population standard deviation (numpy's default, as SB3's
    ``evaluate_policy``); ``(nan, nan)`` for an empty sequence."""
    arr = np.asarray(values, dtype=float)
    if arr.size == 0:
        return float("nan"), float("nan")
    return float(arr.mean()), float(arr.std())


def action_shares(counts: Sequence[int]) -> list[float]:
    """Share of each slot among all decisions (all zeros when there were none)."""
    arr = np.asarray(counts, dtype=float)
    total = arr.sum()
    return [0.0] * len(arr) if total == 0 else (arr / total).tolist()


def overlap_ratio(seen_masks: np.ndarray) -> float:
    """Redundant sensing of a team: ``sum of per-robot seen areas / area of their union - 1``.

    0 when no cell was seen by two robots, ``N - 1`` when all ``N`` robots saw the same cells;
    0 when nothing was seen. ``seen_masks`` is ``(N, H, W)`` bool (e.g. ``world.seen``).
    """
    masks = np.asarray(seen_masks, dtype=bool)
    if masks.ndim != 3:
        raise ValueError(f"seen_masks must have shape (N, H, W), got {masks.shape}")
    union = int(np.count_nonzero(masks.any(axis=0)))
    if union == 0:
        return 0.0
    return float(np.count_nonzero(masks)) / union - 1.0
