"""Rendering of exploration states: RGB and plain-text frames (shown and saved by
:mod:`frontier_marl.render.viewer`).

A frame shows the *true* grid on the left and the *belief* grid on the right, separated by a
one-cell-wide neutral gap. Frontier cells (belief panel only) are tinted by cluster, cluster
centroids are drawn as outlined dots, and robots, their last-step paths and their targets are
drawn on both panels. Only numpy is needed here.
"""

from __future__ import annotations

import numpy as np

from frontier_marl.core.grid import FREE, OCCUPIED
from frontier_marl.render.drawing import (
    GRID_LINE_MIN_PX,
    cell_center_px,
    draw_hollow_square,
    draw_polyline,
    fill_disc,
    grid_lines,
    upscale,
)

__all__ = [
    "CLUSTER_PALETTE",
    "COLOR_FREE",
    "COLOR_GAP",
    "COLOR_OCCUPIED",
    "COLOR_UNKNOWN",
    "ROBOT_PALETTE",
    "frame_shape",
    "render_ansi",
    "render_rgb",
]

COLOR_FREE = np.array([255, 255, 255], dtype=np.uint8)
COLOR_OCCUPIED = np.array([30, 30, 30], dtype=np.uint8)
COLOR_UNKNOWN = np.array([128, 128, 128], dtype=np.uint8)
COLOR_GAP = np.array([205, 210, 220], dtype=np.uint8)
COLOR_OUTLINE = np.array([20, 20, 20], dtype=np.uint8)

#: Frontier-cluster colours (light tab20 shades, grey left out); cluster ``k`` uses
#: ``CLUSTER_PALETTE[(k - 1) % len(CLUSTER_PALETTE)]``.
CLUSTER_PALETTE = np.array(
    [
        [174, 199, 232],
        [255, 187, 120],
        [152, 223, 138],
        [255, 152, 150],
        [197, 176, 213],
        [196, 156, 148],
        [247, 182, 210],
        [219, 219, 141],
        [158, 218, 229],
    ],
    dtype=np.uint8,
)

#: Robot colours (saturated tab10 shades, grey left out); robot ``i`` uses
#: ``ROBOT_PALETTE[i % len(ROBOT_PALETTE)]``.
ROBOT_PALETTE = np.array(
    [
        [31, 119, 180],
        [214, 39, 40],
        [44, 160, 44],
        [255, 127, 14],
        [148, 103, 189],
        [23, 190, 207],
        [227, 119, 194],
        [140, 86, 75],
        [188, 189, 34],
    ],
    dtype=np.uint8,
)


# --------------------------------------------------------------------------- validation


def _as_grid(arr: np.ndarray, name: str) -> np.ndarray:
    arr = np.asarray(arr)
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"{name} must be a non-empty 2-D array, got shape {arr.shape}")
    return arr


def _as_cells(arr: np.ndarray, name: str, n: int | None = None) -> np.ndarray:
    """Validate an ``(n, 2)`` array of integer cell coordinates; return it as int64."""
    arr = np.asarray(arr)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"{name} must have shape (N, 2), got {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(f"{name} must have {n} rows (one per robot), got {arr.shape[0]}")
    integral = np.issubdtype(arr.dtype, np.integer) or np.all(np.equal(np.mod(arr, 1), 0))
    if arr.size and not integral:
        raise ValueError(f"{name} must hold integer cell coordinates")
    return arr.astype(np.int64, copy=False)


def _check_in_bounds(cells: np.ndarray, name: str, shape: tuple[int, int]) -> None:
    if cells.size == 0:
        return
    ok = (
        (cells[:, 0] >= 0)
        & (cells[:, 0] < shape[0])
        & (cells[:, 1] >= 0)
        & (cells[:, 1] < shape[1])
    )
    if not np.all(ok):
        bad = cells[~ok][0]
        raise ValueError(
            f"{name} has a cell outside the {shape} grid: {tuple(int(v) for v in bad)}"
        )


def _check_cell_px(cell_px: int) -> int:
    if isinstance(cell_px, bool) or not isinstance(cell_px, int | np.integer):
        raise ValueError(f"cell_px must be an int >= 1, got {cell_px!r}")
    if cell_px < 1:
        raise ValueError(f"cell_px must be >= 1, got {cell_px}")
    return int(cell_px)


def _check_labels(cluster_labels: np.ndarray | None, shape: tuple[int, int]) -> np.ndarray | None:
    if cluster_labels is None:
        return None
    labels = np.asarray(cluster_labels)
    if labels.shape != shape:
        raise ValueError(f"cluster_labels shape {labels.shape} does not match belief shape {shape}")
    return labels.astype(np.int64, copy=False)


# --------------------------------------------------------------------------- drawing helpers


def frame_shape(grid_shape: tuple[int, int], cell_px: int = 12) -> tuple[int, int, int]:
    """Shape of the frame :func:`render_rgb` returns for a grid of ``grid_shape``.

    ``(H * cell_px, (2 * W + 1) * cell_px, 3)``: two panels plus a one-cell gap.
    """
    h, w = grid_shape
    return (h * cell_px, (2 * w + 1) * cell_px, 3)


