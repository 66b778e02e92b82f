"""Seeding and reproducibility: in-process, across processes, across a cloudpickle round trip."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from typing import Any

import cloudpickle
import numpy as np
import pytest

import frontier_marl
from frontier_marl import FrontierExploreEnv

# Runs in this process (through exec) and in fresh interpreters: plays seeded episodes with a
# seeded random policy (valid slots mostly, a padding slot now and then) and hashes everything
# the env returns, plus the final belief and true grid.
PLAYER = r'''
import hashlib

import numpy as np

import frontier_marl


def _feed(h, value):
    if isinstance(value, dict):
        for key in sorted(value):
            h.update(repr(key).encode())
            _feed(h, value[key])
    elif isinstance(value, (list, tuple)):
        h.update(b"[%d" % len(value))
        for item in value:
            _feed(h, item)
    elif isinstance(value, np.ndarray):
        h.update(str(value.dtype).encode() + repr(value.shape).encode())
        h.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, float):
        h.update(value.hex().encode())
    else:
        h.update(repr(value).encode())


def choose(mask, rng):
    valid = np.flatnonzero(mask)
    if rng.random() < 0.1:
        return int(rng.integers(len(mask)))
    return int(rng.choice(valid))


def play(adapter, kwargs, seed, episodes=2, max_steps=400):
    """Hex digest of ``episodes`` seeded episodes (first reset seeded, the next ones not)."""
    h = hashlib.sha256()
    rng = np.random.default_rng(seed + 1000)
    if adapter == "gym":
        env = frontier_marl.FrontierExploreEnv(**kwargs)
    else:
        env = frontier_marl.parallel_env(**kwargs)
    for episode in range(episodes):
        obs, info = env.reset(seed=seed if episode == 0 else None)
        _feed(h, (obs, info))
        for _ in range(max_steps):
            if adapter == "gym":
                out = env.step(choose(info["action_mask"], rng))
                obs, info = out[0], out[4]
                done = out[2] or out[3]
            else:
                actions = {a: choose(info[a]["action_mask"], rng) for a in env.agents}
                out = env.step(actions)
                obs, info = out[0], out[4]
                done = not env.agents
            _feed(h, out)
            if done:
                break
        _feed(h, (np.asarray(env.world.belief), np.asarray(env.world.true_grid)))
    return h.hexdigest()
'''

CROSS_PROCESS_CASES: list[tuple[str, dict[str, Any], int]] = [
    ("gym", {"preset": "thesis-20x20"}, 7),
    ("gym", {"preset": "thesis-30x30", "map_mode": "dynamic", "agent_position": False}, 11),
    ("parallel", {"preset": "thesis-20x20", "n_agents": 3, "map_mode": "dynamic"}, 3),
    (
        "parallel",
        {
            "preset": "thesis-30x30",
            "n_agents": 2,
            "sensor": "raycast",
            "gain": "unknown",
            "info_gain": True,
            "centroid": "relative",
            "sort_by_distance": True,
            "cells_per_step": "full",
            "action_mask": True,
        },
        5,
    ),
]


def _player() -> dict[str, Any]:
    namespace: dict[str, Any] = {}
    exec(compile(PLAYER, "<player>", "exec"), namespace)
    return namespace


# ----------------------------------------------------------------------------- helpers
def _record_parallel(env: Any, seed: int, steps: int, policy_seed: int = 0) -> list[Any]:
    """The full trajectory of one seeded episode as plain data (arrays copied)."""
    rng = np.random.default_rng(policy_seed)
    obs, infos = env.reset(seed=seed)
    record: list[Any] = [_copy((obs, infos))]
    for _ in range(steps):
        if not env.agents:
            break
        actions = {a: int(rng.choice(np.flatnonzero(infos[a]["action_mask"]))) for a in env.agents}
        obs, rewards, terms, truncs, infos = env.step(actions)
        record.append(_copy((actions, obs, rewards, terms, truncs, infos)))
    record.append(_copy((env.world.belief, env.world.positions, env.world.travelled)))
    return record


def _record_gym(env: Any, seed: int, steps: int, policy_seed: int = 0) -> list[Any]:
    rng = np.random.default_rng(policy_seed)
    obs, info = env.reset(seed=seed)
    record: list[Any] = [_copy((obs, info))]
    for _ in range(steps):
        action = int(rng.choice(np.flatnonzero(info["action_mask"])))
        out = env.step(action)
        record.append(_copy((action, *out)))
        info = out[4]
        if out[2] or out[3]:
            break
    record.append(_copy((env.world.belief, env.world.positions, env.world.travelled)))
    return record


def _copy(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _copy(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(_copy(v) for v in value)
    if isinstance(value, np.ndarray):
        return value.copy()
    return value


def _assert_same(a: Any, b: Any, where: str = "") -> None:
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), where
        for k in a:
            _assert_same(a[k], b[k], f"{where}/{k}")
    elif isinstance(a, (list, tuple)):
        assert isinstance(b, (list, tuple)) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _assert_same(x, y, f"{where}[{i}]")
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype, where
        np.testing.assert_array_equal(a, b, err_msg=where)
    else:
        assert type(a) is type(b) and a == b, f"{where}: {a!r} != {b!r}"


def _differs(a: Any, b: Any) -> bool:
    try:
        _assert_same(a, b)
    except AssertionError:
        return True
    return False


# ----------------------------------------------------------------------------- in-process
PARALLEL_CONFIGS = [
    pytest.param({"n_agents": 1}, id="static-n1"),
    pytest.param({"n_agents": 3, "map_mode": "dynamic"}, id="dynamic-n3"),
    pytest.param(
        {
            "preset": "thesis-30x30",
            "n_agents": 2,
            "cells_per_step": "full",
            "sensor": "raycast",
            "action_mask": True,
        },
        id="30x30-full-raycast-n2",
    ),
]


@pytest.mark.parametrize("kwargs", PARALLEL_CONFIGS)
def test_parallel_same_seed_same_episode(kwargs: dict[str, Any]) -> None:
    first = _record_parallel(frontier_marl.parallel_env(**kwargs), seed=42, steps=150)
    second = _record_parallel(frontier_marl.parallel_env(**kwargs), seed=42, steps=150)
    assert len(first) > 3
    _assert_same(first, second)


@pytest.mark.parametrize(
    "kwargs", [{}, {"map_mode": "dynamic", "preset": "thesis-30x30", "agent_position": False}]
)
def test_gym_same_seed_same_episode(kwargs: dict[str, Any]) -> None:
    first = _record_gym(FrontierExploreEnv(**kwargs), seed=42, steps=150)
    second = _record_gym(FrontierExploreEnv(**kwargs), seed=42, steps=150)
    assert len(first) > 3
    _assert_same(first, second)


def test_reseeding_a_used_env_replays_the_episode() -> None:
    env = frontier_marl.parallel_env(n_agents=2, map_mode="dynamic")
    first = _record_parallel(env, seed=9, steps=60)
    _record_parallel(env, seed=123, steps=30)  # play something else in between
    again = _record_parallel(env, seed=9, steps=60)
    _assert_same(first, again)

    gym_env = FrontierExploreEnv(map_mode="dynamic")
    first = _record_gym(gym_env, seed=9, steps=60)
    _record_gym(gym_env, seed=123, steps=30)
    _assert_same(first, _record_gym(gym_env, seed=9, steps=60))


def test_gym_and_parallel_agree_with_one_robot() -> None:
    """Both adapters drive the same MDP: one robot, same seed, same actions -> same episode."""
    for kwargs in ({}, {"map_mode": "dynamic", "centroid": "relative", "action_mask": True}):
        gym_record = _record_gym(FrontierExploreEnv(**kwargs), seed=4, steps=100)
        par_record = _record_parallel(frontier_marl.parallel_env(**kwargs), seed=4, steps=100)
        assert len(gym_record) == len(par_record)
        _assert_same(gym_record[0], (par_record[0][0]["robot_0"], par_record[0][1]["robot_0"]))
        for g, p in zip(gym_record[1:-1], par_record[1:-1], strict=True):
            action, obs, reward, terminated, truncated, info = g
            p_actions, p_obs, p_rewards, p_terms, p_truncs, p_infos = p
            _assert_same(
                (action, obs, reward, terminated, truncated, info),
                (
                    p_actions["robot_0"],
                    p_obs["robot_0"],
                    p_rewards["robot_0"],
                    p_terms["robot_0"],
                    p_truncs["robot_0"],
                    p_infos["robot_0"],
                ),
            )
        _assert_same(gym_record[-1], par_record[-1])


def test_player_hash_is_stable_in_process() -> None:
    play = _player()["play"]
    adapter, kwargs, seed = CROSS_PROCESS_CASES[2]
    assert play(adapter, kwargs, seed) == play(adapter, kwargs, seed)
    assert play(adapter, kwargs, seed) != play(adapter, kwargs, seed + 1)


def test_determinism_across_processes() -> None:
    """Two fresh interpreters (different hash seeds) and this process produce the same hashes."""
    play = _player()["play"]
    local = [play(adapter, kwargs, seed) for adapter, kwargs, seed in CROSS_PROCESS_CASES]
    code = PLAYER + (
        "\nimport json, sys\n"
        "cases = json.loads(sys.argv[1])\n"
        "print(json.dumps([play(a, k, s) for a, k, s in cases]))\n"
    )
    outputs = []
    for hash_seed in ("0", "4242"):
        env = dict(os.environ, PYTHONHASHSEED=hash_seed)
        done = subprocess.run(
            [sys.executable, "-c", code, json.dumps(CROSS_PROCESS_CASES)],
            capture_output=True,
            text=True,
            env=env,
            timeout=120,
            check=False,
        )
        assert done.returncode == 0, done.stderr
        outputs.append(json.loads(done.stdout.strip().splitlines()[-1]))
    assert outputs[0] == outputs[1] == local


# ----------------------------------------------------------------------------- seeds and maps
def test_dynamic_maps_and_episodes_differ_across_seeds() -> None:
    env = frontier_marl.parallel_env(map_mode="dynamic")
    grids = []
    for seed in range(6):
        env.reset(seed=seed)
        grids.append(np.array(env.world.true_grid))
    for i in range(len(grids)):
        for j in range(i):
            assert not np.array_equal(grids[i], grids[j]), (i, j)
    a = _record_parallel(frontier_marl.parallel_env(map_mode="dynamic"), seed=0, steps=40)
    b = _record_parallel(frontier_marl.parallel_env(map_mode="dynamic"), seed=1, steps=40)
    assert _differs(a, b)


def test_dynamic_maps_differ_across_unseeded_resets() -> None:
    envs = (frontier_marl.parallel_env(map_mode="dynamic"), FrontierExploreEnv(map_mode="dynamic"))
    for env in envs:
        env.reset(seed=0)
        first = np.array(env.world.true_grid)
        env.reset()
        assert not np.array_equal(first, env.world.true_grid)


@pytest.mark.parametrize("preset", ["thesis-20x20", "thesis-30x30"])
def test_static_map_depends_only_on_map_seed(preset: str) -> None:
    env = frontier_marl.parallel_env(preset=preset, n_agents=2)
    gym_env = FrontierExploreEnv(preset=preset)
    env.reset(seed=0)
    reference = np.array(env.world.true_grid)
    starts = set()
    for seed in [1, 2, 3, None, 5, 6, 7, 8, None, 10]:
        for e in (env, gym_env):
            e.reset(seed=seed)
            np.testing.assert_array_equal(e.world.true_grid, reference)
        starts.add(tuple(map(tuple, env.world.positions.tolist())))
    assert len(starts) >= 5, "static mode must draw a random start cell per episode"
    # A fresh env with the same map_seed has the same map; another map_seed another map.
    same = frontier_marl.parallel_env(preset=preset)
    same.reset(seed=99)
    np.testing.assert_array_equal(same.world.true_grid, reference)
    other = frontier_marl.parallel_env(preset=preset, map_seed=1)
    other.reset(seed=0)
    assert not np.array_equal(other.world.true_grid, reference)


def test_static_mode_start_cells_differ_across_seeds_gym() -> None:
    env = FrontierExploreEnv()
    starts = set()
    for seed in range(10):
        _, info = env.reset(seed=seed)
        starts.add(tuple(info["position"].tolist()))
    assert len(starts) >= 5


# ----------------------------------------------------------------------------- cloudpickle
def _continue_parallel(env: Any, steps: int, policy_seed: int) -> list[Any]:
    """Play on from the env's current state; then one unseeded reset and a few steps."""
    rng = np.random.default_rng(policy_seed)
    record: list[Any] = []
    for _ in range(2):
        for _ in range(steps):
            if not env.agents:
                break
            masks = env.mdp.action_masks()
            actions = {
                a: int(rng.choice(np.flatnonzero(masks[i]))) for i, a in enumerate(env.agents)
            }
            record.append(_copy((actions, *env.step(actions))))
        record.append(_copy(env.reset()))  # unseeded: continues the pickled RNG
    return record


