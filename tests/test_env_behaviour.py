"""Behaviour of the adapters: action checking, padding, spaces, info, slots, world, rendering."""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

import frontier_marl
from frontier_marl import FrontierExploreEnv, reason_name, slot_table
from frontier_marl.core.grid import FREE, UNKNOWN
from frontier_marl.core.slots import SlotArrays

INFO_KEYS = {
    "explored_fraction",
    "coverage",
    "new_cells",
    "action_mask",
    "slots",
    "target",
    "position",
    "travelled",
    "padding",
    "oscillation",
    "step",
    "end_reason",
}
CLUSTER_KEYS = {"slot", "cluster", "centroid", "target", "size", "gain", "distance", "path_length"}
FOUR = ndimage.generate_binary_structure(2, 1)


def _random_actions(env: Any, infos: dict[str, Any], rng: np.random.Generator) -> dict[str, int]:
    """A valid slot per live robot, chosen uniformly."""
    return {a: int(rng.choice(np.flatnonzero(infos[a]["action_mask"]))) for a in env.agents}


def _padding_seed(env: Any, agent: str = "robot_0") -> tuple[int, int, dict[str, Any]]:
    """A seed whose first state gives ``agent`` a padding slot: (seed, padding slot, infos)."""
    for seed in range(50):
        _, infos = env.reset(seed=seed)
        free = np.flatnonzero(infos[agent]["action_mask"] == 0)
        if len(free):
            return seed, int(free[0]), infos
    raise AssertionError("no start state with a padding slot in 50 seeds")


def _step_all(env: Any, action: Any) -> Any:
    return env.step(dict.fromkeys(env.agents, action))


# ----------------------------------------------------------------------------- invalid actions
@pytest.mark.parametrize("bad", [4, -1, 100, np.int64(4)])
def test_out_of_range_action_raises_value_error(bad: Any) -> None:
    env = frontier_marl.parallel_env(n_agents=2)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"\[0, 3\]"):
        env.step({"robot_0": 0, "robot_1": bad})
    gym_env = FrontierExploreEnv()
    gym_env.reset(seed=0)
    with pytest.raises(ValueError, match=r"\[0, 3\]"):
        gym_env.step(bad)


@pytest.mark.parametrize("bad", [1.0, np.float32(1.0), "1", None, True, np.array([0, 1])])
def test_wrong_action_type_raises(bad: Any) -> None:
    expected = ValueError if isinstance(bad, np.ndarray) else TypeError
    env = frontier_marl.parallel_env(n_agents=2)
    env.reset(seed=0)
    with pytest.raises(expected, match="action"):
        env.step({"robot_0": bad, "robot_1": 0})
    gym_env = FrontierExploreEnv()
    gym_env.reset(seed=0)
    with pytest.raises(expected, match="action"):
        gym_env.step(bad)


@pytest.mark.parametrize("good", [1, np.int64(1), np.int8(1), np.array(1), np.array([1])])
def test_integer_like_actions_are_accepted(good: Any) -> None:
    env = FrontierExploreEnv(agent_position=False)
    env.reset(seed=0)
    reference = FrontierExploreEnv(agent_position=False)
    reference.reset(seed=0)
    out, ref = env.step(good), reference.step(1)
    np.testing.assert_array_equal(out[0], ref[0])
    assert out[1:4] == ref[1:4]


def test_missing_or_extra_agent_key_raises() -> None:
    env = frontier_marl.parallel_env(n_agents=3)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="robot_2"):
        env.step({"robot_0": 0, "robot_1": 0})
    with pytest.raises(ValueError, match="robot_9"):
        env.step({"robot_0": 0, "robot_1": 0, "robot_2": 0, "robot_9": 0})
    with pytest.raises(ValueError):
        env.step({})


def test_rejected_step_changes_nothing() -> None:
    """A bad action is refused before any state changes: the episode goes on as if unsent."""
    kwargs = {"n_agents": 3, "map_mode": "dynamic", "agent_position": False}
    env = frontier_marl.parallel_env(**kwargs)
    ref = frontier_marl.parallel_env(**kwargs)
    env.reset(seed=8)
    _, infos = ref.reset(seed=8)
    for bad in ({"robot_0": 0, "robot_1": 1, "robot_2": 7}, {"robot_0": 0, "robot_1": 1.5}):
        with pytest.raises((ValueError, TypeError)):
            env.step(bad)
    rng = np.random.default_rng(0)
    for _ in range(30):
        if not ref.agents:
            break
        actions = _random_actions(ref, infos, rng)
        obs, rewards, _, _, infos = ref.step(actions)
        obs2, rewards2, _, _, infos2 = env.step(actions)
        assert rewards == rewards2
        for agent in obs:
            np.testing.assert_array_equal(obs[agent], obs2[agent])
            np.testing.assert_array_equal(infos[agent]["position"], infos2[agent]["position"])
            assert infos[agent]["oscillation"] == infos2[agent]["oscillation"]


