"""The v1 env API (issue 33): infos of numbers and fixed-shape arrays at every level, the
classic mask layout, ``TypeError`` for unknown keywords, ``max_cycles``, the v1 ids."""

from __future__ import annotations

import numbers
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest

import frontier_marl
from frontier_marl import END_REASONS, SLOT_COLUMNS, reason_name, slot_table
from frontier_marl.config import UnknownKeywordError
from frontier_marl.envs.infos import INFO_LEVELS
from frontier_marl.envs.layout import ObservationLayout
from frontier_marl.envs.registration import VARIANTS

LEVEL_KEYS = {
    "mask": {"action_mask"},
    "minimal": {"explored_fraction", "coverage", "new_cells", "travelled", "step", "end_reason"},
    "full": {"slots", "target", "position", "padding", "oscillation"},
    "debug": {"path"},
}

EXPLORER_DQN = Path(__file__).resolve().parents[1] / "training" / "models" / "explorer-dqn"


def _signature(value: Any) -> tuple[str, tuple[int, ...]]:
    """A value's kind and shape: a number, or a numeric array of that shape."""
    if isinstance(value, np.ndarray):
        assert value.dtype.kind in "biuf", value.dtype
        return value.dtype.kind, value.shape
    assert isinstance(value, numbers.Number), type(value)
    return "bool" if isinstance(value, bool) else "number", ()


def _episode_infos(level: str, n_agents: int) -> list[dict[str, Any]]:
    """Every info of two episodes of uniformly random actions, padding slots included."""
    env = frontier_marl.parallel_env(n_agents=n_agents, info=level, max_steps=60)
    rng = np.random.default_rng(0)
    seen = []
    for seed in range(2):
        _, infos = env.reset(seed=seed)
        seen += infos.values()
        while env.agents:
            actions = {a: int(rng.integers(env.config.n_slots)) for a in env.agents}
            *_, infos = env.step(actions)
            seen += infos.values()
    return seen


@pytest.mark.parametrize("n_agents", [1, 3])
@pytest.mark.parametrize("level", ["mask", "minimal", "full"])
def test_infos_are_numbers_of_fixed_shape_at_every_level(level: str, n_agents: int) -> None:
    infos = _episode_infos(level, n_agents)
    expected = set().union(*(LEVEL_KEYS[k] for k in INFO_LEVELS[: INFO_LEVELS.index(level) + 1]))
    first = {key: _signature(value) for key, value in infos[0].items()}
    assert set(first) == expected
    for info in infos:
        assert {key: _signature(value) for key, value in info.items()} == first
    if level == "full":
        assert first["slots"] == ("f", (4, len(SLOT_COLUMNS)))
        assert first["target"] == first["position"] == ("i", (2,))
        assert any(info["target"][0] == -1 for info in infos)  # padding chosen: no target


def test_debug_level_adds_the_path() -> None:
    infos = _episode_infos("debug", 2)
    assert all(info["path"].shape[1:] == (2,) and len(info["path"]) in (1, 2) for info in infos)


def test_end_reasons_are_codes_named_by_the_table() -> None:
    assert END_REASONS[0] == "" and END_REASONS[1] == "threshold"
    assert END_REASONS[2] == "no_frontier" and END_REASONS[4 | 16] == "padding+step_limit"
    assert reason_name(8) == "no_progress" and reason_name("threshold") == "threshold"
    env = frontier_marl.parallel_env(reward="reward1")
    _, infos = env.reset(seed=0)
    assert infos["robot_0"]["end_reason"] == 0
    padding = int(np.flatnonzero(infos["robot_0"]["action_mask"] == 0)[0])
    *_, infos = env.step({"robot_0": padding})
    assert reason_name(infos["robot_0"]["end_reason"]) == "padding"