def _continue_gym(env: Any, steps: int, policy_seed: int) -> list[Any]:
    rng = np.random.default_rng(policy_seed)
    record: list[Any] = []
    for _ in range(2):
        for _ in range(steps):
            action = int(rng.choice(np.flatnonzero(env.action_masks())))
            out = env.step(action)
            record.append(_copy((action, *out)))
            if out[2] or out[3]:
                break
        record.append(_copy(env.reset()))
    return record


@pytest.mark.parametrize("moment", ["fresh", "after_reset", "mid_episode"])
@pytest.mark.parametrize(
    "kwargs",
    [
        pytest.param({"n_agents": 1}, id="n1"),
        pytest.param({"n_agents": 3, "map_mode": "dynamic", "action_mask": True}, id="n3-dynamic"),
    ],
)
def test_cloudpickle_round_trip_parallel(kwargs: dict[str, Any], moment: str) -> None:
    env = frontier_marl.parallel_env(**kwargs)
    if moment != "fresh":
        env.reset(seed=17)
    if moment == "mid_episode":
        rng = np.random.default_rng(1)
        for _ in range(5):
            env.step({a: int(rng.integers(2)) for a in env.agents})
        assert env.agents, "the episode should still be running"
    clone = cloudpickle.loads(cloudpickle.dumps(env))
    assert clone is not env
    if moment == "fresh":
        _assert_same(_copy(env.reset(seed=17)), _copy(clone.reset(seed=17)))
    else:
        assert clone.world is not env.world
        _assert_same(_copy(clone.world.belief), _copy(env.world.belief))
        assert clone.agents == env.agents
    _assert_same(_continue_parallel(env, 80, 5), _continue_parallel(clone, 80, 5))


@pytest.mark.parametrize("moment", ["fresh", "after_reset", "mid_episode"])
def test_cloudpickle_round_trip_gym(moment: str) -> None:
    env = FrontierExploreEnv(map_mode="dynamic", agent_position=False)
    if moment != "fresh":
        env.reset(seed=17)
    if moment == "mid_episode":
        for _ in range(5):
            env.step(0)
    clone = cloudpickle.loads(cloudpickle.dumps(env))
    if moment == "fresh":
        _assert_same(_copy(env.reset(seed=17)), _copy(clone.reset(seed=17)))
    else:
        assert clone.world is not env.world
    _assert_same(_continue_gym(env, 80, 5), _continue_gym(clone, 80, 5))


def test_cloudpickle_keeps_world_read_only() -> None:
    env = frontier_marl.parallel_env(n_agents=2)
    env.reset(seed=0)
    clone = cloudpickle.loads(cloudpickle.dumps(env))
    for name in ("true_grid", "belief", "positions"):
        assert not getattr(clone.world, name).flags.writeable, name
