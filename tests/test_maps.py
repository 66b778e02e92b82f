"""Structured maps: the rooms-and-corridors generator, map files (.txt, .pgm, .png), the shared
Explore-Bench maps and the shipped example maps."""

from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

import frontier_marl
from frontier_marl.config import make_config
from frontier_marl.core.example_maps import (
    EXAMPLE_MAPS,
    example_map_names,
    example_map_path,
    generate_example_map,
    resolve_map,
)
from frontier_marl.core.map_files import format_text_map, load_map, parse_pgm, parse_text_map
from frontier_marl.core.maps import FOUR_CONNECTED, floorplan_map, rooms_map
from frontier_marl.experiments import make_example_maps

# CI keeps a copy of shared/ beside the clone; locally it is ../shared as well.
EXPLORE_BENCH = Path(__file__).resolve().parents[2] / "shared" / "maps" / "explore-bench"


def free_components(grid: np.ndarray) -> int:
    return ndimage.label(~grid, structure=FOUR_CONNECTED)[1]


# ----------------------------------------------------------------- rooms generator

SIZES = [(5, 5), (7, 12), (12, 7), (20, 20), (17, 45), (48, 24), (32, 32), (64, 64), (40, 128)]


@pytest.mark.parametrize("height, width", SIZES)
def test_rooms_map_is_one_connected_free_region_with_walls_around(height, width):
    for seed in range(25):
        grid = rooms_map(height, width, np.random.default_rng(seed))
        assert grid.shape == (height, width) and grid.dtype == bool
        assert free_components(grid) == 1, (height, width, seed)
        border = np.concatenate([grid[0], grid[-1], grid[:, 0], grid[:, -1]])
        assert border.all(), "the outer ring must be wall"


def test_rooms_map_has_rooms_not_just_corridors():
    grid = rooms_map(64, 64, np.random.default_rng(0))
    free = ~grid
    # a room is a 3x3 block of free cells; a corridor (width 1) has none
    blocks = ndimage.binary_erosion(free, structure=np.ones((3, 3), bool))
    assert blocks.sum() > 20
    assert 0.1 < free.mean() < 0.8


def test_rooms_map_is_deterministic_per_seed_and_varies_across_seeds():
    first = rooms_map(30, 50, np.random.default_rng(7))
    again = rooms_map(30, 50, np.random.default_rng(7))
    other = rooms_map(30, 50, np.random.default_rng(8))
    assert np.array_equal(first, again)
    assert not np.array_equal(first, other)


@pytest.mark.parametrize("corridor_width", [1, 2, 3])
def test_rooms_map_wider_corridors_stay_connected(corridor_width):
    for seed in range(10):
        grid = rooms_map(40, 60, np.random.default_rng(seed), corridor_width=corridor_width)
        assert free_components(grid) == 1


def test_rooms_map_rejects_tiny_grids():
    with pytest.raises(ValueError, match="5x5"):
        rooms_map(4, 10, np.random.default_rng(0))
    with pytest.raises(ValueError, match="map_generator"):
        make_config(map_generator="rooms", height=4, width=10)


# ----------------------------------------------------------------- floor-plan generator


@given(
    height=st.integers(5, 90), width=st.integers(5, 90), seed=st.integers(0, 2**32 - 1),
    min_room=st.integers(2, 9),
)  # fmt: skip
@settings(max_examples=150, deadline=None)
def test_floorplan_map_is_one_building_of_thin_walls(height, width, seed, min_room):
    grid = floorplan_map(height, width, np.random.default_rng(seed), min_room=min_room, door=2)
    assert grid.shape == (height, width) and grid.dtype == bool
    assert free_components(grid) == 1, "every room is reachable through doors"
    border = np.concatenate([grid[0], grid[-1], grid[:, 0], grid[:, -1]])
    assert border.all()
    # thin walls: no 2x2 block of wall anywhere, so no solid rock between rooms
    blocks = grid[:-1, :-1] & grid[1:, :-1] & grid[:-1, 1:] & grid[1:, 1:]
    assert not blocks.any()


def test_floorplan_map_splits_large_buildings_into_rooms_no_larger_than_max_room():
    grid = floorplan_map(48, 48, np.random.default_rng(0), min_room=7, max_room=16)
    interior = ~grid[1:-1, 1:-1]
    assert interior.mean() > 0.85  # a building, not rooms carved out of rock
    # a free square wider than max_room cannot fit inside one room; doors are 3 cells wide
    open_square = ndimage.binary_erosion(~grid, structure=np.ones((17, 17), bool))
    assert not open_square.any()
    assert np.array_equal(grid, floorplan_map(48, 48, np.random.default_rng(0), min_room=7))
    assert not np.array_equal(grid, floorplan_map(48, 48, np.random.default_rng(1)))


