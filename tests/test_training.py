"""The DQN training pipeline: vector env, seeding, truncation, runs, resume, configs.

Budgets are tiny (a few thousand steps on a 10 x 10 map); nothing here checks learning quality.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("supersuit")

from frontier_marl.training.experiment import (  # noqa: E402
    THESIS_DQN,
    experiment_from_dict,
    load_experiment,
    parse_override,
)
from frontier_marl.training.vec_env import (  # noqa: E402
    END_REASON_KEY,
    TRUNCATED_KEY,
    make_parallel_env,
    make_vec_env,
    parallel_envs,
)
from tests.helpers import silent  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
SMALL = {"height": 10, "width": 10, "perception_range": 2}


def tiny_experiment(name: str = "tiny", **train: object) -> object:
    settings = {
        "total_timesteps": 1200,
        "checkpoint_every": 500,
        "eval_episodes": 2,
        "log_interval": 2,
        **train,
    }
    return experiment_from_dict(
        {
            "name": name,
            "env": {"preset": "thesis-20x20", **SMALL},
            "dqn": {"learning_starts": 100},
            "train": settings,
        }
    )


def _positions(vec: object, steps: int, actions: np.ndarray) -> np.ndarray:
    """Agent positions of every copy over ``steps`` steps of fixed actions."""
    obs = vec.reset()
    out = [obs["agent_position"].copy()]
    for _ in range(steps):
        obs, _rewards, _dones, _infos = vec.step(actions)
        out.append(obs["agent_position"].copy())
    return np.stack(out, axis=1)  # (copies, steps + 1, 2)


# --------------------------------------------------------------------------- vector env


def test_vector_copies_play_distinct_and_reproducible_episodes() -> None:
    actions = np.array([0, 0, 0])  # same actions: only the episodes can differ
    first = make_vec_env(dict(SMALL), n_envs=3, seed=7)
    assert first.num_envs == 3
    runs = _positions(first, 40, actions)
    envs = parallel_envs(first)
    assert len({id(env.unwrapped) for env in envs}) == 3
    for i in range(3):
        for j in range(i + 1, 3):
            assert not np.array_equal(runs[i], runs[j]), f"copies {i} and {j} replay one episode"
    again = _positions(make_vec_env(dict(SMALL), n_envs=3, seed=7), 40, actions)
    np.testing.assert_array_equal(runs, again)
    other = _positions(make_vec_env(dict(SMALL), n_envs=3, seed=8), 40, actions)
    assert not np.array_equal(runs, other)


def test_clones_without_distinct_seeds_would_replay_the_same_episode() -> None:
    """The trap the seeding avoids: an env seeded before SuperSuit clones it."""
    import supersuit as ss

    par = make_parallel_env(dict(SMALL))
    par.reset(seed=3)
    vec = ss.concat_vec_envs_v1(
        ss.pettingzoo_env_to_vec_env_v1(par), 2, num_cpus=0, base_class="stable_baselines3"
    )
    runs = _positions(vec, 20, np.array([0, 0]))
    np.testing.assert_array_equal(runs[0], runs[1])


def test_truncation_sets_timelimit_key_and_termination_does_not() -> None:
    env = make_parallel_env({**SMALL, "max_steps": 3, "explore_threshold": 1.0})
    env.reset(seed=0)
    for _ in range(3):
        _obs, _rew, term, trunc, infos = env.step({"robot_0": 0})
    assert trunc["robot_0"] and not term["robot_0"]
    assert infos["robot_0"][TRUNCATED_KEY] is True
    assert infos["robot_0"][END_REASON_KEY] == "step_limit"

    env = make_parallel_env({**SMALL, "explore_threshold": 0.05})
    env.reset(seed=0)
    _obs, _rew, term, trunc, infos = env.step({"robot_0": 0})
    assert term["robot_0"]
    assert TRUNCATED_KEY not in infos["robot_0"]
    assert infos["robot_0"][END_REASON_KEY] == "threshold"


def test_end_of_episode_keys_survive_the_vector_wrappers() -> None:
    vec = make_vec_env({**SMALL, "max_steps": 3, "explore_threshold": 1.0}, seed=0)
    vec.reset()
    for _ in range(3):
        _obs, _rewards, dones, infos = vec.step(np.array([0]))
    assert dones[0]
    assert infos[0][TRUNCATED_KEY] is True
    assert infos[0][END_REASON_KEY] == "step_limit"
    assert infos[0]["episode"]["l"] == 3  # VecMonitor's episode statistics
    assert "terminal_observation" in infos[0]


def _collect(env_kwargs: dict, steps: int, bootstrap_truncations: bool = True) -> object:
    """A DQN that only collects ``steps`` transitions (no gradient step)."""
    from stable_baselines3 import DQN

    vec = make_vec_env(env_kwargs, seed=0, bootstrap_truncations=bootstrap_truncations)
    model = DQN("MultiInputPolicy", vec, learning_starts=10**9, buffer_size=1000, device="cpu")
    silent(model).learn(steps)
    return model


def test_truncated_transitions_are_bootstrapped_in_the_replay_buffer() -> None:
    model = _collect({**SMALL, "max_steps": 3, "explore_threshold": 1.0}, 60)
    buffer = model.replay_buffer
    n = buffer.size()
    dones = buffer.dones[:n, 0]
    assert dones.sum() >= 15  # every episode ends after 3 steps
    np.testing.assert_array_equal(buffer.timeouts[:n, 0], dones)  # every end is a truncation
    batch = buffer._get_samples(np.arange(n))
    # the TD target's done flag is 0 for a truncation: the next value is bootstrapped
    assert float(batch.dones.sum()) == 0.0


def test_truncations_are_terminal_when_bootstrapping_is_off() -> None:
    model = _collect({**SMALL, "max_steps": 3, "explore_threshold": 1.0}, 60, False)
    buffer = model.replay_buffer
    n = buffer.size()
    dones = buffer.dones[:n, 0]
    assert dones.sum() >= 15
    assert buffer.timeouts[:n, 0].sum() == 0  # SuperSuit's own behaviour: no timeout marks
    batch = buffer._get_samples(np.arange(n))
    assert float(batch.dones.sum()) == dones.sum()  # the TD target stops at every truncation


def test_terminated_transitions_are_not_bootstrapped() -> None:
    model = _collect({**SMALL, "explore_threshold": 0.05}, 30)
    buffer = model.replay_buffer
    n = buffer.size()
    dones = buffer.dones[:n, 0]
    assert dones.sum() == n  # the first step reaches the tiny threshold
    assert buffer.timeouts[:n, 0].sum() == 0
    batch = buffer._get_samples(np.arange(n))
    assert float(batch.dones.sum()) == n


# --------------------------------------------------------------------------- experiment configs

#: The thesis's experiment grid: config -> (centroid, agent position, info gain, sorted, preset)
THESIS_GRID = {
    1: ("absolute", True, False, False, 20),
    2: ("absolute", True, True, True, 20),
    3: ("absolute", True, True, False, 20),
    4: ("relative", False, False, True, 20),
    5: ("relative", False, False, False, 20),
    6: ("relative", True, False, True, 20),
    7: ("relative", True, False, False, 20),
    8: ("relative", True, True, True, 20),
    9: ("relative", True, True, False, 20),
    10: ("none", False, True, True, 20),
    11: ("none", False, True, False, 20),
    12: ("absolute", True, False, False, 30),
}


@pytest.mark.parametrize("number", sorted(THESIS_GRID))
def test_thesis_config_files(number: int) -> None:
    experiment = load_experiment(f"config{number:02d}")
    cfg = experiment.env_config()
    centroid, position, gain, sort, size = THESIS_GRID[number]
    obs = cfg.observation
    assert (obs.centroid, obs.agent_position, obs.info_gain, obs.sort_by_distance) == (
        centroid,
        position,
        gain,
        sort,
    )
    assert cfg.height == cfg.width == size
    assert cfg.perception_range == (3 if size == 20 else 5)
    for key, value in THESIS_DQN.items():
        assert experiment.dqn[key] == value
    assert experiment.train.total_timesteps == 1_000_000
    assert experiment.train.n_envs == 1
    assert experiment.train.eval_episodes == 30
    if number in (1, 12):
        assert cfg.reward.kind == "reward2"
    if number == 4:
        assert cfg.reward.kind == "reward1"


def test_config_by_name_and_overrides() -> None:
    experiment = load_experiment(
        "config04",
        ["env.reward=reward2", "dqn.learning_rate=1e-4", "n_envs=2", "sort_by_distance=false"],
    )
    assert experiment.name == "config04"
    assert experiment.env_config().reward.kind == "reward2"
    assert experiment.env_config().observation.sort_by_distance is False
    assert experiment.dqn["learning_rate"] == pytest.approx(1e-4)
    assert experiment.train.n_envs == 2
    assert parse_override("dqn.policy_kwargs={net_arch=[32, 32]}") == (
        "dqn",
        "policy_kwargs",
        {"net_arch": [32, 32]},
    )
    assert parse_override("env.cells_per_step=full") == ("env", "cells_per_step", "full")


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("env.centroid=polar", "centroid"),
        ("dqn.learning_rat=1e-4", "learning_rat"),
        ("dqn.seed=3", "seed"),
        ("train.n_envs=0", "n_envs"),
        ("train.bootstrap_truncations=1", "bootstrap_truncations"),
        ("train.skip_forced_steps=1", "skip_forced_steps"),
        ("dqn.train_freq=-1", "train_freq"),
        ("exploration_fraction=1.5", "exploration_fraction"),
        ("dqn.learning_rate=0", "learning_rate"),
        ("bogus=1", "bogus"),
        ("model.x=1", "section"),
        ("no_equals_sign", "key=value"),
    ],
)
def test_bad_overrides_name_the_problem(override: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        load_experiment("config01", [override])


def test_skipping_forced_steps_needs_the_batched_env() -> None:
    overrides = ["train.skip_forced_steps=true", "train.vec_env=supersuit"]
    with pytest.raises(ValueError, match="skip_forced_steps needs train.vec_env"):
        load_experiment("config01", overrides)


# --------------------------------------------------------------------------- training runs


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    from frontier_marl.training.train import train

    run_dir = tmp_path_factory.mktemp("runs") / "tiny"
    result = train(tiny_experiment(), run_dir, progress_bar=False)
    return run_dir, result


def test_run_produces_model_logs_checkpoints_and_evaluation(finished_run: tuple) -> None:
    run_dir, result = finished_run
    assert result.num_timesteps == 1200 and not result.interrupted
    for name in (
        "model.zip",
        "model.json",
        "evaluation.json",
        "actions.png",
        "learning_curve.png",
        "metrics.jsonl",
        "run.json",
    ):
        assert (run_dir / name).is_file(), name
    meta = json.loads((run_dir / "model.json").read_text())
    assert meta["observation_layout"]["centroid"] == "absolute"
    assert meta["env_config"]["height"] == 10
    assert meta["policy"] == "MultiInputPolicy"
    assert meta["num_timesteps"] == 1200
    evaluation = json.loads((run_dir / "evaluation.json").read_text())
    assert [row["policy"] for row in evaluation["rows"]] == ["tiny", "greedy-distance"]
    assert evaluation["model"]["episodes"] == 2
    assert evaluation["model"]["seeds"] == evaluation["heuristics"][0]["seeds"] == [0, 1]
    assert "degenerate" in evaluation["model"]["degeneracy"]
    assert len(evaluation["model"]["action_shares"]) == 4
    steps = sorted(int(p.name.removeprefix("step_")) for p in (run_dir / "checkpoints").iterdir())
    assert steps == [1000, 1200]  # newest two kept (500 was removed)
    assert (run_dir / "checkpoints" / "step_000001200" / "replay_buffer.pkl").is_file()


def test_tensorboard_has_reward_loss_and_epsilon(finished_run: tuple) -> None:
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    run_dir, _ = finished_run
    events = list((run_dir / "tb").glob("events.out.tfevents.*"))
    assert events
    acc = EventAccumulator(str(run_dir / "tb"))
    acc.Reload()
    tags = set(acc.Tags()["scalars"])
    assert {"rollout/ep_rew_mean", "train/loss", "rollout/exploration_rate"} <= tags


def test_training_is_reproducible_for_a_seed(tmp_path: Path) -> None:
    import torch
    from stable_baselines3 import DQN

    from frontier_marl.training.train import train

    params = []
    for name in ("a", "b", "c"):
        seed = 5 if name != "c" else 6
        result = train(
            tiny_experiment(total_timesteps=400, checkpoint_every=0, eval_episodes=0, seed=seed),
            tmp_path / name,
            progress_bar=False,
        )
        model = DQN.load(result.model_path, device="cpu")
        params.append(torch.cat([p.flatten() for p in model.policy.parameters()]))
    assert torch.equal(params[0], params[1])
    assert not torch.equal(params[0], params[2])


def test_resume_continues_step_count_and_replay_buffer(tmp_path: Path) -> None:
    from stable_baselines3.common.callbacks import BaseCallback

    from frontier_marl.policies.model_files import find_checkpoint
    from frontier_marl.training.train import resume_experiment, train

    class InterruptAt(BaseCallback):
        def __init__(self, step: int) -> None:
            super().__init__()
            self.step = step

        def _on_step(self) -> bool:
            if self.model.num_timesteps >= self.step:
                raise KeyboardInterrupt
            return True

    run_dir = tmp_path / "run"
    experiment = tiny_experiment(total_timesteps=1000, eval_episodes=0)
    first = train(experiment, run_dir, progress_bar=False, callbacks=[InterruptAt(700)])
    assert first.interrupted and first.evaluation is None
    checkpoint = find_checkpoint(run_dir)
    assert checkpoint.step == 700 and checkpoint.replay_buffer.is_file()
    assert not (run_dir / "evaluation.json").exists()

    with pytest.raises(ValueError, match="already holds a run"):
        train(experiment, run_dir, progress_bar=False)

    resumed = train(
        resume_experiment(checkpoint, {"total_timesteps": 1000}),
        run_dir,
        resume=checkpoint,
        progress_bar=False,
    )
    assert not resumed.interrupted
    assert resumed.num_timesteps == 1000
    assert resumed.steps_this_session == 300
    from stable_baselines3 import DQN

    model = DQN.load(resumed.model_path, device="cpu")
    assert model.num_timesteps == 1000
    assert model._n_updates > (700 - 100) // 4  # updates of the first session were kept
    final = find_checkpoint(run_dir)
    model.load_replay_buffer(final.replay_buffer)
    assert model.replay_buffer.size() >= 990  # both sessions' transitions
    sessions = json.loads((run_dir / "run.json").read_text())["sessions"]
    assert [(s["start_step"], s["end_step"]) for s in sessions] == [(0, 700), (700, 1000)]
    assert sessions[0]["interrupted"] and not sessions[1]["interrupted"]
    steps = [row["step"] for row in _metrics(run_dir)]
    assert steps == sorted(steps) and steps[-1] <= 1000


def _metrics(run_dir: Path) -> list[dict]:
    from frontier_marl.training.callbacks import read_metrics

    return read_metrics(run_dir / "metrics.jsonl")


def test_resume_refuses_env_or_seed_changes(finished_run: tuple) -> None:
    from frontier_marl.policies.model_files import find_checkpoint
    from frontier_marl.training.train import resume_experiment

    run_dir, _ = finished_run
    checkpoint = find_checkpoint(run_dir)
    with pytest.raises(ValueError, match="n_envs"):
        resume_experiment(checkpoint, {"n_envs": 2})
    assert resume_experiment(checkpoint, {"total_timesteps": 5000}).train.total_timesteps == 5000


# --------------------------------------------------------------------------- model vs env


def test_mismatched_layout_gives_a_named_error(finished_run: tuple) -> None:
    from frontier_marl.config import make_config
    from frontier_marl.evaluation.model_evaluation import evaluate_model
    from frontier_marl.policies.metadata import ModelEnvMismatchError
    from frontier_marl.policies.models import load_model

    run_dir, _ = finished_run
    loaded = load_model(run_dir)
    same_shape = loaded.env_config(sort_by_distance=True)  # same spaces, other meaning
    with pytest.raises(ModelEnvMismatchError, match="sort_by_distance"):
        evaluate_model(loaded, same_shape, episodes=1)
    other_shape = loaded.env_config(info_gain=True)
    with pytest.raises(ModelEnvMismatchError, match="observation space") as err:
        evaluate_model(loaded, other_shape, episodes=1)
    assert "info_gain" in str(err.value)
    flat = make_config(**SMALL, agent_position=False)  # a Box instead of a Dict
    loaded.metadata = None  # a bare SB3 file: only the spaces can be compared
    with pytest.raises(ModelEnvMismatchError, match="observation space"):
        evaluate_model(loaded, flat, episodes=1)


def test_degeneracy_flag() -> None:
    from frontier_marl.evaluation.model_evaluation import degeneracy

    assert degeneracy([0.95, 0.05, 0.0, 0.0])["degenerate"] is True
    assert degeneracy([0.95, 0.05, 0.0, 0.0])["dominant_action"] == 0
    assert degeneracy([0.9, 0.1, 0.0, 0.0])["degenerate"] is False  # "more than 90 %"
    assert degeneracy([0.506, 0.254, 0.212, 0.028])["degenerate"] is False


def test_flat_observations_use_mlp_policy(tmp_path: Path) -> None:
    from frontier_marl.training.train import train

    experiment = experiment_from_dict(
        {
            "name": "flat",
            "env": {
                **SMALL,
                "centroid": "relative",
                "agent_position": False,
                "sort_by_distance": True,
                "reward": "reward1",
            },
            "dqn": {"learning_starts": 50},
            "train": {
                "total_timesteps": 300,
                "checkpoint_every": 0,
                "eval_episodes": 1,
                "n_envs": 2,
            },
        }
    )
    result = train(experiment, tmp_path / "flat", progress_bar=False)
    meta = json.loads((tmp_path / "flat" / "model.json").read_text())
    assert meta["policy"] == "MlpPolicy"
    assert meta["observation_space"]["type"] == "Box"
    assert result.num_timesteps >= 300
    assert result.evaluation["model"]["episodes"] == 1
