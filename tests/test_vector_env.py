"""The batched vector env: world i of a batch seeded s plays the episodes of the ParallelEnv
reset with seed s + i (autoresets included); the SB3 adapter gives SuperSuit's transitions;
bad input is refused by name."""

from __future__ import annotations

import itertools
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

import frontier_marl
from frontier_marl import FrontierParallelEnv, vector_env
from frontier_marl.config import PRESETS, make_config
from frontier_marl.core.frontiers import cluster_frontiers, frontier_mask
from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN
from frontier_marl.core.sensing import make_sensor
from frontier_marl.core.worlds import WorldParams, Worlds
from frontier_marl.envs.registration import GYM_ID
from tests.helpers import silent

STEP_KEYS = ("explored_fraction", "coverage", "new_cells", "travelled", "step", "end_reason")
FULL_KEYS = ("padding", "oscillation")


def _same(a: Any, b: Any) -> bool:
    if isinstance(b, dict):
        return a.keys() == b.keys() and all(np.array_equal(a[key], b[key]) for key in b)
    return np.array_equal(a, b) and np.asarray(a).dtype == np.asarray(b).dtype


def _row(batch: Any, j: int) -> Any:
    return {key: value[j] for key, value in batch.items()} if isinstance(batch, dict) else batch[j]


def play_side_by_side(n_worlds: int, steps: int, seed: int, mode: str, **kwargs: Any) -> int:
    """Steps a batch and one ParallelEnv per world with the same actions and checks every
    observation, reward, flag and info value; returns the number of episode ends seen."""
    vec = vector_env(n_worlds, autoreset_mode=mode, info="full", **kwargs)
    k = vec.n_agents
    robots = [f"robot_{a}" for a in range(k)]
    singles = [FrontierParallelEnv(info="full", **kwargs) for _ in range(n_worlds)]
    observations, infos = vec.reset(seed=seed)
    expected = [env.reset(seed=seed + i)[0] for i, env in enumerate(singles)]
    restart = [False] * n_worlds
    rng = np.random.default_rng(seed)
    ends = 0

    def check_observations(i: int, single_obs: dict[str, Any]) -> None:
        for a, robot in enumerate(robots):
            assert _same(_row(observations, i * k + a), single_obs[robot])

    for i in range(n_worlds):
        check_observations(i, expected[i])
    for _ in range(steps):
        masks = infos["action_mask"]
        valid = (rng.random(masks.shape) * masks).argmax(axis=1)
        actions = np.where(rng.random(len(valid)) < 0.9, valid, rng.integers(0, masks.shape[1]))
        observations, rewards, terminations, truncations, infos = vec.step(actions)
        for i, env in enumerate(singles):
            rows = slice(i * k, (i + 1) * k)
            if restart[i]:  # next-step autoreset: this step restarted world i
                single_obs, _ = env.reset()
                restart[i] = False
                check_observations(i, single_obs)
                assert not rewards[rows].any() and not terminations[rows].any()
                continue
            single = env.step({robot: int(actions[i * k + a]) for a, robot in enumerate(robots)})
            single_obs, single_rewards, single_term, single_trunc, single_infos = single
            ended = single_term["robot_0"] or single_trunc["robot_0"]
            for a, robot in enumerate(robots):
                j = i * k + a
                assert rewards[j] == single_rewards[robot]
                assert terminations[j] == single_term[robot]
                assert truncations[j] == single_trunc[robot]
                if ended and mode == "same-step":
                    info = infos["final_info"][j]
                    assert _same(infos["final_obs"][j], single_obs[robot])
                else:
                    info = {key: infos[key][j] for key in (*STEP_KEYS, *FULL_KEYS)}
                for key in (*STEP_KEYS, *FULL_KEYS):
                    assert info[key] == single_infos[robot][key], key
            if ended:
                ends += 1
                if mode == "same-step":
                    single_obs, _ = env.reset()
                else:
                    restart[i] = True
                    continue
            check_observations(i, single_obs)
    return ends


CASES = [
    pytest.param(preset, map_mode, n_agents, mode, id=f"{preset}-{map_mode}-{n_agents}-{mode}")
    for preset, map_mode, n_agents, mode in itertools.product(
        PRESETS, ("static", "dynamic"), (1, 4), ("next-step", "same-step")
    )
]