def test_step_before_reset_raises() -> None:
    with pytest.raises(RuntimeError):
        frontier_marl.parallel_env().step({"robot_0": 0})
    with pytest.raises(RuntimeError):
        FrontierExploreEnv().step(0)


# ----------------------------------------------------------------------------- padding slots
def test_padding_reward1_penalises_and_truncates() -> None:
    env = frontier_marl.parallel_env(reward="reward1")
    seed, slot, infos = _padding_seed(env)
    position = infos["robot_0"]["position"]
    _, rewards, terms, truncs, infos = env.step({"robot_0": slot})
    cfg = env.config.reward
    assert rewards["robot_0"] == pytest.approx(cfg.padding + cfg.no_new_cell_penalty)
    assert rewards["robot_0"] == pytest.approx(-1.05)
    assert truncs == {"robot_0": True} and terms == {"robot_0": False}
    info = infos["robot_0"]
    assert info["padding"] is True and info["target"].tolist() == [-1, -1]
    assert "padding" in reason_name(info["end_reason"])
    assert (info["position"] == position).all() and info["new_cells"] == 0
    assert env.agents == []
    # The Gymnasium adapter does the same.
    gym_env = FrontierExploreEnv(reward="reward1")
    gym_env.reset(seed=seed)
    _, reward, terminated, truncated, info = gym_env.step(slot)
    assert (reward, terminated, truncated) == (rewards["robot_0"], False, True)


def test_padding_reward2_penalises_and_continues() -> None:
    env = frontier_marl.parallel_env(reward="reward2")
    _, slot, infos = _padding_seed(env)
    position = infos["robot_0"]["position"]
    for step in range(3):  # the robot stays put, the episode goes on
        _, rewards, terms, truncs, infos = env.step({"robot_0": slot})
        cfg = env.config.reward
        expected = cfg.padding + cfg.no_new_cell_penalty
        assert rewards["robot_0"] == pytest.approx(expected), step
        assert rewards["robot_0"] == pytest.approx(-0.15)
        assert terms == {"robot_0": False} and truncs == {"robot_0": False}
        assert infos["robot_0"]["padding"] is True
        assert (infos["robot_0"]["position"] == position).all()
        assert env.agents == ["robot_0"]


def test_padding_by_one_robot_truncates_the_team_under_reward1() -> None:
    env = frontier_marl.parallel_env(reward="reward1", n_agents=2)
    _, slot, infos = _padding_seed(env, "robot_1")
    valid = int(np.flatnonzero(infos["robot_0"]["action_mask"])[0])
    _, rewards, terms, truncs, infos = env.step({"robot_0": valid, "robot_1": slot})
    assert truncs == {"robot_0": True, "robot_1": True}
    assert terms == {"robot_0": False, "robot_1": False}
    assert infos["robot_1"]["padding"] and not infos["robot_0"]["padding"]
    assert rewards["robot_1"] <= -1.0
    assert rewards["robot_0"] > -1.0  # the padding penalty is the chooser's own
    assert env.agents == []


# ----------------------------------------------------------------------------- spaces
def test_spaces_are_cached_objects() -> None:
    env = frontier_marl.parallel_env(n_agents=3, agent_position=True, action_mask=True)
    for agent in env.possible_agents:
        assert env.observation_space(agent) is env.observation_space(agent)
        assert env.action_space(agent) is env.action_space(agent)
        assert env.observation_spaces[agent] is env.observation_space(agent)
        assert env.action_spaces[agent] is env.action_space(agent)
    env.reset(seed=0)
    assert env.observation_space("robot_1") is env.observation_spaces["robot_1"]


