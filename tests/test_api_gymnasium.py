"""Gymnasium API conformance of the single-robot env (Gymnasium and SB3 checkers)."""

from __future__ import annotations

import itertools
import warnings
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import frontier_marl
from frontier_marl import FrontierExploreEnv
from frontier_marl.config import PRESETS as PRESET_TABLE
from frontier_marl.config import make_config
from frontier_marl.envs.registration import VARIANTS, variant_id

PRESETS = tuple(PRESET_TABLE)
MAP_MODES = ("static", "dynamic")
OBSERVATIONS = {
    "box": {"agent_position": False},
    "dict": {"agent_position": True, "action_mask": True},
    "dict-pos": {"agent_position": True},
}
#: Every registered id, in both map modes, with each observation layout.
CASES = [
    pytest.param(env_id, {"map_mode": m, **OBSERVATIONS[o]}, id=f"{env_id.split('/')[1]}-{m}-{o}")
    for env_id, m, o in itertools.product(VARIANTS, MAP_MODES, OBSERVATIONS)
]


@pytest.mark.parametrize("env_id,kwargs", CASES)
def test_gymnasium_check_env(env_id: str, kwargs: dict[str, Any]) -> None:
    env = gymnasium.make(env_id, **kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # any checker warning is a failure
        gym_check_env(env.unwrapped, skip_render_check=True)
    env.close()


@pytest.mark.parametrize("env_id,kwargs", CASES)
def test_sb3_check_env(env_id: str, kwargs: dict[str, Any]) -> None:
    env = gymnasium.make(env_id, **kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_check_env(env, warn=True)
    env.close()


@pytest.mark.parametrize("render_mode", ["rgb_array", "ansi"])
def test_gymnasium_render_check(render_mode: str) -> None:
    env = gymnasium.make(frontier_marl.GYM_ID, render_mode=render_mode).unwrapped
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gym_check_env(env)  # includes the render check of every non-human mode


@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("by_variant", [False, True])
def test_make_by_id(preset: str, by_variant: bool) -> None:
    if by_variant:
        env = gymnasium.make(variant_id(preset))
    else:
        env = gymnasium.make(frontier_marl.GYM_ID, preset=preset)
    base = env.unwrapped
    assert isinstance(base, FrontierExploreEnv)
    assert base.config == make_config(preset)
    side = base.config.height
    assert env.action_space == gymnasium.spaces.Discrete(base.config.n_slots)
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    assert base.world.true_grid.shape == (side, side)
    assert {"explored_fraction", "new_cells", "action_mask", "slots", "target"} <= set(info)


def test_make_passes_overrides() -> None:
    env = gymnasium.make(
        frontier_marl.GYM_ID,
        preset="thesis-30x30",
        n_slots=6,
        centroid="relative",
        agent_position=False,
    )
    base = env.unwrapped
    assert base.config.n_slots == 6
    assert env.action_space.n == 6
    assert isinstance(env.observation_space, gymnasium.spaces.Box)
    assert env.observation_space.shape == (12,)


@pytest.mark.parametrize("n_agents", [2, 3])
def test_gym_env_rejects_teams(n_agents: int) -> None:
    with pytest.raises(ValueError, match="n_agents"):
        FrontierExploreEnv(n_agents=n_agents)
    with pytest.raises(ValueError, match="n_agents"):
        gymnasium.make(frontier_marl.GYM_ID, n_agents=n_agents)


def test_bad_parameter_raises_at_construction() -> None:
    with pytest.raises(ValueError, match="preset"):
        FrontierExploreEnv(preset="thesis-99x99")
    with pytest.raises(ValueError, match="n_slots"):
        FrontierExploreEnv(n_slots=0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'no_such_key'"):
        FrontierExploreEnv(no_such_key=1)


def test_action_masks_match_info() -> None:
    env = FrontierExploreEnv(agent_position=True, action_mask=True)
    obs, info = env.reset(seed=5)
    rng = np.random.default_rng(0)
    for _ in range(60):
        mask = env.action_masks()
        assert mask.dtype == bool
        np.testing.assert_array_equal(mask, info["action_mask"].astype(bool))
        action = int(rng.choice(np.flatnonzero(mask)))
        obs, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break


def test_step_returns_python_types() -> None:
    env = FrontierExploreEnv()
    env.reset(seed=0)
    _, reward, terminated, truncated, info = env.step(0)
    assert type(reward) is float
    assert type(terminated) is bool
    assert type(truncated) is bool
    assert isinstance(info, dict)


def test_step_after_episode_end_raises() -> None:
    env = FrontierExploreEnv(reward="reward1")
    obs, info = env.reset(seed=0)
    done = False
    steps = 0
    while not done:
        mask = info["action_mask"]
        padding = np.flatnonzero(mask == 0)
        action = int(padding[0]) if len(padding) else 0
        _, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
        steps += 1
        assert steps < 1000
    with pytest.raises(RuntimeError):
        env.step(0)
