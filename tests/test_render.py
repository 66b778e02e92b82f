"""Tests for frontier_marl.render.frames."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN
from frontier_marl.render.frames import (
    CLUSTER_PALETTE,
    COLOR_FREE,
    COLOR_GAP,
    COLOR_OCCUPIED,
    COLOR_UNKNOWN,
    ROBOT_PALETTE,
    frame_shape,
    render_ansi,
    render_rgb,
)
from frontier_marl.render.viewer import HumanViewer, write_gif

PX = 12
H, W = 3, 5

# True map (3x5), '#' = occupied:
#   . # . . .
#   . . . # .
#   . . . . #
TRUE = np.zeros((H, W), dtype=bool)
TRUE[0, 1] = TRUE[1, 3] = TRUE[2, 4] = True

U, F, X = UNKNOWN, FREE, OCCUPIED
BELIEF = np.array(
    [
        [F, X, F, U, U],
        [F, F, F, X, U],
        [F, F, U, U, U],
    ],
    dtype=np.int8,
)
NO_ROBOTS = np.zeros((0, 2), dtype=int)


def center(frame: np.ndarray, row: int, col: int, panel: int, cell_px: int = PX) -> np.ndarray:
    """Pixel at the centre of cell (row, col) on panel 0 (true) or 1 (belief)."""
    x_off = panel * (W + 1) * cell_px
    return frame[row * cell_px + cell_px // 2, x_off + col * cell_px + cell_px // 2]


def test_frame_shape_and_dtype() -> None:
    for px in (1, 4, PX):
        frame = render_rgb(TRUE, BELIEF, NO_ROBOTS, cell_px=px)
        assert frame.dtype == np.uint8
        assert frame.shape == (H * px, (2 * W + 1) * px, 3)
        assert frame.shape == frame_shape((H, W), px)


def test_panel_cell_colours() -> None:
    frame = render_rgb(TRUE, BELIEF, NO_ROBOTS, cell_px=PX)
    # True panel: occupied near-black, free white, independent of the belief.
    np.testing.assert_array_equal(center(frame, 0, 1, 0), COLOR_OCCUPIED)
    np.testing.assert_array_equal(center(frame, 2, 4, 0), COLOR_OCCUPIED)
    np.testing.assert_array_equal(center(frame, 0, 4, 0), COLOR_FREE)
    np.testing.assert_array_equal(center(frame, 2, 2, 0), COLOR_FREE)
    # Belief panel: unknown grey, free white, occupied near-black.
    np.testing.assert_array_equal(center(frame, 0, 4, 1), COLOR_UNKNOWN)
    np.testing.assert_array_equal(center(frame, 2, 4, 1), COLOR_UNKNOWN)
    np.testing.assert_array_equal(center(frame, 0, 0, 1), COLOR_FREE)
    np.testing.assert_array_equal(center(frame, 1, 3, 1), COLOR_OCCUPIED)
    # Gap column between the panels.
    np.testing.assert_array_equal(frame[PX, W * PX + PX // 2], COLOR_GAP)
    assert len({tuple(c) for c in (COLOR_FREE, COLOR_OCCUPIED, COLOR_UNKNOWN, COLOR_GAP)}) == 4


def test_grid_lines_only_for_large_cells() -> None:
    frame = render_rgb(TRUE, BELIEF, NO_ROBOTS, cell_px=PX)
    # First pixel column of cell (2, 1) is a grid line: darker than the white cell centre.
    line = frame[2 * PX + PX // 2, 1 * PX]
    assert np.all(line < COLOR_FREE)
    small = render_rgb(TRUE, BELIEF, NO_ROBOTS, cell_px=4)
    np.testing.assert_array_equal(small[2 * 4 : 3 * 4, 0 : 2 * 4], 255)


def test_robots_drawn_on_both_panels() -> None:
    positions = np.array([[1, 1], [2, 0]])
    frame = render_rgb(TRUE, BELIEF, positions, cell_px=PX)
    for panel in (0, 1):
        np.testing.assert_array_equal(center(frame, 1, 1, panel), ROBOT_PALETTE[0])
        np.testing.assert_array_equal(center(frame, 2, 0, panel), ROBOT_PALETTE[1])
    assert not np.array_equal(ROBOT_PALETTE[0], ROBOT_PALETTE[1])
    # Palettes are disjoint.
    assert not {tuple(c) for c in ROBOT_PALETTE} & {tuple(c) for c in CLUSTER_PALETTE}


def test_frontier_cells_get_cluster_colour() -> None:
    labels = np.zeros((H, W), dtype=int)
    labels[0, 2] = 1
    labels[1, 2] = 1
    labels[2, 1] = 2
    frame = render_rgb(TRUE, BELIEF, NO_ROBOTS, cluster_labels=labels, cell_px=PX)
    np.testing.assert_array_equal(center(frame, 0, 2, 1), CLUSTER_PALETTE[0])
    np.testing.assert_array_equal(center(frame, 1, 2, 1), CLUSTER_PALETTE[0])
    np.testing.assert_array_equal(center(frame, 2, 1, 1), CLUSTER_PALETTE[1])
    # The true panel is not tinted.
    np.testing.assert_array_equal(center(frame, 0, 2, 0), COLOR_FREE)
    # Labels cycle through the palette.
    labels[2, 1] = len(CLUSTER_PALETTE) + 1
    frame = render_rgb(TRUE, BELIEF, NO_ROBOTS, cluster_labels=labels, cell_px=PX)
    np.testing.assert_array_equal(center(frame, 2, 1, 1), CLUSTER_PALETTE[0])


def test_centroid_dot_at_fractional_position() -> None:
    labels = np.zeros((H, W), dtype=int)
    labels[0, 2] = labels[1, 2] = 1
    centroids = np.array([[0.5, 2.0]])
    frame = render_rgb(TRUE, BELIEF, NO_ROBOTS, labels, centroids, cell_px=PX)
    x_off = (W + 1) * PX
    # Centroid pixel position: (0.5 * 12 + 5.5, 2 * 12 + 5.5) = (11.5, 29.5) in the panel.
    np.testing.assert_array_equal(frame[12, x_off + 30], CLUSTER_PALETTE[0])
    np.testing.assert_array_equal(frame[11, x_off + 29], CLUSTER_PALETTE[0])
    # 3.5 px left of the centre: in the dark outline ring, inside a cluster-coloured cell.
    # (Row 11 is used because pixel row 12 is a grid line.)
    assert frame[11, x_off + 26].max() < 60
    np.testing.assert_array_equal(frame[11, x_off + 34], CLUSTER_PALETTE[0])


def test_paths_and_targets() -> None:
    positions = np.array([[2, 1]])
    paths = [np.array([[0, 0], [1, 0], [2, 0], [2, 1]])]
    targets = np.array([[0, 4]])
    frame = render_rgb(TRUE, BELIEF, positions, paths=paths, targets=targets, cell_px=PX)
    color = ROBOT_PALETTE[0]
    for panel in (0, 1):
        x_off = panel * (W + 1) * PX
        # Path through the centres of column 0: the centre of cell (0, 0) is on it.
        np.testing.assert_array_equal(center(frame, 0, 0, panel), color)
        np.testing.assert_array_equal(frame[PX, x_off + PX // 2], color)
        # Hollow square: border pixel coloured, centre keeps its cell colour.
        np.testing.assert_array_equal(frame[0, x_off + 4 * PX + PX // 2], color)
        np.testing.assert_array_equal(frame[PX // 2, x_off + 5 * PX - 1], color)
    np.testing.assert_array_equal(center(frame, 0, 4, 0), COLOR_FREE)
    np.testing.assert_array_equal(center(frame, 0, 4, 1), COLOR_UNKNOWN)
    # A negative target row means "no target".
    render_rgb(TRUE, BELIEF, positions, targets=np.array([[-1, -1]]), cell_px=PX)


def test_large_map_small_cells() -> None:
    rng = np.random.default_rng(0)
    true = rng.random((128, 128)) < 0.2
    belief = np.where(rng.random((128, 128)) < 0.5, UNKNOWN, true.astype(np.int8)).astype(np.int8)
    labels = rng.integers(0, 4, size=(128, 128))
    positions = rng.integers(0, 128, size=(4, 2))
    frame = render_rgb(true, belief, positions, labels, cell_px=4)
    assert frame.shape == (512, 1028, 3)  # two 128 x 4 px panels and a 4 px gap
    assert np.array_equal(frame[:4, :4], np.broadcast_to(frame[0, 0], (4, 4, 3)))  # one cell


def test_render_ansi_exact() -> None:
    labels = np.zeros((H, W), dtype=int)
    labels[0, 2] = labels[1, 2] = 1
    labels[2, 1] = 2
    positions = np.array([[1, 0], [2, 0]])
    expected = "\n".join([".#a??", "0.a#?", "1b???"])
    assert render_ansi(BELIEF, positions, labels) == expected
    assert render_ansi(BELIEF, NO_ROBOTS) == "\n".join([".#.??", "...#?", "..???"])


def test_render_ansi_cycles_letters_and_digits() -> None:
    belief = np.zeros((1, 12), dtype=np.int8)
    labels = np.zeros((1, 12), dtype=int)
    labels[0, 11] = 27  # wraps to 'a'
    positions = np.array([[0, c] for c in range(11)])
    assert render_ansi(belief, positions, labels) == "01234567890a"


def test_write_gif_round_trip(tmp_path) -> None:
    iio = pytest.importorskip("imageio.v3")
    frames = [render_rgb(TRUE, BELIEF, np.array([[r, 0]]), cell_px=4) for r in range(H)]
    path = tmp_path / "episode.gif"
    write_gif(frames, path, fps=5)
    data = iio.imread(path, index=None)
    assert data.shape == (len(frames), *frames[0].shape)
    assert iio.immeta(path)["duration"] == 200
    with pytest.raises(ValueError, match="frames"):
        write_gif([], tmp_path / "empty.gif")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"belief": np.zeros((3, 4), dtype=np.int8)}, "belief"),
        ({"positions": np.zeros((2, 3), dtype=int)}, "positions"),
        ({"positions": np.zeros(2, dtype=int)}, "positions"),
        ({"positions": np.array([[3, 0]])}, "positions"),
        ({"cell_px": 0}, "cell_px"),
        ({"cluster_labels": np.zeros((5, 3), dtype=int)}, "cluster_labels"),
        ({"centroids": np.zeros((2, 3))}, "centroids"),
        ({"paths": [np.zeros((2, 2), dtype=int)] * 2}, "paths"),
        ({"targets": np.zeros((2, 2), dtype=int)}, "targets"),
        ({"true_grid": np.zeros(5, dtype=bool)}, "true_grid"),
    ],
)
def test_render_rgb_value_errors(kwargs: dict, match: str) -> None:
    args = {"true_grid": TRUE, "belief": BELIEF, "positions": np.array([[0, 0]])}
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        render_rgb(**args)


def test_render_ansi_value_errors() -> None:
    with pytest.raises(ValueError, match="positions"):
        render_ansi(BELIEF, np.zeros((1, 3), dtype=int))
    with pytest.raises(ValueError, match="cluster_labels"):
        render_ansi(BELIEF, NO_ROBOTS, np.zeros((2, 2), dtype=int))


def test_human_viewer_shows_each_frame_in_its_own_figure_and_closes_it() -> None:
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    frame = render_rgb(TRUE, BELIEF, NO_ROBOTS, cell_px=2)
    first, second = HumanViewer(fps=1000.0), HumanViewer(fps=1000.0)
    with warnings.catch_warnings():
        # Agg draws off screen; matplotlib says so when asked to pause
        warnings.filterwarnings("ignore", message=".*non-interactive", category=UserWarning)
        first.show(frame)
        second.show(frame[::-1].copy())
        assert first._fig is not second._fig  # one figure per viewer
        assert np.array_equal(first._im.get_array(), frame)
        assert np.array_equal(second._im.get_array(), frame[::-1])
        larger = render_rgb(TRUE, BELIEF, NO_ROBOTS, cell_px=3)
        first.show(larger)  # a new shape replaces the image
        assert np.array_equal(first._im.get_array(), larger)
    number = first._fig.number
    first.close()
    assert not plt.fignum_exists(number) and plt.fignum_exists(second._fig.number)
    first.close()  # closing twice is safe
    second.close()


def test_two_human_mode_envs_render_side_by_side(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each env has a viewer figure of its own: a second env, and an env made while an
    earlier one is still open, render beside it."""
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    import frontier_marl

    monkeypatch.setattr(plt, "pause", lambda interval: None)  # the frames, not the sleep
    first = frontier_marl.parallel_env(render_mode="human", n_agents=2)
    second = frontier_marl.FrontierExploreEnv(render_mode="human")
    first.reset(seed=0)
    second.reset(seed=1)
    for _ in range(3):
        first.step(dict.fromkeys(first.agents, 0))
        second.step(0)
    figures = {first._renderer._viewer._fig.number, second._renderer._viewer._fig.number}
    assert len(figures) == 2 and all(plt.fignum_exists(number) for number in figures)
    third = frontier_marl.parallel_env(render_mode="human")  # while the others are open
    third.reset(seed=2)
    assert plt.fignum_exists(third._renderer._viewer._fig.number)
    for env in (first, second, third):
        env.close()
    assert not any(plt.fignum_exists(number) for number in figures)