OBS_CASES = [
    pytest.param(
        {"centroid": c, "info_gain": g, "agent_position": p, "action_mask": m, "normalize": n},
        id=f"{c}-gain{int(g)}-pos{int(p)}-mask{int(m)}-norm{int(n)}",
    )
    for c, g, p, m, n in itertools.product(
        ["absolute", "relative", "distance", "none"],
        [False, True],
        [False, True],
        [False, True],
        [False, True],
    )
    if c != "none" or g
]


@pytest.mark.parametrize("obs_kwargs", OBS_CASES)
def test_observations_stay_in_space(obs_kwargs: dict[str, Any]) -> None:
    env = frontier_marl.parallel_env(
        n_agents=2, height=12, width=17, map_mode="dynamic", gain="unknown", **obs_kwargs
    )
    space = env.observation_space("robot_0")
    is_dict = obs_kwargs["agent_position"] or obs_kwargs["action_mask"]
    assert type(space).__name__ == ("Dict" if is_dict else "Box")
    rng = np.random.default_rng(0)
    steps = 0
    for seed in range(2):
        obs, infos = env.reset(seed=seed)
        while True:
            for agent, o in obs.items():
                assert space.contains(o), (agent, o)
            if not env.agents:
                break
            obs, _, _, _, infos = env.step(_random_actions(env, infos, rng))
            steps += 1
    assert steps > 10


# ----------------------------------------------------------------------------- info and slots
def _reachable_clusters(world: Any, agent: int) -> set[int]:
    """Clusters with a cell 4-connected to the robot through known-free cells."""
    labels, _ = ndimage.label(np.asarray(world.belief) == FREE, structure=FOUR)
    row, col = world.positions[agent]
    clusters = world.clusters()
    here = labels[clusters.cell_rows, clusters.cell_cols] == labels[row, col]
    return set(np.unique(clusters.cell_cluster[here]).tolist())


def _check_infos(env: Any, infos: dict[str, Any]) -> None:
    world = env.world
    belief = np.asarray(world.belief)
    clusters = world.clusters()
    for index, agent in enumerate(env.possible_agents):
        info = infos[agent]
        assert set(info) >= INFO_KEYS, INFO_KEYS - set(info)
        assert info["explored_fraction"] == pytest.approx(
            world.explored_fraction(env.config.reward.threshold_basis)
        )
        assert 0.0 <= info["coverage"] <= 1.0
        assert info["position"].tolist() == world.positions[index].tolist()
        mask = info["action_mask"]
        assert mask.dtype == np.int8 and mask.shape == (env.config.n_slots,)
        assert info["slots"].shape == (env.config.n_slots, 10)
        live = slot_table(info).rows()
        for entry in live:
            assert set(entry) == CLUSTER_KEYS
        slots = [entry["slot"] for entry in live]
        if live:
            # The mask is exactly the live slots, and live slots come first.
            np.testing.assert_array_equal(np.flatnonzero(mask), slots)
            assert slots == list(range(len(slots)))
        else:
            np.testing.assert_array_equal(mask, np.eye(len(mask), dtype=np.int8)[0])
        reachable = _reachable_clusters(world, index)
        assert len(live) == min(env.config.n_slots, len(reachable))
        distance_of = {}
        for entry in live:
            k = entry["cluster"]
            assert k in reachable
            cells = {tuple(c) for c in clusters.cells_of(k).tolist()}
            assert entry["target"] in cells  # a reachable cell of the cluster
            assert belief[entry["target"]] == FREE
            assert entry["size"] == len(cells)
            np.testing.assert_allclose(entry["centroid"], clusters.centroids[k])
            d = float(np.hypot(*(np.array(entry["centroid"]) - world.positions[index])))
            assert entry["distance"] == pytest.approx(d)
            distance_of[k] = d
        # The slots hold the nearest reachable clusters.
        others = [
            float(np.hypot(*(clusters.centroids[k] - world.positions[index])))
            for k in reachable - set(distance_of)
        ]
        if others and distance_of:
            assert max(distance_of.values()) <= min(others) + 1e-9


