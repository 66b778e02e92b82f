"""Tests for frontier_marl.config: validation messages, presets, overrides, round trip."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from frontier_marl.config import (
    PRESETS,
    EnvConfig,
    ObservationConfig,
    RewardConfig,
    config_keys,
    config_to_dict,
    make_config,
)

# (flat key, bad value, name the message must contain)
BAD_VALUES = [
    ("height", 2, "height"),
    ("height", 4097, "height"),
    ("height", 20.0, "height"),
    ("height", "20", "height"),
    ("height", True, "height"),
    ("width", 2, "width"),
    ("width", -5, "width"),
    ("n_agents", 0, "n_agents"),
    ("n_agents", 1.5, "n_agents"),
    ("obstacle_prob", 1.5, "obstacle_prob"),
    ("obstacle_prob", -0.1, "obstacle_prob"),
    ("obstacle_prob", 0.95, "obstacle_prob"),
    ("obstacle_prob", math.nan, "obstacle_prob"),
    ("obstacle_prob", "low", "obstacle_prob"),
    ("obstacle_prob_spread", 0.6, "obstacle_prob_spread"),
    ("obstacle_prob_spread", -0.1, "obstacle_prob_spread"),
    ("start_cells", "corner", "start_cells"),
    ("map_mode", "moving", "map_mode"),
    ("map_seed", -1, "map_seed"),
    ("map_seed", 0.5, "map_seed"),
    ("map_scale", 0, "map_scale"),
    ("map_scale", 3, "map_scale"),  # 20x20 is not a multiple of 3
    ("map_scale", 1.5, "map_scale"),
    *[pytest.param("map_path", value, "map_path") for value in ("/nonexistent/map.txt", 5)],
    ("perception_range", 0, "perception_range"),
    ("perception_range", 21, "perception_range"),  # larger than the 20x20 map
    ("sensor", "lidar", "sensor"),
    ("map_generator", "caves", "map_generator"),
    ("team_weight", 1.5, "team_weight"),
    ("team_weight", -0.1, "team_weight"),
    ("teammates", "velocities", "teammates"),
    ("teammates", "positions", "teammates"),  # needs n_agents >= 2
    ("cells_per_step", 0, "cells_per_step"),
    ("cells_per_step", -1, "cells_per_step"),
    ("cells_per_step", "half", "cells_per_step"),
    ("cells_per_step", 1.5, "cells_per_step"),
    ("cells_per_step", True, "cells_per_step"),
    ("connectivity", 6, "connectivity"),
    ("connectivity", 0, "connectivity"),
    ("connectivity", True, "connectivity"),
    ("connectivity", "8", "connectivity"),
    ("max_cluster_cells", 0, "max_cluster_cells"),
    ("n_slots", 0, "n_slots"),
    ("n_slots", 257, "n_slots"),
    ("gain", "entropy", "gain"),
    ("centroid", "polar", "centroid"),
    ("agent_position", "yes", "agent_position"),
    ("agent_position", 1, "agent_position"),
    ("info_gain", None, "info_gain"),
    ("sort_by_distance", "no", "sort_by_distance"),
    ("action_mask", 0, "action_mask"),
    ("normalize", "false", "normalize"),
    ("tour", 1, "tour"),
    ("turn", 1, "turn"),
    ("unknown_near", "yes", "unknown_near"),
    ("fill", 1, "fill"),
    ("utility", 1, "utility"),
    ("utility", True, "utility"),  # needs features="explorer"
    ("near_ranges", -1.0, "near_ranges"),
    ("explore_threshold", 0, "explore_threshold"),
    ("explore_threshold", 0.0, "explore_threshold"),
    ("explore_threshold", 1.01, "explore_threshold"),
    ("explore_threshold", math.inf, "explore_threshold"),
    ("threshold_basis", "visible", "threshold_basis"),
    ("max_steps", 0, "max_steps"),
    ("max_steps", 10.5, "max_steps"),
    ("no_progress_limit", 0, "no_progress_limit"),
    ("oscillation_window", 0, "oscillation_window"),
    ("cell_reward", math.nan, "cell_reward"),
    ("cell_reward", "big", "cell_reward"),
    ("no_new_cell_penalty", math.inf, "no_new_cell_penalty"),
    ("padding_penalty", -math.inf, "padding_penalty"),
    ("goal_bonus", None, "goal_bonus"),
    ("step_limit_penalty", math.nan, "step_limit_penalty"),
    ("no_progress_penalty", "x", "no_progress_penalty"),
    ("oscillation_penalty", math.inf, "oscillation_penalty"),
    ("reward", "reward3", "reward"),
    ("travel_cost", math.nan, "travel_cost"),
    ("features", "pixels", "features"),
    ("commit", "always", "commit"),
    ("foo", 1, "foo"),
    ("preset", "thesis-10x10", "preset"),
    ("config", "thesis-20x20", "config"),
]


@pytest.mark.parametrize(("key", "value", "name"), BAD_VALUES)
def test_bad_value_raises_value_error_naming_the_parameter(key, value, name):
    with pytest.raises(ValueError) as excinfo:
        make_config(**{key: value})
    assert name in str(excinfo.value)


def test_bad_values_cover_every_flat_key():
    covered = {entry.values[0] if hasattr(entry, "values") else entry[0] for entry in BAD_VALUES}
    assert set(config_keys()) - covered == set()


def test_empty_observation_raises_naming_centroid():
    with pytest.raises(ValueError, match="centroid"):
        make_config(centroid="none", info_gain=False)
    assert make_config(centroid="none", info_gain=True).observation.centroid == "none"


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"height": 2}, "height"),
        ({"obstacle_prob": 1.5}, "obstacle_prob"),
        ({"cells_per_step": "half"}, "cells_per_step"),
        ({"observation": ObservationConfig(centroid="polar")}, "centroid"),
        ({"reward": RewardConfig(max_steps=0)}, "max_steps"),
        ({"reward": RewardConfig(kind="reward3")}, "reward"),
        ({"observation": "absolute"}, "observation"),
        ({"map_path": 5}, "map_path"),
        ({"reward": "reward1"}, "reward"),
    ],
)
def test_env_config_constructor_validates(kwargs, name):
    with pytest.raises(ValueError, match=name):
        EnvConfig(**kwargs)


def test_sub_configs_validate():
    with pytest.raises(ValueError, match="centroid"):
        ObservationConfig(centroid="polar").validate()
    with pytest.raises(ValueError, match="explore_threshold"):
        RewardConfig(explore_threshold=2.0).validate()
    ObservationConfig().validate()
    RewardConfig().validate()


def test_connectivity_float_rejected_like_other_integers():
    with pytest.raises(ValueError, match="connectivity"):
        make_config(connectivity=8.0)


def test_valid_edge_values_accepted():
    cfg = make_config(
        height=3,
        width=4096,
        obstacle_prob=0.0,
        perception_range=4096,
        cells_per_step="full",
        connectivity=4,
        max_cluster_cells=1,
        n_slots=256,
        explore_threshold=1.0,
        max_steps=1,
        n_agents=np.int64(2),
    )
    assert cfg.walks_full_path
    assert cfg.shape == (3, 4096)
    assert make_config(obstacle_prob=0.9).obstacle_prob == 0.9


# ----------------------------------------------------------------------------- map files
@pytest.fixture
def map_file(tmp_path):
    path = tmp_path / "map.txt"
    path.write_text("..#..\n.....\n#...#\n")  # 3x5, non-square
    return str(path)


def test_map_path_sets_the_shape(map_file):
    cfg = make_config(map_path=map_file)
    assert cfg.shape == (3, 5)
    assert cfg.map_path == map_file
    assert make_config(map_path=map_file, height=3, width=5).shape == (3, 5)


def test_map_path_contradicting_shape_raises(map_file):
    with pytest.raises(ValueError, match="height"):
        make_config(map_path=map_file, height=4)
    with pytest.raises(ValueError, match="width"):
        make_config(map_path=map_file, width=6)


def test_map_path_needs_static_mode(map_file):
    with pytest.raises(ValueError, match="map_path"):
        make_config(map_path=map_file, map_mode="dynamic")


def test_map_path_refuses_map_scale(map_file):
    with pytest.raises(ValueError, match="map_scale"):
        make_config(map_path=map_file, map_scale=2)


def test_map_scale_needs_a_rooms_layout_of_five_cells():
    with pytest.raises(ValueError, match="5x5"):
        make_config(map_generator="rooms", height=16, width=16, map_scale=4)
    assert make_config(map_generator="rooms", height=20, width=20, map_scale=4).map_scale == 4


def test_map_path_round_trip(map_file):
    cfg = make_config(map_path=map_file, perception_range=2, n_agents=2)
    assert make_config(config=None, preset="thesis-30x30", **config_to_dict(cfg)) == cfg


# ----------------------------------------------------------------------------- presets
def test_presets():
    assert set(PRESETS) == {"thesis-20x20", "thesis-30x30", "rooms-32"}
    small = make_config(preset="thesis-20x20")
    assert (small.height, small.width, small.perception_range) == (20, 20, 3)
    large = make_config(preset="thesis-30x30")
    assert (large.height, large.width, large.perception_range) == (30, 30, 5)
    assert large.shape == (30, 30)
    assert make_config() == small
    assert make_config(preset=None) == small
    rooms = make_config(preset="rooms-32")
    assert (rooms.map_generator, rooms.height, rooms.perception_range) == ("rooms", 32, 3)
    assert rooms.reward.max_steps == 400 * 32 * 32 // (20 * 20)


def test_overrides_win_over_presets():
    cfg = make_config(
        preset="thesis-30x30",
        perception_range=2,
        width=25,
        n_agents=3,
        centroid="relative",
        sort_by_distance=True,
        reward="reward1",
        max_steps=50,
    )
    assert (cfg.height, cfg.width, cfg.perception_range, cfg.n_agents) == (30, 25, 2, 3)
    assert cfg.observation.centroid == "relative" and cfg.observation.sort_by_distance
    assert cfg.reward.kind == "reward1" and cfg.reward.max_steps == 50
    # Untouched fields keep their defaults.
    assert cfg.observation.agent_position is True
    assert cfg.reward.explore_threshold == RewardConfig().explore_threshold


def test_config_argument_replaces_the_preset():
    base = make_config(preset="thesis-30x30", n_agents=2)
    cfg = make_config(preset="thesis-20x20", config=base, max_steps=9)
    assert cfg.height == 30 and cfg.n_agents == 2 and cfg.reward.max_steps == 9
    assert base.reward.max_steps != 9  # the original is not modified


def test_replace_and_frozen():
    cfg = make_config()
    other = cfg.replace(n_slots=6, info_gain=True)
    assert other.n_slots == 6 and other.observation.info_gain
    assert cfg.n_slots == 4 and not cfg.observation.info_gain
    with pytest.raises(dataclasses.FrozenInstanceError):
        cfg.height = 10  # type: ignore[misc]
    with pytest.raises(ValueError, match="n_slots"):
        cfg.replace(n_slots=0)


def test_reward_padding_defaults_by_kind():
    assert RewardConfig(kind="reward1").padding == -1.0
    assert RewardConfig(kind="reward2").padding == -0.1
    assert RewardConfig(kind="reward1", padding_penalty=-0.3).padding == -0.3
    assert RewardConfig(kind="reward1").padding_truncates
    assert not RewardConfig(kind="reward2").padding_truncates
    assert make_config(reward="reward1").reward.padding == -1.0


def test_observation_is_dict():
    assert make_config(agent_position=True).observation.is_dict
    assert make_config(agent_position=False, action_mask=True).observation.is_dict
    assert not make_config(agent_position=False, action_mask=False).observation.is_dict


# ----------------------------------------------------------------------------- round trip
ROUND_TRIP_CASES = [
    {},
    {"preset": "thesis-30x30"},
    {
        "preset": "thesis-30x30",
        "height": 17,
        "width": 23,
        "n_agents": 3,
        "obstacle_prob": 0.35,
        "map_mode": "dynamic",
        "map_seed": 123,
        "sensor": "raycast",
        "cells_per_step": "full",
        "connectivity": 4,
        "max_cluster_cells": 5,
        "n_slots": 7,
        "gain": "unknown",
        "centroid": "distance",
        "agent_position": False,
        "info_gain": True,
        "sort_by_distance": True,
        "action_mask": True,
        "normalize": True,
        "reward": "reward1",
        "explore_threshold": 0.9,
        "threshold_basis": "free",
        "max_steps": 77,
        "no_progress_limit": 5,
        "oscillation_window": 2,
        "cell_reward": 0.1,
        "padding_penalty": -0.7,
        "goal_bonus": 2.0,
    },
    {"cells_per_step": 3, "centroid": "none", "info_gain": True},
]


@pytest.mark.parametrize("kwargs", ROUND_TRIP_CASES)
@pytest.mark.parametrize("preset", ["thesis-20x20", "thesis-30x30"])
def test_config_to_dict_round_trip(kwargs, preset):
    cfg = make_config(**kwargs)
    flat = config_to_dict(cfg)
    assert set(flat) == set(config_keys()) - {"preset", "config"}
    assert make_config(config=None, preset=preset, **flat) == cfg
    assert config_to_dict(make_config(config=None, preset=preset, **flat)) == flat


def test_start_cells_and_obstacle_spread_are_validated_and_used():
    with pytest.raises(ValueError, match="start_cells"):
        make_config(start_cells="corner")
    with pytest.raises(ValueError, match="obstacle_prob_spread"):
        make_config(obstacle_prob_spread=0.6)
    import frontier_marl

    env = frontier_marl.parallel_env(map_mode="dynamic", obstacle_prob_spread=0.1)
    densities = set()
    for seed in range(8):
        env.reset(seed=seed)
        densities.add(round(float(env.world.true_grid.mean()), 3))
    assert len(densities) == 8 and min(densities) < 0.06 and max(densities) > 0.14
    spread, plain = (frontier_marl.parallel_env(obstacle_prob_spread=s) for s in (0.1, 0.0))
    spread.reset(seed=0)
    plain.reset(seed=0)
    np.testing.assert_array_equal(spread.world.true_grid, plain.world.true_grid)  # static
    pocket = frontier_marl.parallel_env(start_cells="any-free", obstacle_prob=0.4)
    sizes = set()
    for seed in range(40):
        pocket.reset(seed=seed)
        region = pocket.world.start_region
        assert region[tuple(pocket.world.positions[0])]
        sizes.add(int(region.sum()))
    assert min(sizes) < 10  # some start in a small pocket
