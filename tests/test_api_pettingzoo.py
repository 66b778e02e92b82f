"""PettingZoo API conformance of the Parallel and AEC forms (pettingzoo.test suites)."""

from __future__ import annotations

import itertools
import warnings
from typing import Any

import matplotlib
import pytest
from pettingzoo.test import api_test, parallel_api_test, parallel_seed_test, render_test

import frontier_marl
from frontier_marl.config import PRESETS as PRESET_TABLE
from frontier_marl.config import make_config
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.envs.registration import VARIANTS, variant_id

matplotlib.use("Agg")

PRESETS = tuple(PRESET_TABLE)
MAP_MODES = ("static", "dynamic")
N_AGENTS = (1, 3)
# Flat Box observation, and a Dict one with the agent position and the action mask.
OBSERVATIONS = {
    "box": {"agent_position": False},
    "dict": {"agent_position": True, "action_mask": True},
}

#: Every registered id (as its env kwargs), in both map modes, alone and as a team, with each
#: observation layout.
CASES = [
    pytest.param(
        {**VARIANTS[env_id], "map_mode": mode, "n_agents": n, **OBSERVATIONS[obs]},
        id=f"{env_id.split('/')[1]}-{mode}-n{n}-{obs}",
    )
    for env_id, mode, n, obs in itertools.product(VARIANTS, MAP_MODES, N_AGENTS, OBSERVATIONS)
]

# PettingZoo's checkers warn about Dict observations by design; they are not failures here.
pytestmark = pytest.mark.filterwarnings(
    "ignore:Observation is not a NumPy array:UserWarning",
    "ignore:Observation space for each agent probably should be:UserWarning",
)


@pytest.mark.parametrize("kwargs", CASES)
def test_parallel_api(kwargs: dict[str, Any]) -> None:
    env = frontier_marl.parallel_env(**kwargs)
    parallel_api_test(env, num_cycles=200)
    assert env.possible_agents == [f"robot_{i}" for i in range(kwargs["n_agents"])]


@pytest.mark.parametrize("kwargs", CASES)
def test_parallel_seed(kwargs: dict[str, Any]) -> None:
    # PettingZoo 1.27's parallel_seed_test stops after one step (``any(terminations)`` tests the
    # dict's keys); tests/test_determinism.py compares whole episodes.
    parallel_seed_test(lambda: frontier_marl.parallel_env(**kwargs), num_cycles=200)


@pytest.mark.parametrize("kwargs", CASES)
def test_aec_api(kwargs: dict[str, Any]) -> None:
    api_test(frontier_marl.env(**kwargs), num_cycles=200)


@pytest.mark.parametrize("kwargs", CASES)
def test_render(kwargs: dict[str, Any], monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib.pyplot as plt

    # The human viewer sleeps 1/fps per frame; the frames themselves are what is tested.
    monkeypatch.setattr(plt, "pause", lambda interval: None)
    calls: list[str | None] = []

    def env_fn(render_mode: str | None = None) -> Any:
        calls.append(render_mode)
        return frontier_marl.env(render_mode=render_mode, **kwargs)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # matplotlib: "non-interactive backend"
        render_test(env_fn)
    assert set(calls) >= {"human", "rgb_array", "ansi"}
    plt.close("all")


@pytest.mark.parametrize("preset", PRESETS)
def test_make_parallel_and_aec_by_id(preset: str) -> None:
    import pettingzoo

    par = pettingzoo.make("parallel", frontier_marl.PETTINGZOO_ID, preset=preset, n_agents=2)
    assert isinstance(par, FrontierParallelEnv)
    assert par.possible_agents == ["robot_0", "robot_1"]
    assert par.config == make_config(preset, n_agents=2)
    variant = pettingzoo.make("parallel", variant_id(preset), n_agents=2)
    assert variant.config == par.config
    aec = pettingzoo.make("aec", frontier_marl.PETTINGZOO_ID, preset=preset, n_agents=2)
    assert isinstance(aec.unwrapped, FrontierParallelEnv)
    aec.reset(seed=0)
    assert aec.agents == ["robot_0", "robot_1"]
    assert aec.agent_selection == "robot_0"


def test_aec_steps_the_team_once_per_cycle() -> None:
    """In the AEC form the world moves only after every robot has chosen."""
    aec = frontier_marl.env(n_agents=3, agent_position=False)
    aec.reset(seed=3)
    par = aec.unwrapped
    assert isinstance(par, FrontierParallelEnv)
    before = par.world.positions.copy()
    for _ in range(2):
        aec.step(0)
        assert (par.world.positions == before).all()
        assert par.mdp.steps == 0
    aec.step(0)
    assert par.mdp.steps == 1


def test_metadata() -> None:
    env = frontier_marl.parallel_env()
    assert env.metadata["name"] == "frontier_explore_v1"
    assert set(env.metadata["render_modes"]) == {"human", "rgb_array", "ansi"}
    assert env.metadata["is_parallelizable"] is True


@pytest.mark.parametrize("kwargs", CASES)
def test_raw_env_is_the_unwrapped_aec_env_and_env_enforces_the_order(
    kwargs: dict[str, Any],
) -> None:
    from pettingzoo.utils.conversions import parallel_to_aec_wrapper
    from pettingzoo.utils.wrappers import BaseWrapper, OrderEnforcingWrapper

    raw = frontier_marl.raw_env(**kwargs)
    assert isinstance(raw, parallel_to_aec_wrapper) and not isinstance(raw, BaseWrapper)
    api_test(raw, num_cycles=50)
    wrapped = frontier_marl.env(**kwargs)
    assert isinstance(wrapped, OrderEnforcingWrapper)
    with pytest.raises(AssertionError, match="reset"):
        wrapped.step(0)  # before reset: the wrapper names what is missing