@pytest.mark.parametrize(
    "kwargs",
    [
        pytest.param({"n_agents": 1}, id="n1"),
        pytest.param({"n_agents": 3, "map_mode": "dynamic", "sort_by_distance": True}, id="n3"),
        pytest.param(
            {
                "preset": "thesis-30x30",
                "n_agents": 2,
                "n_slots": 6,
                "cells_per_step": "full",
                "sensor": "raycast",
            },
            id="30x30-full",
        ),
        pytest.param({"height": 11, "width": 23, "connectivity": 4}, id="non-square"),
    ],
)
def test_info_and_action_mask_match_live_clusters(kwargs: dict[str, Any]) -> None:
    env = frontier_marl.parallel_env(**kwargs)
    rng = np.random.default_rng(1)
    checked = 0
    for seed in range(2):
        _, infos = env.reset(seed=seed)
        _check_infos(env, infos)
        while env.agents and checked < 120:
            _, _, _, _, infos = env.step(_random_actions(env, infos, rng))
            if env.agents:
                _check_infos(env, infos)
            checked += 1
    assert checked > 20


def test_sorted_layout_orders_slots_by_distance() -> None:
    sorted_env = frontier_marl.parallel_env(sort_by_distance=True, n_slots=8, n_agents=2)
    plain_env = frontier_marl.parallel_env(sort_by_distance=False, n_slots=8, n_agents=2)
    rng = np.random.default_rng(2)
    seen_unsorted = False
    for seed in range(12):
        _, infos = sorted_env.reset(seed=seed)
        _, plain = plain_env.reset(seed=seed)
        for _ in range(5):
            for agent in sorted_env.agents:
                s, p = slot_table(infos[agent]).rows(), slot_table(plain[agent]).rows()
                distances = [e["distance"] for e in s]
                assert distances == sorted(distances)
                ids = [e["cluster"] for e in p]
                assert ids == sorted(ids)  # unsorted: label (raster) order
                # Sorting orders the slots; it never changes which clusters get one.
                assert {e["cluster"] for e in s} == set(ids)
                seen_unsorted |= [e["distance"] for e in p] != distances
            if not sorted_env.agents:
                break
            # Same target in both envs so the two stay in the same state.
            actions, plain_actions = {}, {}
            for agent in sorted_env.agents:
                rows = slot_table(infos[agent]).rows()
                entry = rows[int(rng.integers(len(rows)))]
                actions[agent] = entry["slot"]
                plain_actions[agent] = next(
                    e["slot"]
                    for e in slot_table(plain[agent]).rows()
                    if e["cluster"] == entry["cluster"]
                )
            _, _, _, _, infos = sorted_env.step(actions)
            _, _, _, _, plain = plain_env.step(plain_actions)
    assert seen_unsorted, "the unsorted layout should sometimes differ from the sorted one"


ENCODINGS = ["absolute", "relative", "distance"]


@pytest.mark.parametrize("centroid", ENCODINGS)
@pytest.mark.parametrize("normalize", [False, True])
def test_cluster_features_encode_the_slot_table(centroid: str, normalize: bool) -> None:
    height, width = 13, 21
    env = frontier_marl.parallel_env(
        height=height,
        width=width,
        n_agents=2,
        centroid=centroid,
        info_gain=True,
        agent_position=True,
        normalize=normalize,
        n_slots=5,
        map_mode="dynamic",
        obstacle_prob_spread=0.0,  # the layouts this test's seed was chosen on
    )
    scale = {
        "absolute": [height, width],
        "relative": [height, width],
        "distance": [float(np.hypot(height, width))],
    }[centroid]
    gain_scale = float(env.config.max_cluster_cells)
    rng = np.random.default_rng(3)
    obs, infos = env.reset(seed=4)
    padding_seen = False
    for _ in range(40):
        for index, agent in enumerate(env.possible_agents):
            table = obs[agent]["clusters"].reshape(env.config.n_slots, -1)
            assert table.shape[1] == len(scale) + 1
            position = np.asarray(env.world.positions[index], dtype=float)
            expected_position = position / ([height, width] if normalize else [1, 1])
            np.testing.assert_allclose(obs[agent]["agent_position"], expected_position, rtol=1e-6)
            live = slot_table(infos[agent]).rows()
            for entry in live:
                centroid_arr = np.array(entry["centroid"])
                feature = {
                    "absolute": centroid_arr,
                    "relative": centroid_arr - position,
                    "distance": np.array([entry["distance"]]),
                }[centroid]
                if normalize:
                    feature = feature / np.array(scale)
                gain = entry["gain"] / (gain_scale if normalize else 1.0)
                np.testing.assert_allclose(table[entry["slot"], :-1], feature, rtol=1e-5, atol=1e-5)
                np.testing.assert_allclose(table[entry["slot"], -1], gain, rtol=1e-5)
            padding_rows = table[len(live) :]
            padding_seen |= len(padding_rows) > 0
            assert not padding_rows.any(), "padding slots must be all zeros"
        if not env.agents:
            break
        obs, _, _, _, infos = env.step(_random_actions(env, infos, rng))
    assert padding_seen