# --------------------------------------------------------------------------- public API


def render_rgb(
    true_grid: np.ndarray,
    belief: np.ndarray,
    positions: np.ndarray,
    cluster_labels: np.ndarray | None = None,
    centroids: np.ndarray | None = None,
    paths: list[np.ndarray] | None = None,
    targets: np.ndarray | None = None,
    cell_px: int = 12,
) -> np.ndarray:
    """Render one RGB frame: true grid (left) | gap | belief grid (right).

    Args:
        true_grid: bool ``(H, W)``, ``True`` = occupied.
        belief: int ``(H, W)`` with ``UNKNOWN``/``FREE``/``OCCUPIED`` codes (others = unknown).
        positions: int ``(N, 2)`` robot cells ``(row, col)``.
        cluster_labels: int ``(H, W)``; 0 = no frontier, ``k >= 1`` = frontier cluster ``k``.
            Frontier cells are tinted on the belief panel only.
        centroids: float ``(K, 2)``; row ``k - 1`` is the centroid of cluster ``k`` (NaN rows
            are skipped). Drawn on the belief panel only.
        paths: one int ``(L, 2)`` array per robot (cells walked in the last step), or ``None``
            entries; drawn as lines through cell centres on both panels.
        targets: int ``(N, 2)`` target cell per robot; rows with a negative entry mean "no
            target". Drawn as hollow squares on both panels.
        cell_px: pixel size of one cell (``>= 1``). Grid lines are drawn when ``>= 6``.

    Returns:
        ``uint8`` array of shape ``frame_shape(true_grid.shape, cell_px)``.
    """
    cell_px = _check_cell_px(cell_px)
    true_grid = _as_grid(true_grid, "true_grid")
    belief = _as_grid(belief, "belief")
    if belief.shape != true_grid.shape:
        raise ValueError(
            f"belief shape {belief.shape} does not match true_grid shape {true_grid.shape}"
        )
    shape: tuple[int, int] = (int(true_grid.shape[0]), int(true_grid.shape[1]))
    positions = _as_cells(positions, "positions")
    _check_in_bounds(positions, "positions", shape)
    n_robots = positions.shape[0]
    labels = _check_labels(cluster_labels, shape)
    cents = _check_centroids(centroids)
    path_list = _check_paths(paths, n_robots, shape)
    tgt = None if targets is None else _check_targets(targets, n_robots, shape)

    frame = _panels(true_grid, belief, labels, cell_px)
    pw = shape[1] * cell_px
    offsets = (0, pw + cell_px)  # column offset of each panel in pixels
    robot_colors = ROBOT_PALETTE[np.arange(n_robots) % len(ROBOT_PALETTE)]
    if cents is not None:
        _draw_centroids(frame, cents, cell_px, offsets[1], pw)
    if tgt is not None:
        _draw_targets(frame, tgt, robot_colors, cell_px, offsets)
    _draw_paths(frame, path_list, robot_colors, cell_px, offsets, pw)
    _draw_robots(frame, positions, robot_colors, cell_px, offsets, pw)
    return frame


def _check_centroids(centroids: np.ndarray | None) -> np.ndarray | None:
    if centroids is None:
        return None
    cents = np.asarray(centroids, dtype=np.float64)
    if cents.size == 0:
        cents = cents.reshape(0, 2)
    if cents.ndim != 2 or cents.shape[1] != 2:
        raise ValueError(f"centroids must have shape (K, 2), got {cents.shape}")
    return cents


def _check_paths(
    paths: list[np.ndarray] | None, n_robots: int, shape: tuple[int, int]
) -> list[np.ndarray | None]:
    path_list: list[np.ndarray | None] = []
    if paths is None:
        return path_list
    if len(paths) != n_robots:
        raise ValueError(f"paths must have one entry per robot ({n_robots}), got {len(paths)}")
    for i, p in enumerate(paths):
        if p is None or np.asarray(p).size == 0:
            path_list.append(None)
            continue
        cells = _as_cells(p, f"paths[{i}]")
        _check_in_bounds(cells, f"paths[{i}]", shape)
        path_list.append(cells)
    return path_list


def _check_targets(targets: np.ndarray, n_robots: int, shape: tuple[int, int]) -> np.ndarray:
    tgt = _as_cells(targets, "targets", n=n_robots)
    valid = np.all(tgt >= 0, axis=1)
    _check_in_bounds(tgt[valid], "targets", shape)
    return tgt


