"""The envs under the RL libraries users already have, as shipped (the ``clients`` extra:
TorchRL, Tianshou, skrl): construction, the library's own checks, a few hundred steps with 1
and 3 robots of a policy that reads the mask where the library puts it, the masks honoured
(no padding slot chosen while a live one existed: the env's own ``padding`` info). Each test
skips when its library is not installed."""

from __future__ import annotations

import warnings
from typing import Any

import gymnasium
import numpy as np
import pytest

import frontier_marl

STEPS = 300
TEAMS = (1, 3)

pytestmark = pytest.mark.filterwarnings(
    "ignore:PettingZoo in TorchRL is tested:UserWarning",
    "ignore::DeprecationWarning",
)


# ----------------------------------------------------------------------------- TorchRL
@pytest.mark.parametrize("n_agents", TEAMS)
def test_torchrl_pettingzoo_wrapper_rolls_out_masked(n_agents: int) -> None:
    pytest.importorskip("torchrl")
    from torchrl.envs.libs.pettingzoo import PettingZooWrapper
    from torchrl.envs.utils import check_env_specs

    # TorchRL takes the mask from the observation or from the info: here the info's
    env = PettingZooWrapper(frontier_marl.parallel_env(n_agents=n_agents), use_mask=True, seed=0)
    check_env_specs(env)
    rollout = env.rollout(STEPS, break_when_any_done=False)  # random actions, masked
    actions, masks = rollout["robot", "action"], rollout["robot", "action_mask"]
    assert actions.shape == (STEPS, n_agents) and masks.shape == (STEPS, n_agents, 4)
    assert masks.gather(-1, actions.unsqueeze(-1)).all()
    info = rollout["next", "robot", "info"]
    assert not info["padding"].any()
    assert info["slots"].shape == (STEPS, n_agents, 4, 10)
    assert rollout["next", "done"].any()  # episodes ended and were reset
    env.close()


def test_torchrl_gym_env_builds_every_id_and_masks_with_action_mask() -> None:
    pytest.importorskip("torchrl")
    from torchrl.envs import ActionMask, TransformedEnv
    from torchrl.envs.libs.gym import GymEnv
    from torchrl.envs.utils import check_env_specs

    from frontier_marl.envs.registration import VARIANTS

    for env_id in VARIANTS:  # TorchRL passes frameskip= and drops it on the TypeError
        GymEnv(env_id).close()
    env = TransformedEnv(GymEnv(frontier_marl.GYM_ID, action_mask=True), ActionMask())
    check_env_specs(env)
    rollout = env.rollout(STEPS, break_when_any_done=False)
    actions, masks = rollout["action"], rollout["action_mask"]  # one-hot actions
    assert (actions.bool() <= masks.bool()).all() and (actions.sum(-1) == 1).all()
    assert rollout["observation"].shape == (STEPS, 10)  # agent_position and clusters, joined
    env.close()


# ----------------------------------------------------------------------------- Tianshou
def _tianshou_random(masked: bool) -> Any:
    """A Tianshou policy choosing uniformly among the valid slots of a classic observation
    (``masked``) or among all slots, padding included."""
    from tianshou.algorithm.algorithm_base import Policy
    from tianshou.data import Batch

    class Random(Policy):
        def __init__(self, action_space: Any) -> None:
            super().__init__(action_space=action_space)
            self.rng = np.random.default_rng(0)

        def forward(self, batch: Any, state: Any = None, **kwargs: Any) -> Any:
            mask = np.asarray(batch.obs.action_mask) > 0
            scores = self.rng.random(mask.shape)
            return Batch(act=np.where(mask | (not masked), scores, -1).argmax(axis=-1))

    return Random


