"""The slot scorer as an actor-critic policy: PPO and MaskablePPO on the explorer observation,
through the training pipeline, the model loader and the benchmark."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch
from sb3_contrib import MaskablePPO
from stable_baselines3 import PPO

from frontier_marl.cli.main import main
from frontier_marl.config import make_config
from frontier_marl.policies.base import ModelPolicy
from frontier_marl.policies.models import load_model, loader
from frontier_marl.policies.networks.slot_actor_critic import (
    MaskableSlotActorCriticPolicy,
    SlotActorCriticPolicy,
)
from frontier_marl.training.batched_vec_env import make_batched_vec_env
from frontier_marl.training.experiment import experiment_from_dict, parse_override
from tests.helpers import silent

#: The MaskablePPO research model of the explorer studies (in the repository, not the wheel)
EXPLORER_PPO = Path(__file__).resolve().parents[1] / "training" / "models" / "explorer-ppo"
EXPLORER_DQN = EXPLORER_PPO.parent / "explorer-dqn"

EXPLORER = {"features": "explorer", "n_slots": 6, "gain": "unknown", "reward": "travel"}
CLASSES = [(PPO, SlotActorCriticPolicy), (MaskablePPO, MaskableSlotActorCriticPolicy)]


def _model(algorithm, policy, scorer: str = "mlp", n_envs: int = 2):  # noqa: ANN001, ANN202
    torch.set_num_threads(1)
    cfg = make_config("thesis-20x20", **EXPLORER)
    env = make_batched_vec_env({"config": cfg}, n_envs, seed=0)
    model = algorithm(
        policy, env, n_steps=16, batch_size=16, n_epochs=1, policy_kwargs={"scorer": scorer}
    )
    return model, env


@pytest.mark.parametrize(("algorithm", "policy"), CLASSES)
@pytest.mark.parametrize("scorer", ["mlp", "linear"])
def test_actor_is_permutation_equivariant_masked_and_the_critic_invariant(
    algorithm,
    policy,
    scorer: str,  # noqa: ANN001
) -> None:
    model, env = _model(algorithm, policy, scorer)
    observation = env.reset()
    observation["action_mask"][:, :2] = 1  # at least two live slots to tell apart
    order = np.random.default_rng(0).permutation(observation["slots"].shape[1])
    shuffled = {key: value[:, order] for key, value in observation.items()}
    tensor, shuffled_tensor = (model.policy.obs_to_tensor(o)[0] for o in (observation, shuffled))
    probs = model.policy.get_distribution(tensor).distribution.probs
    probs_shuffled = model.policy.get_distribution(shuffled_tensor).distribution.probs
    assert torch.allclose(probs[:, order], probs_shuffled, atol=1e-6)
    masked = torch.as_tensor(observation["action_mask"] == 0)
    assert (probs[masked] == 0).all() and (probs[~masked] > 0).all()
    values = model.policy.predict_values(tensor)
    assert values.shape == (2, 1)
    assert torch.allclose(values, model.policy.predict_values(shuffled_tensor), atol=1e-5)


@pytest.mark.parametrize(("algorithm", "policy"), CLASSES)
def test_ppo_trains_only_on_valid_slots_and_survives_save_and_load(
    algorithm,
    policy,
    tmp_path: Path,  # noqa: ANN001
) -> None:
    model, env = _model(algorithm, policy, "linear")
    before = model.policy.mlp_extractor.actor.weight.detach().clone()
    silent(model).learn(64)
    buffer = model.rollout_buffer
    masks = buffer.observations["action_mask"].reshape(-1, 6)
    taken = buffer.actions.reshape(-1).astype(int)
    assert len(taken) == 32 and masks[np.arange(32), taken].all()
    assert not torch.equal(before, model.policy.mlp_extractor.actor.weight)  # it learned
    model.save(tmp_path / "model.zip")
    loaded = algorithm.load(tmp_path / "model.zip")
    assert type(loaded.policy) is policy and loaded.policy.scorer == "linear"
    observation = env.reset()
    for deterministic in (True, False):
        expected, _ = model.predict(observation, deterministic=True)
        actions, _ = loaded.predict(observation, deterministic=deterministic)
        assert observation["action_mask"][np.arange(len(actions)), actions].all()
    assert np.array_equal(loaded.predict(observation, deterministic=True)[0], expected)


@pytest.mark.parametrize("scorer", ["mlp", "linear"])
def test_a_prior_starts_the_actor_at_the_linear_scorer(scorer: str) -> None:
    cfg = make_config("thesis-20x20", **EXPLORER)
    env = make_batched_vec_env({"config": cfg}, 3, seed=0)
    prior = np.random.default_rng(1).normal(size=env.observation_space["slots"].shape[1])
    kwargs = {"scorer": scorer, "prior": prior.tolist(), "logit_scale": 10}
    prior = prior * 10
    model = MaskablePPO(MaskableSlotActorCriticPolicy, env, n_steps=16, policy_kwargs=kwargs)
    observation = env.reset()
    observation["action_mask"][:, :3] = 1
    scores = np.where(observation["action_mask"], observation["slots"] @ prior, -np.inf)
    expected = np.exp(scores - scores.max(axis=1, keepdims=True))
    expected /= expected.sum(axis=1, keepdims=True)
    tensor = model.policy.obs_to_tensor(observation)[0]
    probs = model.policy.get_distribution(tensor).distribution.probs.detach().numpy()
    assert np.allclose(probs, expected, atol=1e-5)
    assert np.array_equal(model.predict(observation, deterministic=True)[0], scores.argmax(1))


def test_a_prior_by_feature_name_becomes_the_weight_vector() -> None:
    kwargs = {"net_arch": [8], "prior": {"path": -32.0, "tour": -16.0}}
    with_tour = {**EXPLORER, "tour": True}
    experiment = experiment_from_dict(_experiment(ppo={"policy_kwargs": kwargs}, env=with_tour))
    prior = experiment.hyperparameters()["policy_kwargs"]["prior"]
    assert prior[0] == -32.0 and prior[-1] == -16.0 and set(prior[1:-1]) == {0.0}
    assert experiment.to_dict()["ppo"]["policy_kwargs"]["prior"] == kwargs["prior"]
    with pytest.raises(ValueError, match=r"prior names unknown feature\(s\) \['tour'\]"):
        experiment_from_dict(_experiment(ppo={"policy_kwargs": kwargs}, env={**EXPLORER}))


@pytest.mark.parametrize(
    ("policy_kwargs", "message"),
    [
        ({"scorer": "transformer"}, "scorer must be one of"),
        ({"scorer": "linear", "attention_heads": 2}, "attention_heads needs scorer='mlp'"),
        ({"net_arch": {"pi": [64], "vf": [64]}}, "net_arch of the slot actor-critic"),
        ({"ortho_init": True}, "ortho_init=False"),
        ({"prior": [1.0, 2.0]}, "prior has 2 weights; the observation has"),
        ({"logit_scale": 0}, r"logit_scale must be a number in \(0, 1e4\)"),
        ({"logit_scale": "big"}, "logit_scale must be a number in"),
    ],
)
def test_bad_actor_critic_settings_are_refused(policy_kwargs: dict, message: str) -> None:
    cfg = make_config("thesis-20x20", **EXPLORER)
    env = make_batched_vec_env({"config": cfg}, 1, seed=0)
    with pytest.raises(ValueError, match=message):
        PPO(SlotActorCriticPolicy, env, n_steps=16, batch_size=16, policy_kwargs=policy_kwargs)


def test_the_actor_critic_needs_the_explorer_observation() -> None:
    env = make_batched_vec_env({"config": make_config("thesis-20x20")}, 1, seed=0)
    with pytest.raises(ValueError, match="explorer observation"):
        PPO(SlotActorCriticPolicy, env, n_steps=16, batch_size=16)


def test_a_maskable_model_gets_the_envs_mask_in_the_benchmark() -> None:
    class Recorder:
        def __init__(self) -> None:
            self.masks: list = []

        def predict(self, obs, deterministic=True, action_masks=None):  # noqa: ANN001, ANN202
            self.masks.append(action_masks)
            return np.array(int(np.argmax(action_masks))), None

    recorder = Recorder()
    mask = np.array([0, 0, 1, 1], dtype=np.int8)
    assert ModelPolicy(recorder).act({}, {"action_mask": mask}) == 2
    assert recorder.masks[0].dtype == bool and recorder.masks[0].tolist() == [0, 0, 1, 1]


def test_the_loader_follows_the_models_metadata() -> None:
    assert loader("PPO") is PPO and loader("MaskablePPO") is MaskablePPO
    assert loader(None).__name__ == "DQN"  # models saved before PPO
    with pytest.raises(ValueError, match="algorithm 'A3C'"):
        loader("A3C")


def _experiment(**sections: dict) -> dict:
    train = {"algorithm": "ppo", "policy": "slot-scorer", **sections.pop("train", {})}
    return {"name": "t", "env": EXPLORER, "train": train, **sections}


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (_experiment(dqn={"learning_rate": 1e-4}), r"\[dqn\] settings.*not read"),
        (_experiment(train={"algorithm": "dqn"}, ppo={"n_epochs": 2}), r"\[ppo\] settings"),
        (_experiment(ppo={"n_epoch": 2}), r"unknown or reserved \[ppo\] key.*n_epoch"),
        (_experiment(ppo={"seed": 2}), r"unknown or reserved \[ppo\] key.*seed"),
        (_experiment(ppo={"gae_lambda": 1.5}), r"ppo.gae_lambda must be a number in"),
        (_experiment(ppo={"clip_range": 0.0}), "ppo.clip_range must be > 0"),
        (_experiment(ppo={"n_steps": 0}), "ppo.n_steps must be an integer >= 1"),
        (
            _experiment(train={"algorithm": "maskable-ppo", "vec_env": "supersuit"}),
            "'maskable-ppo' needs train.vec_env = 'batched'",
        ),
    ],
)
def test_bad_ppo_experiments_are_refused_by_name(data: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        experiment_from_dict(data)


def test_ppo_overrides_find_their_section() -> None:
    assert parse_override("n_epochs=3") == ("ppo", "n_epochs", 3)
    assert parse_override("ppo.learning_rate=1e-4") == ("ppo", "learning_rate", 1e-4)
    experiment = experiment_from_dict(_experiment(ppo={"n_epochs": 3}))
    assert experiment.hyperparameters() == {"n_epochs": 3}
    saved = experiment.to_dict()
    assert "dqn" not in saved and experiment_from_dict(saved) == experiment


@pytest.mark.slow
def test_train_explorer_ppo_resume_and_benchmark(tmp_path: Path) -> None:
    """The shipped explorer-ppo config trains (tiny budget), resumes, records its algorithm,
    loads as MaskablePPO and runs in the benchmark."""
    run_dir = tmp_path / "ppo"
    small = ["--set", "ppo.n_steps=8", "--set", "ppo.batch_size=20", "--set", "train.n_envs=1"]
    args = ["train", "explorer-ppo", "--steps", "40", "--out", str(run_dir), "--no-progress"]
    assert main([*args, *small]) == 0
    assert json.loads((run_dir / "model.json").read_text())["algorithm"] == "MaskablePPO"
    assert main(["train", "--resume", str(run_dir), "--steps", "80", "--no-progress"]) == 0
    loaded = load_model(run_dir)
    assert isinstance(loaded.model, MaskablePPO) and loaded.model.num_timesteps == 80
    out = tmp_path / "bench.json"
    code = main(
        ["benchmark", "--policies", f"nearest-path,{run_dir}", "--families", "random-20",
         "--episodes", "1", "--split", "validation", "--json", str(out), "--no-progress"]
    )  # fmt: skip
    assert code == 0
    rows = json.loads(out.read_text())["rows"]
    assert [row["success"] for row in rows if row["policy"] == "ppo"] == [1]  # the folder name


def test_the_explorer_ppo_research_model_loads_and_explores(tmp_path: Path) -> None:
    loaded = load_model(EXPLORER_PPO)
    assert isinstance(loaded.model, MaskablePPO)
    assert type(loaded.model.policy) is MaskableSlotActorCriticPolicy
    assert loaded.metadata["experiment"]["train"]["algorithm"] == "maskable-ppo"
    out = tmp_path / "bench.json"
    code = main(
        ["benchmark", "--policies", str(EXPLORER_PPO), "--families", "rooms-32", "--episodes", "2",
         "--split", "validation", "--json", str(out), "--no-progress"]
    )  # fmt: skip
    assert code == 0
    (row,) = json.loads(out.read_text())["rows"]
    assert row["policy"] == "explorer-ppo" and row["success"] == row["episodes"] == 2


@pytest.mark.parametrize("name", [str(EXPLORER_DQN), str(EXPLORER_PPO)])
def test_skipping_forced_steps_leaves_the_slot_scorers_episodes_unchanged(name: str) -> None:
    """A slot scorer is not asked when one slot is valid; it would have taken that slot."""
    from frontier_marl.envs.parallel import FrontierParallelEnv

    loaded = load_model(name)
    cfg = loaded.env_config()
    runs = []
    for skips in (True, False):
        policy = ModelPolicy(loaded.model)
        assert policy.skips_forced  # the slot scorers mask invalid slots themselves
        policy.skips_forced = skips
        env = FrontierParallelEnv(config=cfg)
        observations, infos = env.reset(seed=3)
        actions, choices = [], []
        for _ in range(60):
            agent = env.agents[0]
            choices.append(int(np.count_nonzero(infos[agent]["action_mask"])))
            actions.append(policy.act(observations[agent], infos[agent]))
            observations, _, terminated, truncated, infos = env.step({agent: actions[-1]})
            if terminated[agent] or truncated[agent]:
                break
        runs.append(actions)
    assert runs[0] == runs[1]
    assert 1 in choices and max(choices) > 1  # forced steps and real decisions both played


def test_forced_steps_are_not_asked_of_a_masking_model() -> None:
    class Masking:
        class policy:  # noqa: N801
            masks_invalid_slots = True

        def __init__(self) -> None:
            self.calls = 0

        def predict(self, obs, deterministic=True):  # noqa: ANN001, ANN202
            self.calls += 1
            return np.array(0), None

    model = Masking()
    assert ModelPolicy(model).act({}, {"action_mask": np.array([0, 0, 1, 0])}) == 2
    assert model.calls == 0
    ModelPolicy(model).act({}, {"action_mask": np.array([1, 0, 1, 0])})
    ModelPolicy(model, deterministic=False).act({}, {"action_mask": np.array([0, 0, 1, 0])})
    assert model.calls == 2