@pytest.mark.parametrize("preset,map_mode,n_agents,mode", CASES)
def test_world_i_plays_the_parallel_env_seeded_s_plus_i(
    preset: str, map_mode: str, n_agents: int, mode: str
) -> None:
    ends = play_side_by_side(
        3, 60, 17, mode, preset=preset, map_mode=map_mode, n_agents=n_agents, max_steps=25
    )
    assert ends >= 3  # autoresets happened and were checked


@pytest.mark.parametrize(
    "kwargs",
    [
        {"centroid": "relative", "sort_by_distance": True, "reward": "reward1"},
        {"agent_position": False, "info_gain": True, "centroid": "distance", "normalize": True},
        {"n_agents": 3, "teammates": "positions+targets", "action_mask": True, "normalize": True},
        {"n_agents": 2, "teammates": "positions", "team_weight": 0.5, "gain": "unknown"},
        {"cells_per_step": "full", "map_mode": "dynamic", "start_cells": "any-free"},
        {"features": "explorer", "commit": "until-progress", "reward": "travel", "max_steps": 40},
        {"features": "explorer", "n_agents": 3, "teammates": "positions+targets", "max_steps": 40},
        {"features": "explorer", "n_agents": 2, "tour": True, "turn": True, "max_steps": 40},
        {
            "features": "explorer",
            "n_agents": 2,
            "unknown_near": True,
            "fill": True,
            "max_steps": 40,
        },
    ],
    ids=[
        "relative-sorted-r1",
        "box-distance-gain",
        "teammates-targets",
        "team-reward",
        "full",
        "explorer-commit",
        "explorer-team",
        "explorer-tour-turn",
        "explorer-unknown-near",
    ],  # fmt: skip
)
def test_equality_holds_for_every_observation_and_reward_variant(kwargs: dict[str, Any]) -> None:
    assert play_side_by_side(2, 120, 3, "same-step", **kwargs) >= 1


def test_stacked_labelling_keeps_worlds_apart() -> None:
    """Two worlds with frontier cells at the same cells: one label call, separate clusters,
    each world's clusters equal to its own labelling."""
    belief = np.full((2, 4, 5), UNKNOWN, dtype=np.int8)
    belief[:, 1:3, 0:2] = FREE  # the same frontier block in both worlds
    belief[1, 0:2, 3:5] = FREE  # and a second cluster in world 1 only
    belief[1, 0, 2] = OCCUPIED
    params = WorldParams(make_sensor("square", 1), 1)
    worlds = Worlds((4, 5), 2, 1, params)
    worlds.belief[:] = belief
    worlds.version[:] = 1
    worlds.refresh_clusters()
    for i in range(2):
        mine, alone = worlds.clusters(i), cluster_frontiers(belief[i], 8)
        assert np.array_equal(mine.cell_cluster, alone.cell_cluster)
        assert np.array_equal(mine.sizes, alone.sizes)
        assert np.array_equal(mine.centroids, alone.centroids)
    assert list(worlds.n_clusters) == [1, 2]


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_worlds=st.integers(1, 5),
    height=st.integers(1, 12),
    width=st.integers(1, 12),
    connectivity=st.sampled_from([4, 8]),
)
def test_each_world_is_labelled_as_scipy_labels_its_whole_map(
    seed: int, n_worlds: int, height: int, width: int, connectivity: int
) -> None:
    """The batch labels each world's frontier cropped to its box and packed beside the other
    worlds' crops; every world's clusters are numbered as ``scipy.ndimage.label`` numbers the
    frontier of its whole map (worlds with no frontier, and every shape, included)."""
    rng = np.random.default_rng(seed)
    belief = rng.choice(
        np.array([UNKNOWN, FREE, OCCUPIED], dtype=np.int8),
        size=(n_worlds, height, width),
        p=rng.dirichlet(np.ones(3)),
    )
    params = WorldParams(make_sensor("square", 1), 1, connectivity=connectivity)
    worlds = Worlds((height, width), n_worlds, 1, params)
    worlds.belief[:] = belief
    worlds.version[:] = 1
    worlds.refresh_clusters()
    structure = ndimage.generate_binary_structure(2, 1 if connectivity == 4 else 2)
    for i in range(n_worlds):
        expected, count = ndimage.label(frontier_mask(belief[i]), structure=structure)
        assert np.array_equal(worlds.clusters(i).labels(), expected)
        assert worlds.n_clusters[i] == count


