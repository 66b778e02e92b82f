"""Pixel drawing on RGB frames: cell centres, discs, polylines, hollow squares, upscaling and
grid lines (the primitives of :mod:`frontier_marl.render.frames`)."""

from __future__ import annotations

import numpy as np

#: grid lines are drawn from this cell size in pixels up, darkening the cells' edge pixels
GRID_LINE_MIN_PX = 6
GRID_LINE_FACTOR = 0.8


def cell_center_px(rc: np.ndarray, cell_px: int) -> np.ndarray:
    """Pixel coordinates (float) of the centre of (possibly fractional) cell coordinates."""
    return np.asarray(rc, dtype=np.float64) * cell_px + (cell_px - 1) / 2.0


def fill_disc(
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


def draw_polyline(
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


def draw_hollow_square(
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


def upscale(cells_rgb: np.ndarray, cell_px: int) -> np.ndarray:
    if cell_px == 1:
        return cells_rgb
    return np.repeat(np.repeat(cells_rgb, cell_px, axis=0), cell_px, axis=1)


def grid_lines(panel: np.ndarray, cell_px: int) -> None:
    """Darken the first pixel row/column of every cell except the outer ones, in place."""
    if cell_px < GRID_LINE_MIN_PX:
        return
    rows = np.arange(cell_px, panel.shape[0], cell_px)
    cols = np.arange(cell_px, panel.shape[1], cell_px)
    panel[rows, :] = (panel[rows, :] * GRID_LINE_FACTOR).astype(np.uint8)
    panel[:, cols] = (panel[:, cols] * GRID_LINE_FACTOR).astype(np.uint8)