def test_floorplan_map_rejects_bad_arguments():
    rng = np.random.default_rng(0)
    for kwargs, match in (
        ({"height": 4}, "5x5"),
        ({"min_room": 1}, "min_room"),
        ({"door": 8}, "door"),
        ({"max_room": 10}, "max_room"),
    ):
        with pytest.raises(ValueError, match=match):
            floorplan_map(**{"height": 40, "width": 40, "rng": rng, **kwargs})
    with pytest.raises(ValueError, match="map_generator='floorplan'"):
        make_config(map_generator="floorplan", height=8, width=8, map_scale=2)


def test_env_with_the_floorplan_generator_is_deterministic():
    kwargs = {"map_generator": "floorplan", "height": 48, "width": 48, "map_scale": 2}
    first = frontier_marl.parallel_env(**kwargs, map_mode="dynamic", perception_range=6)
    again = frontier_marl.parallel_env(**kwargs, map_mode="dynamic", perception_range=6)
    first.reset(seed=4)
    again.reset(seed=4)
    assert np.array_equal(first.world.true_grid, again.world.true_grid)
    grid = first.world.true_grid
    assert np.array_equal(grid, grid[::2, ::2].repeat(2, axis=0).repeat(2, axis=1))  # 2x2 blocks
    assert grid.mean() < 0.3


def test_env_with_the_rooms_generator_static_and_dynamic():
    static = frontier_marl.parallel_env(map_generator="rooms", height=24, width=36, map_seed=3)
    static.reset(seed=0)
    layout = np.array(static.world.true_grid)
    assert np.array_equal(layout, rooms_map(24, 36, np.random.default_rng(3)))
    static.reset(seed=1)
    assert np.array_equal(static.world.true_grid, layout)  # static: same layout, new start
    dynamic = frontier_marl.parallel_env(
        map_generator="rooms", height=24, width=36, map_mode="dynamic"
    )
    layouts = []
    for seed in (0, 1):
        dynamic.reset(seed=seed)
        layouts.append(np.array(dynamic.world.true_grid))
        assert free_components(layouts[-1]) == 1
    assert not np.array_equal(*layouts)


@pytest.mark.parametrize("generator", ["rooms", "random"])
def test_map_scale_draws_the_same_layout_in_blocks(generator):
    coarse = frontier_marl.parallel_env(map_generator=generator, height=12, width=10, map_seed=5)
    fine = frontier_marl.parallel_env(
        map_generator=generator, height=36, width=30, map_seed=5, map_scale=3
    )
    coarse.reset(seed=0)
    fine.reset(seed=0)
    layout = np.array(coarse.world.true_grid)
    blocks = np.kron(layout, np.ones((3, 3), dtype=bool))
    assert np.array_equal(fine.world.true_grid, blocks)
    assert fine.world.true_grid.shape == (36, 30)


# ----------------------------------------------------------------- text maps


@pytest.mark.parametrize(
    "text, match",
    [
        ("#.#\n#x#\n###\n", r"row 2, column 2: unexpected character 'x'"),
        ("#.# \n#.# \n", r"row 1, column 4: unexpected character ' '"),
        ("#.#\n#..#\n###\n", r"row 2 has 4 cells, row 1 has 3"),
        ("#.#\n\n#.#\n", r"row 2 has 0 cells"),
        ("###\n###\n", "no free cell"),
        ("\n\n", "empty"),
        ("", "empty"),
    ],
    ids=["character", "trailing-space", "ragged", "blank-row", "no-free-cell", "blank", "empty"],
)
def test_text_loader_rejects_malformed_files_with_a_clear_message(tmp_path, text, match):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(ValueError, match=match) as caught:
        load_map(path)
    assert str(path) in str(caught.value), "the message names the file"
    with pytest.raises(ValueError, match="map_path"):
        make_config(map_path=str(path))


def test_text_round_trip_and_line_endings(tmp_path):
    grid = rooms_map(9, 14, np.random.default_rng(2))
    text = format_text_map(grid)
    assert np.array_equal(parse_text_map(text), grid)
    path = tmp_path / "map.txt"
    path.write_bytes(text.replace("\n", "\r\n").encode())
    assert np.array_equal(load_map(path), grid)