@pytest.mark.parametrize("n_agents", TEAMS)
def test_tianshou_pettingzoo_env_collects_with_masked_policies(n_agents: int) -> None:
    pytest.importorskip("tianshou")
    from tianshou.algorithm import MultiAgentOffPolicyAlgorithm
    from tianshou.algorithm.random import MARLRandomDiscreteMaskedOffPolicyAlgorithm
    from tianshou.data import Collector, VectorReplayBuffer
    from tianshou.env import DummyVectorEnv, PettingZooEnv

    def make() -> Any:
        return PettingZooEnv(frontier_marl.env(n_agents=n_agents, action_mask=True))

    env = make()
    random = [
        MARLRandomDiscreteMaskedOffPolicyAlgorithm(action_space=env.action_space)
        for _ in env.agents
    ]
    algorithm = MultiAgentOffPolicyAlgorithm(algorithms=random, env=env)
    collector = Collector(algorithm, DummyVectorEnv([make, make]), VectorReplayBuffer(1000, 2))
    collector.reset()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # its statistics of (n, 1) sequences
        stats = collector.collect(n_step=STEPS)
    assert stats.n_collected_steps >= STEPS
    batch = collector.buffer.sample(0)[0]
    masks, actions = batch.obs.mask, batch.act
    assert not masks.all()  # the env's masks, not Tianshou's all-True default
    assert masks[np.arange(len(actions)), actions].all()
    assert not batch.info.padding.any()
    assert batch.info.slots.shape == (len(actions), 4, 10)


@pytest.mark.parametrize("masked", [True, False], ids=["masked", "uniform"])
def test_tianshou_collector_batches_the_gymnasium_env_infos(masked: bool) -> None:
    pytest.importorskip("tianshou")
    from tianshou.data import Collector, VectorReplayBuffer
    from tianshou.env import DummyVectorEnv

    def make() -> Any:
        return gymnasium.make(frontier_marl.GYM_ID, action_mask=True)

    venv = DummyVectorEnv([make, make])
    venv.seed([0, 1])  # unseeded, an episode of random slots may outlast the steps collected
    policy = _tianshou_random(masked)(venv.action_space[0])
    collector = Collector(policy, venv, VectorReplayBuffer(1000, 2))
    collector.reset()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        stats = collector.collect(n_step=STEPS)
    assert stats.n_collected_episodes >= 1
    batch = collector.buffer.sample(0)[0]
    chosen = batch.obs.action_mask[np.arange(len(batch.act)), batch.act]
    assert chosen.all() == masked  # uniform: padding slots chosen, their targets [-1, -1]
    assert batch.info.padding.any() != masked
    assert batch.info.target.shape == (len(batch.act), 2)


# ----------------------------------------------------------------------------- skrl
def _skrl_masked_step(env: Any, observations: dict[str, Any], rng: Any) -> Any:
    import torch
    from skrl.utils.spaces.torch import unflatten_tensorized_space

    actions = {}
    for agent in env.possible_agents:
        obs = unflatten_tensorized_space(env.observation_space(agent), observations[agent])
        actions[agent] = torch.multinomial(obs["action_mask"].float(), 1, generator=rng)
    return env.step(actions)


@pytest.mark.parametrize("n_agents", TEAMS)
def test_skrl_pettingzoo_wrapper_steps_masked(n_agents: int) -> None:
    pytest.importorskip("skrl")
    import torch
    from skrl.envs.wrappers.torch import wrap_env

    parallel = frontier_marl.parallel_env(n_agents=n_agents, action_mask=True)
    parallel.reset(seed=0)  # skrl resets unseeded: later episodes follow from this seed
    env = wrap_env(parallel, "pettingzoo")
    rng = torch.Generator().manual_seed(0)
    observations, _ = env.reset()
    assert observations["robot_0"].shape == (1, 14)  # skrl flattens: the mask, the observation
    episodes = 0
    for _ in range(STEPS):
        observations, rewards, terminated, truncated, infos = _skrl_masked_step(
            env, observations, rng
        )
        assert rewards["robot_0"].shape == (1, 1)
        assert not any(info["padding"] for info in infos.values())
        if any(bool(t | u) for t, u in zip(terminated.values(), truncated.values(), strict=True)):
            observations, _ = env.reset()
            episodes += 1
    assert episodes >= 1
    env.close()


def test_skrl_gymnasium_wrapper_steps() -> None:
    pytest.importorskip("skrl")
    import torch
    from skrl.envs.wrappers.torch import wrap_env

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        env = wrap_env(gymnasium.make(frontier_marl.GYM_ID, action_mask=True), "gymnasium")
    observation, _ = env.reset()
    assert observation.shape == (1, 14)
    for _ in range(STEPS):
        mask = observation[:, :4]  # the flattened mask comes first (sorted keys)
        observation, _, terminated, truncated, info = env.step(torch.multinomial(mask, 1))
        assert not info["padding"]
        if bool(terminated | truncated):
            observation, _ = env.reset()
    env.close()
