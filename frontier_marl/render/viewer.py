"""Showing and saving frames of :mod:`frontier_marl.render.frames`: a live matplotlib window and GIF
export (matplotlib and imageio are imported lazily)."""

from __future__ import annotations

import os
from typing import Any

import imageio.v3 as iio
import numpy as np


class HumanViewer:
    """Shows frames in a matplotlib window of its own (imported lazily); closes cleanly."""

    def __init__(self, fps: float = 4.0, title: str = "frontier_marl") -> None:
        self.fps = fps
        self.title = title
        self._fig: Any = None
        self._ax: Any = None
        self._im: Any = None

    def show(self, frame: np.ndarray) -> None:
        """Display ``frame`` (``uint8 (H, W, 3)``), reusing the window and image artist."""
        import matplotlib.pyplot as plt

        frame = np.asarray(frame)
        if self._fig is None or not plt.fignum_exists(self._fig.number):
            plt.ion()
            self._fig, self._ax = plt.subplots()  # a figure of its own: viewers never share
            if self._fig.canvas.manager is not None:
                self._fig.canvas.manager.set_window_title(self.title)
            self._ax.set_axis_off()
            self._fig.tight_layout(pad=0.1)
            self._im = self._ax.imshow(frame, interpolation="nearest")
        elif self._im.get_array().shape != frame.shape:
            self._im.remove()
            self._im = self._ax.imshow(frame, interpolation="nearest")
        else:
            self._im.set_data(frame)
        self._fig.canvas.draw_idle()
        plt.pause(1.0 / self.fps if self.fps and self.fps > 0 else 0.001)

    def close(self) -> None:
        """Close the window if open; safe to call repeatedly."""
        if self._fig is not None:
            import matplotlib.pyplot as plt

            plt.close(self._fig)
        self._fig = self._ax = self._im = None

    def __enter__(self) -> HumanViewer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def write_gif(frames: list[np.ndarray], path: str | os.PathLike, fps: float = 4.0) -> None:
    """Write ``frames`` (equal-shape ``uint8 (H, W, 3)``) as a looping GIF at ``fps``.

    Pillow merges identical consecutive frames into one longer frame, so the file may hold
    fewer frames than given while the playback timing stays the same.
    """
    if len(frames) == 0:
        raise ValueError("frames must be a non-empty list of images")
    if not fps > 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    stack = [np.asarray(f) for f in frames]
    first = stack[0].shape
    if len(first) != 3 or first[2] != 3:
        raise ValueError(f"frames must have shape (H, W, 3), got {first}")
    for i, f in enumerate(stack):
        if f.shape != first:
            raise ValueError(f"frames[{i}] has shape {f.shape}, expected {first}")
    data = np.stack(stack).astype(np.uint8, copy=False)

    iio.imwrite(
        os.fspath(path),
        data,
        plugin="pillow",
        extension=".gif",
        duration=1000.0 / fps,
        loop=0,
    )