def test_missing_file_and_unknown_suffix(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        load_map(tmp_path / "nowhere.txt")
    odd = tmp_path / "map.bmp"
    odd.write_text("#.#\n")
    with pytest.raises(ValueError, match="unsupported suffix '.bmp'"):
        load_map(odd)
    with pytest.raises(ValueError, match="map_path.*does not exist"):
        frontier_marl.parallel_env(map_path=str(tmp_path / "nowhere.txt"))


def test_a_folder_binary_bytes_and_a_damaged_png_name_the_file_and_the_fault(tmp_path):
    with pytest.raises(ValueError, match=f"map_path: map file {tmp_path} is a folder"):
        frontier_marl.parallel_env(map_path=str(tmp_path))
    noise = np.random.default_rng(0).integers(0, 256, 300, dtype=np.uint8).tobytes()
    text = tmp_path / "noise.txt"
    text.write_bytes(b"\xff" + noise)
    with pytest.raises(ValueError, match=r"noise\.txt is not a text map: byte 0 is not UTF-8"):
        load_map(text)
    fake = tmp_path / "noise.png"
    fake.write_bytes(noise)
    with pytest.raises(ValueError, match=r"noise\.png is not a PNG image"):
        load_map(fake)
    image = tmp_path / "room.png"
    iio.imwrite(image, np.full((6, 5), 255, dtype=np.uint8))
    cut = tmp_path / "cut.png"
    cut.write_bytes(image.read_bytes()[:40])
    with pytest.raises(ValueError, match=r"cut\.png is a damaged PNG image"):
        load_map(cut)


# ----------------------------------------------------------------- PGM


def pgm_p5(pixels: np.ndarray, maxval: int = 255, comment: bytes = b"") -> bytes:
    height, width = pixels.shape
    header = b"P5\n" + comment + f"{width} {height}\n{maxval}\n".encode()
    dtype = ">u2" if maxval > 255 else np.uint8
    return header + pixels.astype(dtype).tobytes()


def test_pgm_p5_p2_and_16_bit_parse_to_the_same_grid():
    grid = rooms_map(8, 11, np.random.default_rng(4))
    pixels = np.where(grid, 0, 254)
    assert np.array_equal(parse_pgm(pgm_p5(pixels, comment=b"# a comment\n")), grid)
    ascii_body = " ".join(str(v) for v in pixels.ravel())
    p2 = f"P2\n{grid.shape[1]} {grid.shape[0]}\n255\n{ascii_body}\n".encode()
    assert np.array_equal(parse_pgm(p2), grid)
    deep = np.where(grid, 0, 65535)
    assert np.array_equal(parse_pgm(pgm_p5(deep, maxval=65535)), grid)
    # ROS "unknown" grey (205) counts as a wall
    grey = np.where(grid, 205, 254)
    assert np.array_equal(parse_pgm(pgm_p5(grey)), grid)


@pytest.mark.parametrize(
    "data, match",
    [
        (b"P6\n2 2\n255\n" + bytes(12), "not a PGM file"),
        (b"P5\n2 2\n", "truncated PGM header"),
        (b"", "truncated PGM header"),
        (b"P5\nab 2\n255\n" + bytes(4), "malformed PGM header"),
        (b"P5\n0 2\n255\n", "bad PGM size"),
        (b"P5\n2 2\n0\n" + bytes(4), "bad PGM size"),
        (b"P5\n2 2\n255\n\xff", "1 pixels, expected 2x2"),
        (b"P2\n2 2\n255\n255 0\n", "2 pixels, expected 2x2"),
        (b"P5\n2 2\n255\n" + bytes(4), "no free cell"),
    ],
    ids=[
        "magic",
        "truncated",
        "empty",
        "non-integer",
        "zero-size",
        "maxval",
        "short",
        "short-ascii",
        "no-free-cell",
    ],
)
def test_pgm_loader_rejects_malformed_files(tmp_path, data, match):
    path = tmp_path / "bad.pgm"
    path.write_bytes(data)
    with pytest.raises(ValueError, match=match) as caught:
        load_map(path)
    assert str(path) in str(caught.value)


def test_pgm_ascii_pixel_that_is_not_a_number_is_reported_with_the_file(tmp_path):
    path = tmp_path / "bad.pgm"
    path.write_bytes(b"P2\n2 2\n255\n255 x 0 255\n")
    with pytest.raises(ValueError, match="bad.pgm"):
        load_map(path)


def test_pgm_16_bit_with_a_trailing_byte_loads():
    grid = np.array([[True, False], [False, False]])
    data = pgm_p5(np.where(grid, 0, 65535), maxval=65535) + b"\n"
    assert np.array_equal(parse_pgm(data), grid)


# ----------------------------------------------------------------- PNG


def test_png_round_trip(tmp_path):
    import imageio.v3 as iio

    grid = rooms_map(12, 17, np.random.default_rng(5))
    image = np.where(grid, 0, 255).astype(np.uint8)
    iio.imwrite(tmp_path / "plan.png", image)
    assert np.array_equal(load_map(tmp_path / "plan.png"), grid)
    rgb = np.stack([image] * 3 + [np.full_like(image, 255)], axis=-1)  # RGBA floor plan
    iio.imwrite(tmp_path / "plan_rgba.png", rgb)
    assert np.array_equal(load_map(tmp_path / "plan_rgba.png"), grid)
    env = frontier_marl.parallel_env(map_path=str(tmp_path / "plan.png"), n_agents=2)
    env.reset(seed=0)
    assert np.array_equal(env.world.true_grid, grid)
    assert env.config.shape == (12, 17)


def test_png_all_black_has_no_free_cell(tmp_path):
    import imageio.v3 as iio

    iio.imwrite(tmp_path / "black.png", np.zeros((4, 5), np.uint8))
    with pytest.raises(ValueError, match="no free cell"):
        load_map(tmp_path / "black.png")


def test_png_16_bit_levels_are_scaled(tmp_path):
    import imageio.v3 as iio

    grid = np.array([[True, False], [False, True]])
    iio.imwrite(tmp_path / "deep.png", np.where(grid, 1000, 65535).astype(np.uint16))
    assert np.array_equal(load_map(tmp_path / "deep.png"), grid)


# ----------------------------------------------------------------- Explore-Bench


@pytest.mark.skipif(not EXPLORE_BENCH.is_dir(), reason=f"{EXPLORE_BENCH} is absent")
def test_explore_bench_maps_load():
    files = sorted(EXPLORE_BENCH.glob("*.pgm"))
    assert len(files) >= 10
    for path in files:
        grid = load_map(path)
        assert grid.shape == (250, 250), path.name
        free = ~grid
        assert 0.01 < free.mean() < 0.9, path.name
        # a floor plan has one large free region that holds most of the free cells
        labels, count = ndimage.label(free, structure=FOUR_CONNECTED)
        assert np.bincount(labels.ravel())[1:].max() > 0.5 * free.sum(), path.name


@pytest.mark.skipif(not EXPLORE_BENCH.is_dir(), reason=f"{EXPLORE_BENCH} is absent")
def test_explore_bench_map_runs_a_team():
    env = frontier_marl.parallel_env(
        map_path=str(EXPLORE_BENCH / "room_1.pgm"), n_agents=2, perception_range=20
    )
    _, infos = env.reset(seed=0)
    assert env.config.shape == (250, 250)
    for _ in range(3):
        if not env.agents:
            break
        actions = {a: int(np.flatnonzero(infos[a]["action_mask"])[0]) for a in env.agents}
        _, _, _, _, infos = env.step(actions)
    assert env.world.explored_fraction("reachable") > 0


# ----------------------------------------------------------------- example maps


def test_example_maps_are_shipped_and_match_their_generator():
    assert example_map_names() == ["rooms-32", "rooms-64", "rooms-128"]
    for name, (height, width, _seed) in EXAMPLE_MAPS.items():
        path = example_map_path(name)
        assert path.is_file() and path.suffix == ".txt"
        grid = load_map(path)
        assert grid.shape == (height, width)
        assert free_components(grid) == 1
        assert np.array_equal(grid, generate_example_map(name)), (
            f"{path} is stale: rerun python baselines/make_example_maps.py"
        )


def test_example_map_names_resolve_and_unknown_names_fail():
    assert resolve_map("rooms-64") == str(example_map_path("rooms-64"))
    assert resolve_map("some/file.txt") == "some/file.txt"
    with pytest.raises(ValueError, match="rooms-32"):
        example_map_path("rooms-7")
    env = frontier_marl.parallel_env(map_path=example_map_path("rooms-32"), n_agents=4)
    env.reset(seed=0)
    assert env.config.shape == (32, 32)


def test_example_maps_script_check_passes():
    assert make_example_maps.main(["--check"]) == 0


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"corridor_width": 0}, "corridor_width"),
        ({"min_room": 5, "max_room": 3}, "max_room"),
        ({"min_room": 0}, "min_room"),
    ],
)
def test_rooms_map_rejects_bad_parameters(kwargs, name):
    with pytest.raises(ValueError, match=name):
        rooms_map(30, 30, np.random.default_rng(0), **kwargs)