def test_sb3_adapter_gives_supersuit_transitions_and_the_same_dqn() -> None:
    import torch
    from stable_baselines3 import DQN
    from stable_baselines3.common.utils import set_random_seed

    from frontier_marl.training.batched_vec_env import make_batched_vec_env
    from frontier_marl.training.vec_env import make_vec_env

    torch.set_num_threads(1)
    cfg = make_config("thesis-20x20", n_agents=2, normalize=True, max_steps=30)
    supersuit, batched = (
        make({"config": cfg}, 2, seed=11) for make in (make_vec_env, make_batched_vec_env)
    )
    assert _same(supersuit.reset(), batched.reset())
    rng = np.random.default_rng(0)
    ends = 0
    for _ in range(200):
        actions = rng.integers(0, cfg.n_slots, supersuit.num_envs)
        (obs_a, rew_a, done_a, info_a), (obs_b, rew_b, done_b, info_b) = (
            env.step(actions) for env in (supersuit, batched)
        )
        assert _same(obs_a, obs_b) and _same(rew_a, rew_b)
        assert np.array_equal(done_a, done_b)  # SuperSuit: uint8, here bool
        for a, b in zip(info_a, info_b, strict=True):
            for key in ("TimeLimit.truncated", "episode_end_reason"):
                assert a.get(key) == b.get(key)
            assert ("terminal_observation" in a) == ("terminal_observation" in b)
            if "terminal_observation" in a:
                ends += 1
                assert _same(a["terminal_observation"], b["terminal_observation"])
                assert a["episode"]["r"] == b["episode"]["r"]
    assert ends > 10
    cfg = make_config("thesis-20x20", normalize=True)
    weights = []
    for make in (make_vec_env, make_batched_vec_env):
        set_random_seed(3)
        env = make({"config": cfg}, 2, seed=3)
        model = DQN(
            "MultiInputPolicy",
            env,
            learning_starts=100,
            buffer_size=2000,
            batch_size=16,
            target_update_interval=100,
        )
        model.action_space.seed(3)
        silent(model).learn(600)
        weights.append(torch.cat([p.flatten() for p in model.policy.parameters()]))
    assert torch.equal(weights[0], weights[1])


def test_infos_are_arrays_and_levels_leave_out_the_rest() -> None:
    vec = vector_env(4, n_agents=2, info="full")
    _, infos = vec.reset(seed=0)
    assert infos["action_mask"].shape == (8, vec.config.n_slots)
    assert infos["action_mask"].dtype == np.int8
    assert all(infos[f"_{key}"].all() for key in (*STEP_KEYS, *FULL_KEYS, "position", "target"))
    assert infos["position"].shape == (8, 2)
    masks_only = vector_env(4, n_agents=2, info="mask")
    _, infos = masks_only.reset(seed=0)
    assert set(infos) == {"action_mask", "_action_mask"}
    minimal = vector_env(2)
    _, infos = minimal.reset(seed=0)
    assert set(STEP_KEYS) <= set(infos) and "position" not in infos


def test_spaces_hold_the_batch_and_gymnasium_make_vec_builds_it() -> None:
    vec = gymnasium.make_vec(
        GYM_ID, num_envs=3, vectorization_mode="vector_entry_point", preset="rooms-32"
    )
    assert isinstance(vec, frontier_marl.FrontierVectorEnv)
    observations, infos = vec.reset(seed=1)
    assert vec.observation_space.contains(observations)
    assert vec.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    for _ in range(5):
        observations, rewards, _, _, infos = vec.step(infos["action_mask"].argmax(axis=1))
        assert vec.observation_space.contains(observations)
        assert rewards.shape == (3,)


def test_same_seed_same_batch_and_unseeded_resets_continue() -> None:
    runs = []
    for _ in range(2):
        vec = vector_env(3, map_mode="dynamic")
        first, _ = vec.reset(seed=5)
        second, _ = vec.reset()
        runs.append((first, second))
    assert _same(runs[0][0], runs[1][0]) and _same(runs[0][1], runs[1][1])
    assert not _same(runs[0][0], runs[0][1])
    listed = vector_env(2, map_mode="dynamic")
    observations, _ = listed.reset(seed=[5, 6])
    assert _same(observations, vector_env(2, map_mode="dynamic").reset(seed=5)[0])