def _panels(
    true_grid: np.ndarray, belief: np.ndarray, labels: np.ndarray | None, cell_px: int
) -> np.ndarray:
    """The frame's two panels (true grid | gap | belief with frontier tints), no overlays."""
    h, w = true_grid.shape
    true_rgb = np.where(np.asarray(true_grid, dtype=bool)[..., None], COLOR_OCCUPIED, COLOR_FREE)
    b = np.asarray(belief)
    belief_rgb = np.empty((h, w, 3), dtype=np.uint8)
    belief_rgb[:] = COLOR_UNKNOWN
    belief_rgb[b == FREE] = COLOR_FREE
    belief_rgb[b == OCCUPIED] = COLOR_OCCUPIED
    if labels is not None:
        fmask = labels > 0
        if np.any(fmask):
            belief_rgb[fmask] = CLUSTER_PALETTE[(labels[fmask] - 1) % len(CLUSTER_PALETTE)]

    true_panel = upscale(true_rgb.astype(np.uint8, copy=False), cell_px)
    belief_panel = upscale(belief_rgb, cell_px)
    grid_lines(true_panel, cell_px)
    grid_lines(belief_panel, cell_px)

    frame = np.empty(frame_shape((int(h), int(w)), cell_px), dtype=np.uint8)
    pw = w * cell_px
    frame[:, :pw] = true_panel
    frame[:, pw : pw + cell_px] = COLOR_GAP
    frame[:, pw + cell_px :] = belief_panel
    return frame


def _draw_centroids(frame: np.ndarray, cents: np.ndarray, cell_px: int, x0: int, pw: int) -> None:
    """Cluster centroids as outlined dots on the belief panel (NaN rows skipped)."""
    r_dot = max(0.22 * cell_px, 0.5)
    r_out = r_dot + max(1.0, cell_px / 12.0)
    for k, c in enumerate(cents):
        if not np.all(np.isfinite(c)):
            continue
        cy, cx = cell_center_px(c, cell_px)
        color = CLUSTER_PALETTE[k % len(CLUSTER_PALETTE)]
        if cell_px >= 4:
            fill_disc(frame, cy, cx + x0, r_out, COLOR_OUTLINE, x0, x0 + pw)
        fill_disc(frame, cy, cx + x0, r_dot, color, x0, x0 + pw)


def _draw_targets(
    frame: np.ndarray,
    tgt: np.ndarray,
    robot_colors: np.ndarray,
    cell_px: int,
    offsets: tuple[int, int],
) -> None:
    """Each robot's target as a hollow square in its colour on both panels."""
    thick = max(1, cell_px // 6)
    for i in range(len(tgt)):
        if np.any(tgt[i] < 0):
            continue
        for off in offsets:
            draw_hollow_square(frame, tgt[i, 0], tgt[i, 1], cell_px, thick, robot_colors[i], off)


def _draw_paths(
    frame: np.ndarray,
    path_list: list[np.ndarray | None],
    robot_colors: np.ndarray,
    cell_px: int,
    offsets: tuple[int, int],
    pw: int,
) -> None:
    """The cells each robot walked in the last step, as lines through cell centres."""
    width = max(1, cell_px // 6)
    for i, cells in enumerate(path_list):
        if cells is None:
            continue
        pts = cell_center_px(cells, cell_px)
        for off in offsets:
            draw_polyline(frame, pts + [0.0, off], width, robot_colors[i], off, off + pw)


def _draw_robots(
    frame: np.ndarray,
    positions: np.ndarray,
    robot_colors: np.ndarray,
    cell_px: int,
    offsets: tuple[int, int],
    pw: int,
) -> None:
    """Robots as outlined discs in their colours on both panels."""
    r_robot = max(0.38 * cell_px, 0.5)
    r_robot_out = r_robot + max(1.0, cell_px / 12.0)
    for i in range(len(positions)):
        cy, cx = cell_center_px(positions[i], cell_px)
        for off in offsets:
            if cell_px >= GRID_LINE_MIN_PX:
                fill_disc(frame, cy, cx + off, r_robot_out, COLOR_OUTLINE, off, off + pw)
            fill_disc(frame, cy, cx + off, r_robot, robot_colors[i], off, off + pw)


def render_ansi(
    belief: np.ndarray, positions: np.ndarray, cluster_labels: np.ndarray | None = None
) -> str:
    """Plain-text frame of the belief grid, one line per row.

    ``'#'`` occupied, ``'.'`` free, ``'?'`` unknown, ``'a'..'z'`` frontier cluster 1, 2, ...
    (cycling), and ``'0'..'9'`` robot ``i`` (``i mod 10``), drawn on top.
    """
    belief = _as_grid(belief, "belief")
    shape: tuple[int, int] = (int(belief.shape[0]), int(belief.shape[1]))
    positions = _as_cells(positions, "positions")
    _check_in_bounds(positions, "positions", shape)
    labels = _check_labels(cluster_labels, shape)

    chars = np.full(shape, "?", dtype="<U1")
    chars[belief == FREE] = "."
    chars[belief == OCCUPIED] = "#"
    if labels is not None:
        fmask = labels > 0
        letters = np.array([chr(ord("a") + i) for i in range(26)], dtype="<U1")
        chars[fmask] = letters[(labels[fmask] - 1) % 26]
    for i, (r, c) in enumerate(positions):
        chars[r, c] = str(i % 10)
    return "\n".join("".join(row) for row in chars)