def test_slot_table_unpacks_the_info_to_the_engines_table() -> None:
    env = frontier_marl.parallel_env(n_agents=3, commit="until-progress", map_mode="dynamic")
    rng = np.random.default_rng(1)
    _, infos = env.reset(seed=2)
    for _ in range(40):
        tables = env.mdp.slot_tables()
        for agent, table in zip(env.agents, tables, strict=True):
            assert slot_table(infos[agent]) == table
        if not env.agents:
            break
        actions = {a: int(rng.choice(np.flatnonzero(infos[a]["action_mask"]))) for a in env.agents}
        *_, infos = env.step(actions)
    with pytest.raises(ValueError, match="slots"):
        slot_table({"action_mask": np.ones(4, np.int8)})


# ----------------------------------------------------------------------------- layout
LAYOUTS = {
    "box": ({"agent_position": False, "action_mask": True}, ["clusters"]),
    "position": ({"action_mask": True}, ["agent_position", "clusters"]),
    "team": (
        {"action_mask": True, "n_agents": 3, "teammates": "positions"},
        ["agent_position", "clusters", "teammates"],
    ),
    "explorer": ({"features": "explorer", "n_slots": 6}, ["slots"]),
}


@pytest.mark.parametrize("name", list(LAYOUTS))
def test_classic_layout_puts_the_mask_beside_one_observation(name: str) -> None:
    kwargs, keys = LAYOUTS[name]
    classic = frontier_marl.parallel_env(**kwargs)
    flat = frontier_marl.parallel_env(obs_layout="flat", **kwargs)
    space = classic.observation_space("robot_0")
    assert list(space.spaces) == ["action_mask", "observation"]
    assert isinstance(space["observation"], gymnasium.spaces.Box)
    assert list(flat.observation_space("robot_0").spaces) == sorted([*keys, "action_mask"])
    layout = ObservationLayout(flat.observation_space("robot_0"))
    assert layout.space == space
    observations, _ = classic.reset(seed=3)
    expected, _ = flat.reset(seed=3)
    for agent, obs in observations.items():
        assert space.contains(obs)
        parts = [expected[agent][key].reshape(-1) for key in keys]
        assert np.array_equal(obs["observation"].reshape(-1), np.concatenate(parts))
        assert np.array_equal(obs["action_mask"], expected[agent]["action_mask"])
        back = layout.unwrap(obs)
        assert sorted(back) == sorted(expected[agent])
        assert all(np.array_equal(back[key], expected[agent][key]) for key in back)


def test_layouts_without_a_mask_are_the_same_and_bad_layouts_raise() -> None:
    for kwargs in ({}, {"agent_position": False}):
        spaces = [
            frontier_marl.parallel_env(obs_layout=layout, **kwargs).observation_space("robot_0")
            for layout in ("classic", "flat")
        ]
        assert spaces[0] == spaces[1]
    with pytest.raises(ValueError, match="obs_layout"):
        frontier_marl.parallel_env(obs_layout="nested")


def test_vector_and_gymnasium_envs_take_the_layout_alike() -> None:
    kwargs = {"action_mask": True}
    vec = gymnasium.make_vec(
        frontier_marl.GYM_ID, 2, vectorization_mode="vector_entry_point", **kwargs
    )
    sync = gymnasium.make_vec(frontier_marl.GYM_ID, 2, vectorization_mode="sync", **kwargs)
    assert vec.single_observation_space == sync.single_observation_space
    (batched, vec_infos), (synced, sync_infos) = vec.reset(seed=0), sync.reset(seed=[0, 1])
    for key in ("observation", "action_mask"):
        assert np.array_equal(batched[key], synced[key])
    assert vec_infos["end_reason"].dtype.kind == sync_infos["end_reason"].dtype.kind == "i"
    assert frontier_marl.vector_env(2, obs_layout="flat", **kwargs).single_observation_space == (
        frontier_marl.parallel_env(obs_layout="flat", **kwargs).observation_space("robot_0")
    )


