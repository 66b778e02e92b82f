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

_GRID_LINE_MIN_PX = 6
_GRID_LINE_FACTOR = 0.8


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


def _cell_center_px(rc: np.ndarray, cell_px: int) -> np.ndarray:
    """Pixel coordinates (float) of the centre of (possibly fractional) cell coordinates."""
    return np.asarray(rc, dtype=np.float64) * cell_px + (cell_px - 1) / 2.0


def _fill_disc(
    img: np.ndarray, cy: float, cx: float, radius: float, color: np.ndarray, x0: int, x1: int
) -> None:
    """Fill a disc into ``img``, clipped to the columns ``[x0, x1)`` (one panel)."""
    h = img.shape[0]
    r0, r1 = max(int(np.floor(cy - radius)), 0), min(int(np.ceil(cy + radius)) + 1, h)
    c0, c1 = max(int(np.floor(cx - radius)), x0), min(int(np.ceil(cx + radius)) + 1, x1)
    if r0 >= r1 or c0 >= c1:
        return
    yy = np.arange(r0, r1, dtype=np.float64)[:, None] - cy
    xx = np.arange(c0, c1, dtype=np.float64)[None, :] - cx
    mask = yy * yy + xx * xx <= radius * radius
    img[r0:r1, c0:c1][mask] = color


def _draw_polyline(
    img: np.ndarray, pts: np.ndarray, width: int, color: np.ndarray, x0: int, x1: int
) -> None:
    """Draw a polyline through float pixel points ``pts`` (L, 2), clipped to columns [x0, x1)."""
    if len(pts) < 2:
        return
    seg = np.diff(pts, axis=0)
    n = np.maximum(np.ceil(np.abs(seg).max(axis=1) * 2).astype(np.int64), 1)
    idx = np.repeat(np.arange(len(seg)), n)
    t = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    samples = pts[idx] + seg[idx] * t[:, None]
    samples = np.vstack([samples, pts[-1:]])
    half = (width - 1) / 2.0
    offs = np.arange(width, dtype=np.float64) - half
    oy, ox = np.meshgrid(offs, offs, indexing="ij")
    all_pts = samples[:, None, :] + np.stack([oy.ravel(), ox.ravel()], axis=1)[None]
    ij = np.rint(all_pts.reshape(-1, 2)).astype(np.int64)
    keep = (ij[:, 0] >= 0) & (ij[:, 0] < img.shape[0]) & (ij[:, 1] >= x0) & (ij[:, 1] < x1)
    ij = ij[keep]
    img[ij[:, 0], ij[:, 1]] = color