@settings(max_examples=40, deadline=None)
@given(
    centroid=st.sampled_from(["none", *ENCODINGS]),
    info_gain=st.booleans(),
    normalize=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_compiled_features_are_numpys_to_the_bit(centroid, info_gain, normalize, seed) -> None:
    """The thesis layout's vectors equal the numpy formula: float64 values divided by their
    scale, then rounded to float32 (relative offsets zero in padding slots)."""
    from frontier_marl.config import make_config
    from frontier_marl.sim.observations import ObservationEncoder

    info_gain = info_gain or centroid == "none"  # an empty layout is refused
    cfg = make_config(
        "thesis-20x20", centroid=centroid, info_gain=info_gain, normalize=normalize, n_slots=4
    )
    encoder = ObservationEncoder(cfg)
    rng = np.random.default_rng(seed)
    slots = SlotArrays.empty(3, 1, 4).rows(slice(None))
    slots.valid[:] = rng.random((3, 4)) < 0.7
    slots.centroid[:] = rng.random((3, 4, 2)) * 20 * slots.valid[..., None]
    slots.distance[:] = rng.random((3, 4)) * 28 * slots.valid
    slots.gain[:] = rng.integers(0, 30, (3, 4)) * slots.valid
    positions = rng.integers(0, 20, (3, 2))
    parts = []
    if centroid == "absolute":
        parts.append(slots.centroid)
    elif centroid == "relative":
        relative = slots.centroid - positions[:, None, :]
        parts.append(np.where(slots.valid[..., None], relative, 0.0))
    elif centroid == "distance":
        parts.append(slots.distance[..., None])
    if info_gain:
        parts.append(slots.gain[..., None])
    expected = np.concatenate(parts, axis=-1) / encoder._scale
    observed = encoder.encode_batch(slots, positions)
    flat = observed["clusters"] if isinstance(observed, dict) else observed
    assert flat.dtype == np.float32
    assert np.array_equal(flat, expected.astype(np.float32).reshape(3, -1))


def test_relative_encoding_flat_box() -> None:
    env = FrontierExploreEnv(centroid="relative", agent_position=False, n_slots=6)
    obs, info = env.reset(seed=1)
    rng = np.random.default_rng(0)
    for _ in range(30):
        table = obs.reshape(6, 2)
        position = np.array(info["position"], dtype=float)
        rows = slot_table(info).rows()
        for entry in rows:
            np.testing.assert_allclose(
                table[entry["slot"]], np.array(entry["centroid"]) - position, atol=1e-5
            )
        assert not table[len(rows) :].any()
        obs, _, terminated, truncated, info = env.step(
            int(rng.choice(np.flatnonzero(info["action_mask"])))
        )
        if terminated or truncated:
            break


def test_observation_mask_matches_info_mask_while_running() -> None:
    env = frontier_marl.parallel_env(n_agents=3, action_mask=True, map_mode="dynamic")
    rng = np.random.default_rng(5)
    for seed in range(3):
        obs, infos = env.reset(seed=seed)
        while env.agents:
            for agent in env.agents:
                mask = infos[agent]["action_mask"]
                np.testing.assert_array_equal(obs[agent]["action_mask"], mask)
            obs, _, _, _, infos = env.step(_random_actions(env, infos, rng))


def _explore_fully(env: Any, seed: int) -> tuple[Any, Any, Any, Any, Any]:
    obs, infos = env.reset(seed=seed)
    out = (obs, None, None, None, infos)
    for _ in range(2000):
        if not env.agents:
            return out
        out = env.step({a: int(np.flatnonzero(out[4][a]["action_mask"])[0]) for a in env.agents})
    raise AssertionError("episode did not end")


FULL = {
    "explore_threshold": 1.0,
    "threshold_basis": "reachable",
    "cells_per_step": "full",
    "max_steps": 2000,
    "no_progress_limit": 2000,
    "height": 10,
    "width": 10,
}


def test_full_exploration_ends_with_threshold() -> None:
    env = frontier_marl.parallel_env(n_agents=2, **FULL)
    _, rewards, terms, truncs, infos = _explore_fully(env, seed=0)
    assert all(terms.values()) and not any(truncs.values())
    assert reason_name(infos["robot_0"]["end_reason"]) == "threshold"
    assert infos["robot_0"]["explored_fraction"] == 1.0


def test_thesis_preset_greedy_episode_completes() -> None:
    """Thesis 20x20 preset, one robot walking full paths to slot 0: seed 17 reveals the last
    frontier in one step (a regression test: no frontier cell left used to crash the slots)."""
    env = frontier_marl.parallel_env(cells_per_step="full")
    env.reset(seed=17)
    for _ in range(400):
        _, _, terms, truncs, _ = env.step({"robot_0": 0})
        if not env.agents:
            break
    assert terms == {"robot_0": True} and truncs == {"robot_0": False}


def test_no_frontier_left_terminates() -> None:
    # Ray casting leaves cells behind walls unknown, so "all cells" is never reached: the episode
    # must end by running out of frontiers.
    env = frontier_marl.parallel_env(**{**FULL, "threshold_basis": "all", "sensor": "raycast"})
    _, _, terms, truncs, infos = _explore_fully(env, seed=0)
    assert terms == {"robot_0": True} and truncs == {"robot_0": False}
    assert reason_name(infos["robot_0"]["end_reason"]) == "no_frontier"
    assert slot_table(infos["robot_0"]).rows() == []


def test_observation_mask_matches_info_mask_without_live_slots() -> None:
    env = frontier_marl.parallel_env(n_agents=1, action_mask=True, **FULL)
    obs, _, _, _, infos = _explore_fully(env, seed=0)
    assert slot_table(infos["robot_0"]).rows() == []
    np.testing.assert_array_equal(obs["robot_0"]["action_mask"], infos["robot_0"]["action_mask"])


# ----------------------------------------------------------------------------- world
def test_world_is_read_only() -> None:
    for env in (frontier_marl.parallel_env(n_agents=2), FrontierExploreEnv()):
        with pytest.raises(RuntimeError):
            _ = env.world
        env.reset(seed=0)
        world = env.world
        for name in ("true_grid", "belief", "positions", "seen", "travelled", "start_region"):
            array = getattr(world, name)
            assert isinstance(array, np.ndarray)
            assert not array.flags.writeable, name
            with pytest.raises(ValueError):
                array[(0,) * array.ndim] = array[(0,) * array.ndim]
        side = env.config.height
        assert world.true_grid.shape == world.belief.shape == (side, side)
        assert world.positions.shape == (env.config.n_agents, 2)
        assert world.belief.dtype == np.int8
        assert set(np.unique(world.belief).tolist()) <= {UNKNOWN, FREE, 1}


def test_state_is_a_copy_of_the_belief() -> None:
    env = frontier_marl.parallel_env(n_agents=2)
    env.reset(seed=0)
    state = env.state()
    np.testing.assert_array_equal(state, env.world.belief)
    state[...] = 1
    assert (env.world.belief != 1).any()


# ----------------------------------------------------------------------------- rendering
def test_render_modes() -> None:
    for make in (frontier_marl.parallel_env, FrontierExploreEnv):
        env = make(render_mode="rgb_array")
        with pytest.raises(RuntimeError):
            env.render()
        env.reset(seed=0)
        frame = env.render()
        assert isinstance(frame, np.ndarray) and frame.dtype == np.uint8
        assert frame.ndim == 3 and frame.shape[2] == 3 and frame.shape[0] > 20
        env = make(render_mode="ansi")
        env.reset(seed=0)
        text = env.render()
        assert isinstance(text, str)
        lines = text.strip("\n").splitlines()
        assert len(lines) >= 20 and "0" in text  # one line per row at least; robot 0 drawn
        env = make()
        env.reset(seed=0)
        assert env.render() is None


@pytest.mark.parametrize("mode", ["rgb", "RGB_ARRAY", "video", ""])
def test_unknown_render_mode_raises(mode: str) -> None:
    with pytest.raises(ValueError, match="render_mode"):
        frontier_marl.parallel_env(render_mode=mode)
    with pytest.raises(ValueError, match="render_mode"):
        FrontierExploreEnv(render_mode=mode)


# ----------------------------------------------------------------------------- episodes, robots
@pytest.mark.parametrize(
    "kwargs",
    [
        pytest.param({"n_agents": 3}, id="n3-r2"),
        pytest.param({"n_agents": 4, "reward": "reward1", "map_mode": "dynamic"}, id="n4-r1"),
    ],
)
def test_episode_ends_for_all_agents_together(kwargs: dict[str, Any]) -> None:
    env = frontier_marl.parallel_env(**kwargs)
    rng = np.random.default_rng(6)
    ended = 0
    for seed in range(6):
        _, infos = env.reset(seed=seed)
        while env.agents:
            actions = {a: int(rng.integers(env.config.n_slots)) for a in env.agents}
            _, rewards, terms, truncs, infos = env.step(actions)
            assert set(rewards) == set(terms) == set(truncs) == set(env.possible_agents)
            assert len(set(terms.values())) == 1 and len(set(truncs.values())) == 1
            reasons = {info["end_reason"] for info in infos.values()}
            assert len(reasons) == 1
            done = next(iter(terms.values())) or next(iter(truncs.values()))
            assert (env.agents == []) == done
            assert bool(reasons.pop()) == done
        ended += 1
        with pytest.raises(RuntimeError):
            env.step(dict.fromkeys(env.possible_agents, 0))
    assert ended == 6


@pytest.mark.parametrize("cells_per_step", [1, 3, "full"])
def test_robots_never_share_a_cell(cells_per_step: int | str) -> None:
    env = frontier_marl.parallel_env(
        n_agents=5,
        cells_per_step=cells_per_step,
        map_mode="dynamic",
        obstacle_prob=0.3,
        height=14,
        width=14,
        info="debug",  # with the path
    )
    rng = np.random.default_rng(7)
    steps = 0
    for seed in range(200):
        if steps >= 150:
            break
        _, infos = env.reset(seed=seed)
        while True:
            world = env.world
            positions = [tuple(p) for p in world.positions.tolist()]
            assert len(set(positions)) == len(positions), positions
            assert not world.true_grid[tuple(np.asarray(positions).T)].any()
            if not env.agents:
                break
            known_before = int(np.count_nonzero(np.asarray(world.belief) != UNKNOWN))
            before = positions
            travelled = world.travelled.copy()
            actions = {a: int(rng.integers(env.config.n_slots)) for a in env.agents}
            _, _, _, _, infos = env.step(actions)
            steps += 1
            known_after = int(np.count_nonzero(np.asarray(env.world.belief) != UNKNOWN))
            assert sum(i["new_cells"] for i in infos.values()) == known_after - known_before
            for index, agent in enumerate(env.possible_agents):
                path = infos[agent]["path"]
                assert tuple(path[0]) == before[index]
                assert tuple(path[-1]) == tuple(infos[agent]["position"])
                assert (np.abs(np.diff(path, axis=0)).sum(axis=1) == 1).all()
                assert not env.world.true_grid[path[:, 0], path[:, 1]].any()
                if cells_per_step != "full":
                    assert len(path) - 1 <= cells_per_step
                assert env.world.travelled[index] - travelled[index] == len(path) - 1
    assert steps >= 150


@pytest.mark.parametrize("seed", [-1, 1.5, "7", True, np.float64(3.0)])
def test_a_bad_reset_seed_is_named_by_every_env(seed: object) -> None:
    from frontier_marl.envs.gym_env import FrontierExploreEnv

    for env in (frontier_marl.parallel_env(), FrontierExploreEnv()):
        with pytest.raises(ValueError, match=r"reset\(seed=\.\.\.\) must be None or an integer"):
            env.reset(seed=seed)
    batch = frontier_marl.vector_env(num_envs=2)
    with pytest.raises(ValueError, match="seed"):
        batch.reset(seed=seed)
    with pytest.raises(ValueError, match=r"reset\(seed=\.\.\.\)\[1\] must be None or an integer"):
        batch.reset(seed=[0, seed])


def test_every_env_refuses_a_step_before_reset() -> None:
    batch = frontier_marl.vector_env(num_envs=2)
    with pytest.raises(RuntimeError, match=r"before reset\(\)"):
        batch.step(np.zeros(2, dtype=np.int64))
    with pytest.raises(RuntimeError, match=r"call reset\(\) first"):
        frontier_marl.parallel_env().step({"robot_0": 0})
    batch.reset(seed=0)
    batch.step(np.zeros(2, dtype=np.int64))  # after reset it steps