def test_a_model_acts_alike_on_the_classic_and_the_flat_layout() -> None:
    pytest.importorskip("stable_baselines3")
    from frontier_marl.evaluation import evaluate
    from frontier_marl.policies import ModelPolicy
    from frontier_marl.policies.models import load_model

    loaded = load_model(EXPLORER_DQN)  # a slot scorer of the repository's research models
    cfg = loaded.env_config()
    results = [
        evaluate({"config": cfg, "obs_layout": layout}, ModelPolicy(loaded.model), episodes=2)
        for layout in ("classic", "flat")
    ]
    assert results[0].to_dict() == results[1].to_dict()


def test_models_of_either_layout_pass_the_model_check_and_act() -> None:
    pytest.importorskip("stable_baselines3")
    from pathlib import Path

    from stable_baselines3 import DQN

    from frontier_marl.policies import ModelPolicy
    from frontier_marl.policies.metadata import ModelEnvMismatchError
    from frontier_marl.policies.models import LoadedModel, check_model_env

    cfg = frontier_marl.make_config(action_mask=True)
    obs, info = frontier_marl.FrontierExploreEnv(config=cfg).reset(seed=0)  # classic
    for layout in ("classic", "flat"):
        env = frontier_marl.FrontierExploreEnv(config=cfg, obs_layout=layout)
        model = DQN("MultiInputPolicy", env, buffer_size=10, learning_starts=10)
        check_model_env(LoadedModel(model, Path("model.zip"), None), cfg)
        assert 0 <= ModelPolicy(model).act(obs, info) < cfg.n_slots
    with pytest.raises(ModelEnvMismatchError):
        check_model_env(LoadedModel(model, Path("model.zip"), None), cfg.replace(n_slots=5))


# ----------------------------------------------------------------------------- keywords, ids
@pytest.mark.parametrize(
    "make",
    [
        pytest.param(lambda **kw: frontier_marl.parallel_env(**kw), id="parallel"),
        pytest.param(lambda **kw: frontier_marl.env(**kw), id="aec"),
        pytest.param(lambda **kw: frontier_marl.FrontierExploreEnv(**kw), id="gym"),
        pytest.param(lambda **kw: gymnasium.make(frontier_marl.GYM_ID, **kw), id="gym-make"),
        pytest.param(lambda **kw: frontier_marl.vector_env(2, **kw), id="vector"),
    ],
)
def test_unknown_keywords_raise_type_error_naming_them(make: Any) -> None:
    with pytest.raises(TypeError, match="unexpected keyword argument 'frameskip'") as error:
        make(frameskip=4)
    assert isinstance(error.value, UnknownKeywordError) and isinstance(error.value, ValueError)
    assert "max_steps" in str(error.value) and "obs_layout" in str(error.value)
    with pytest.raises(TypeError, match="unexpected keyword arguments 'a', 'b'"):
        make(b=1, a=2)


def test_max_cycles_is_pettingzoos_name_for_the_step_limit() -> None:
    from pettingzoo.test import max_cycles_test

    assert frontier_marl.parallel_env(max_cycles=7).config.reward.max_steps == 7
    assert frontier_marl.make_config(max_cycles=7) == frontier_marl.make_config(max_steps=7)
    with pytest.raises(TypeError, match="max_steps or max_cycles"):
        frontier_marl.parallel_env(max_cycles=7, max_steps=8)
    max_cycles_test(frontier_marl)


def test_the_parallel_env_takes_the_mask_level_and_names_bad_levels() -> None:
    _, infos = frontier_marl.parallel_env(info="mask", n_agents=2).reset(seed=0)
    assert all(set(info) == {"action_mask"} for info in infos.values())
    with pytest.raises(ValueError, match="info must be one of"):
        frontier_marl.parallel_env(info="everything")


@pytest.mark.filterwarnings("ignore:.*out of date:DeprecationWarning")
def test_the_ids_are_v1_and_v0_names_its_successor() -> None:
    assert frontier_marl.GYM_ID.endswith("-v1") and all(i.endswith("-v1") for i in VARIANTS)
    assert frontier_marl.parallel_env().metadata["name"] == "frontier_explore_v1"
    with pytest.raises(gymnasium.error.DeprecatedEnv, match="v1"):
        gymnasium.make("frontier_marl/FrontierExplore-v0")