def _draw_hollow_square(
    img: np.ndarray, row: int, col: int, cell_px: int, thick: int, color: np.ndarray, x_off: int
) -> None:
    """Outline the cell ``(row, col)`` with a border ``thick`` pixels wide."""
    y0, x0 = row * cell_px, x_off + col * cell_px
    y1, x1 = y0 + cell_px, x0 + cell_px
    t = min(thick, max(cell_px // 2, 1))
    img[y0 : y0 + t, x0:x1] = color
    img[y1 - t : y1, x0:x1] = color
    img[y0:y1, x0 : x0 + t] = color
    img[y0:y1, x1 - t : x1] = color


def _upscale(cells_rgb: np.ndarray, cell_px: int) -> np.ndarray:
    if cell_px == 1:
        return cells_rgb
    return np.repeat(np.repeat(cells_rgb, cell_px, axis=0), cell_px, axis=1)


def _grid_lines(panel: np.ndarray, cell_px: int) -> None:
    """Darken the first pixel row/column of every cell except the outer ones, in place."""
    if cell_px < _GRID_LINE_MIN_PX:
        return
    rows = np.arange(cell_px, panel.shape[0], cell_px)
    cols = np.arange(cell_px, panel.shape[1], cell_px)
    panel[rows, :] = (panel[rows, :] * _GRID_LINE_FACTOR).astype(np.uint8)
    panel[:, cols] = (panel[:, cols] * _GRID_LINE_FACTOR).astype(np.uint8)


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
    h, w = shape
    positions = _as_cells(positions, "positions")
    _check_in_bounds(positions, "positions", shape)
    n_robots = positions.shape[0]
    labels = _check_labels(cluster_labels, shape)

    cents: np.ndarray | None = None
    if centroids is not None:
        cents = np.asarray(centroids, dtype=np.float64)
        if cents.size == 0:
            cents = cents.reshape(0, 2)
        if cents.ndim != 2 or cents.shape[1] != 2:
            raise ValueError(f"centroids must have shape (K, 2), got {cents.shape}")

    path_list: list[np.ndarray | None] = []
    if paths is not None:
        if len(paths) != n_robots:
            raise ValueError(f"paths must have one entry per robot ({n_robots}), got {len(paths)}")
        for i, p in enumerate(paths):
            if p is None or np.asarray(p).size == 0:
                path_list.append(None)
                continue
            cells = _as_cells(p, f"paths[{i}]")
            _check_in_bounds(cells, f"paths[{i}]", shape)
            path_list.append(cells)

    tgt: np.ndarray | None = None
    if targets is not None:
        tgt = _as_cells(targets, "targets", n=n_robots)
        valid = np.all(tgt >= 0, axis=1)
        _check_in_bounds(tgt[valid], "targets", shape)

    # -- per-cell colours ------------------------------------------------------------------
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

    true_panel = _upscale(true_rgb.astype(np.uint8, copy=False), cell_px)
    belief_panel = _upscale(belief_rgb, cell_px)
    _grid_lines(true_panel, cell_px)
    _grid_lines(belief_panel, cell_px)

    frame = np.empty(frame_shape(shape, cell_px), dtype=np.uint8)
    pw = w * cell_px
    frame[:, :pw] = true_panel
    frame[:, pw : pw + cell_px] = COLOR_GAP
    frame[:, pw + cell_px :] = belief_panel
    offsets = (0, pw + cell_px)  # column offset of each panel in pixels

    # -- overlays --------------------------------------------------------------------------
    if cents is not None and len(cents):
        r_dot = max(0.22 * cell_px, 0.5)
        r_out = r_dot + max(1.0, cell_px / 12.0)
        x0 = offsets[1]
        for k, c in enumerate(cents):
            if not np.all(np.isfinite(c)):
                continue
            cy, cx = _cell_center_px(c, cell_px)
            color = CLUSTER_PALETTE[k % len(CLUSTER_PALETTE)]
            if cell_px >= 4:
                _fill_disc(frame, cy, cx + x0, r_out, COLOR_OUTLINE, x0, x0 + pw)
            _fill_disc(frame, cy, cx + x0, r_dot, color, x0, x0 + pw)

    robot_colors = ROBOT_PALETTE[np.arange(n_robots) % len(ROBOT_PALETTE)]
    if tgt is not None:
        thick = max(1, cell_px // 6)
        for i in range(n_robots):
            if np.any(tgt[i] < 0):
                continue
            for off in offsets:
                _draw_hollow_square(
                    frame, tgt[i, 0], tgt[i, 1], cell_px, thick, robot_colors[i], off
                )

    width = max(1, cell_px // 6)
    for i, cells in enumerate(path_list):
        if cells is None:
            continue
        pts = _cell_center_px(cells, cell_px)
        for off in offsets:
            _draw_polyline(frame, pts + [0.0, off], width, robot_colors[i], off, off + pw)

    r_robot = max(0.38 * cell_px, 0.5)
    r_robot_out = r_robot + max(1.0, cell_px / 12.0)
    for i in range(n_robots):
        cy, cx = _cell_center_px(positions[i], cell_px)
        for off in offsets:
            if cell_px >= _GRID_LINE_MIN_PX:
                _fill_disc(frame, cy, cx + off, r_robot_out, COLOR_OUTLINE, off, off + pw)
            _fill_disc(frame, cy, cx + off, r_robot, robot_colors[i], off, off + pw)
    return frame


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