@pytest.mark.parametrize("num_envs", [0, -2])
def test_num_envs_below_one_is_refused(num_envs: int) -> None:
    with pytest.raises(ValueError, match="num_envs"):
        vector_env(num_envs)


@pytest.mark.parametrize("num_envs", [1.5, True, "4"])
def test_num_envs_of_another_type_is_refused(num_envs: Any) -> None:
    with pytest.raises(TypeError, match="num_envs"):
        vector_env(num_envs)


def test_bad_actions_are_refused_by_name() -> None:
    vec = vector_env(2, n_agents=2)
    with pytest.raises(RuntimeError, match="before reset"):
        vec.step(np.zeros(4, dtype=np.int64))
    vec.reset(seed=0)
    with pytest.raises(ValueError, match=r"actions\[1\] = 18446744073709551615"):
        vec.step(np.array([0, 2**64 - 1, 0, 0], dtype=np.uint64))  # -1 as an int64
    with pytest.raises(ValueError, match=r"actions\[3\] = -7"):
        vec.step(np.array([0, 0, 0, -7], dtype=np.int32))
    with pytest.raises(ValueError, match=r"shape \(4,\)"):
        vec.step(np.zeros(2, dtype=np.int64))
    with pytest.raises(TypeError, match="dtype float64"):
        vec.step(np.zeros(4))
    with pytest.raises(ValueError, match=r"actions\[2\] = 4"):
        vec.step(np.array([0, 0, 4, 0]))
    with pytest.raises(ValueError, match=r"actions\[0\] = -1"):
        vec.step(np.array([-1, 0, 0, 0]))
    with pytest.raises(ValueError, match="seed"):
        vec.reset(seed=[1, 2, 3])
    with pytest.raises(ValueError, match="autoreset_mode"):
        vector_env(2, autoreset_mode="whenever")
    with pytest.raises(ValueError, match="info"):
        vector_env(2, info="everything")
    with pytest.raises(ValueError, match="n_agents"):
        vector_env(2, n_agents=0)


def _episodes_of_first_valid_policy(skip: bool, n_agents: int) -> tuple[list[list], int]:
    """Per world, (return, cells travelled, end reason) of its first three episodes when every
    robot takes its first valid slot; also the number of steps called."""
    vec = vector_env(
        3,
        autoreset_mode="same-step",
        skip_forced_steps=skip,
        n_agents=n_agents,
        map_mode="dynamic",
        features="explorer",
        commit="until-reached",
        reward="travel",
    )
    k = vec.n_agents
    _, infos = vec.reset(seed=11)
    returns = np.zeros(vec.num_envs)
    episodes: list[list] = [[] for _ in range(vec.n_worlds)]
    calls = 0
    fresh = np.ones(vec.n_worlds, dtype=bool)  # episodes may start with a single choice
    while min(len(e) for e in episodes) < 3:
        masks = infos["action_mask"]
        if skip:  # every world that did not just reset offers some robot a choice
            choice = (masks.reshape(vec.n_worlds, k, -1).sum(axis=2) > 1).any(axis=1)
            assert (choice | fresh).all()
        _, rewards, terminated, truncated, infos = vec.step(masks.argmax(axis=1))
        calls += 1
        returns += rewards
        fresh = (terminated | truncated)[::k]
        for j in np.flatnonzero(fresh).tolist():
            final = infos["final_info"][j * k]
            episodes[j].append((round(returns[j * k], 9), final["travelled"], final["end_reason"]))
            returns[j * k : (j + 1) * k] = 0.0
    return [e[:3] for e in episodes], calls


@pytest.mark.parametrize("n_agents", [1, 2])
def test_skipping_forced_steps_plays_the_same_episodes_in_fewer_steps(n_agents: int) -> None:
    stepped, every_step = _episodes_of_first_valid_policy(False, n_agents)
    skipped, decisions = _episodes_of_first_valid_policy(True, n_agents)
    assert skipped == stepped
    assert decisions < every_step


def test_skip_forced_steps_must_be_a_bool() -> None:
    with pytest.raises(ValueError, match="skip_forced_steps"):
        vector_env(1, skip_forced_steps=1)
