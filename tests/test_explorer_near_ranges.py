"""The unknown_near square sized in sensor ranges (``near_ranges``) rather than fixed cells."""

from __future__ import annotations

import numpy as np
import pytest

import frontier_marl
from frontier_marl.config import make_config
from frontier_marl.core.slots import SlotArrays
from frontier_marl.policies.metadata import ModelEnvMismatchError, check_compatible
from frontier_marl.sim.features import NEAR, near_half_side, unknown_near
from frontier_marl.sim.observations import ObservationEncoder, describe_layout

EXPLORER = {"features": "explorer", "n_slots": 6, "gain": "unknown", "unknown_near": True}


def test_near_half_side_in_cells_and_in_sensor_ranges() -> None:
    assert near_half_side(None, 5) == NEAR
    assert near_half_side(4, 3) == 12
    assert near_half_side(2.5, 13) == 32  # 32.5 rounds to even
    assert near_half_side(0.1, 3) == 1  # at least one cell


@pytest.mark.parametrize(("near_ranges", "half_side"), [(None, NEAR), (2.0, 10), (1.0, 5)])
def test_the_feature_reads_the_square_of_its_half_side(near_ranges, half_side) -> None:
    cfg = {**EXPLORER, "height": 40, "width": 40, "perception_range": 5}
    env = frontier_marl.parallel_env(**cfg, near_ranges=near_ranges)
    observations, _ = env.reset(seed=4)
    assert ObservationEncoder(env.config).near == half_side
    for _ in range(5):
        table = SlotArrays.stack(env.mdp.slot_tables())
        expected = unknown_near(table, env.world.belief[None], half_side)[0, :, 0]
        assert np.array_equal(observations["robot_0"]["observation"][:, -1], expected)
        mask = observations["robot_0"]["action_mask"]
        observations, *_ = env.step({"robot_0": int(np.flatnonzero(mask)[0])})


def test_bad_near_ranges_are_named() -> None:
    with pytest.raises(ValueError, match="near_ranges must be in"):
        make_config("rooms-32", **EXPLORER, near_ranges=0)
    with pytest.raises(ValueError, match="near_ranges must be a finite number"):
        make_config("rooms-32", **EXPLORER, near_ranges="wide")
    with pytest.raises(ValueError, match="needs unknown_near=True"):
        make_config("rooms-32", **{**EXPLORER, "unknown_near": False}, near_ranges=2)


def test_a_model_with_another_square_is_refused() -> None:
    trained = make_config("rooms-32", **EXPLORER, near_ranges=4)
    other = make_config("rooms-32", **EXPLORER)
    space = ObservationEncoder(other).space
    action = frontier_marl.parallel_env(**EXPLORER).action_space("robot_0")
    meta = {"observation_layout": describe_layout(trained)}
    with pytest.raises(ModelEnvMismatchError, match="near_ranges"):
        check_compatible(other, space, action, space, action, meta)
    check_compatible(trained, space, action, space, action, meta)  # the same square: fine
