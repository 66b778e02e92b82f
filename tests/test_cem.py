"""The cross-entropy method on a linear slot scorer: its settings, its batched rollouts (the
same episodes as the single env), the linear scorer, and `frontier-marl train` end to end."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from frontier_marl import FrontierParallelEnv, reason_name
from frontier_marl.cli.main import main
from frontier_marl.experiments.explorer_studies import (
    ablation,
    near_probe,
    selection,
    tour_sweep,
    true_gain_probe,
    weight_sensitivity,
)
from frontier_marl.policies.linear_scorer import feature_names
from frontier_marl.training.cem import linear_model, play_t99, relative_t99, save_hand_set
from frontier_marl.training.experiment import load_experiment
from frontier_marl.training.settings import CEMSettings

#: The DQN-trained slot scorer of the explorer studies (in the repository, not the wheel)
EXPLORER_DQN = Path(__file__).resolve().parents[1] / "training" / "models" / "explorer-dqn"

CEM_OVERRIDES = [
    "train.algorithm=cem",
    "train.families=['random-20', 'rooms-32']",
    "env.tour=true",
    "env.turn=true",
    "env.unknown_near=true",
    "env.fill=true",
]


def _config():  # noqa: ANN202
    return load_experiment("explorer-dqn", CEM_OVERRIDES).env_configs()


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"elite": 5, "population": 4}, "must not exceed cem.population"),
        ({"generations": 0}, "cem.generations"),
        ({"sigma": 0}, "cem.sigma"),
        ({"init": {"tour": -1.0}}, "'path'"),
        ({"init": {"path": 1.0}}, "cem.init.path must be < 0"),
    ],
)
def test_bad_cem_settings_are_refused_by_name(settings: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        CEMSettings(**settings)


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (["cem.populaton=3"], "unknown \\[cem\\] key"),
        (["cem.init={path=-1.0, bogus=1.0}"], "unknown feature"),
        (["train.families=[]"], "needs train.families and one robot"),
    ],
)
def test_bad_cem_experiments_are_refused_by_name(overrides: list[str], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        experiment = load_experiment("explorer-dqn", [*CEM_OVERRIDES, *overrides])
        from frontier_marl.training.cem import initial_weights

        initial_weights(CEMSettings(**experiment.cem), feature_names(experiment.env_config()))


def _single_env_t99(cfg, seed: int, weights: np.ndarray) -> int | None:  # noqa: ANN001
    """T99 of one episode on the ParallelEnv, the robot taking the best-scoring valid slot
    at every step (forced steps included)."""
    env = FrontierParallelEnv(config=cfg, info="minimal")
    observations, _ = env.reset(seed=seed)
    while True:
        obs = observations["robot_0"]
        scores = np.where(
            obs["action_mask"] > 0, obs["observation"].astype(np.float64) @ weights, -np.inf
        )
        observations, _, terminated, truncated, infos = env.step({"robot_0": int(scores.argmax())})
        if terminated["robot_0"] or truncated["robot_0"]:
            info = infos["robot_0"]
            reached = reason_name(info["end_reason"]) == "threshold"
            return int(info["travelled"]) if reached else None


def test_batched_rollouts_play_the_single_env_episodes() -> None:
    cfg = _config()[1]  # rooms-32
    names = feature_names(cfg)
    weights = np.zeros(len(names))
    weights[names.index("path")], weights[names.index("tour")] = -1.0, -0.5
    weights[names.index("turn")], weights[names.index("unknown_near")] = -0.05, -0.5
    weights[names.index("size")], weights[names.index("fill")] = 0.8, -0.4
    seeds = [3, 17, 29]
    t99, decisions = play_t99(cfg, seeds, weights)
    expected = [_single_env_t99(cfg, seed, weights) for seed in seeds]
    assert [None if np.isnan(t) else int(t) for t in t99] == expected
    assert decisions > 0


def test_relative_t99_counts_a_missed_episode_as_a_failure() -> None:
    t99 = np.array([90.0, np.nan, 120.0])
    reference = np.array([100.0, 100.0, np.nan])
    assert relative_t99(t99, reference).tolist() == pytest.approx([-0.1, 1.0, 1.0])


def test_the_linear_model_scores_slots_by_their_features() -> None:
    cfg = _config()[0]
    weights = np.linspace(-1.0, 1.0, len(feature_names(cfg)))
    model = linear_model(cfg, weights)
    env = FrontierParallelEnv(config=cfg, obs_layout="flat")  # the layout SB3 models take
    obs = env.reset(seed=5)[0]["robot_0"]
    q_values = model.q_net(model.policy.obs_to_tensor(obs)[0])[0]
    valid = obs["action_mask"] > 0
    expected = torch.as_tensor(obs["slots"][valid] @ weights.astype(np.float32))
    assert torch.allclose(q_values[torch.as_tensor(valid)], expected, atol=1e-5)
    assert (q_values[torch.as_tensor(~valid)] <= -1e8).all()


@pytest.mark.slow
def test_train_with_cem_writes_a_model_the_benchmark_runs(tmp_path: Path) -> None:
    run_dir = tmp_path / "cem"
    tiny = ["cem.generations=2", "cem.population=3", "cem.elite=2", "cem.episodes=1"]
    tiny += ["train.validation_episodes=1"]
    argv = ["train", "explorer-cem", "--out", str(run_dir), "--no-progress"]
    assert main([*argv, *(arg for s in tiny for arg in ("--set", s))]) == 0
    records = [json.loads(line) for line in (run_dir / "cem.jsonl").read_text().splitlines()]
    assert [r["generation"] for r in records] == [0, 1]
    assert records[0]["weights"]["path"] == records[1]["weights"]["path"] == -1.0
    assert (run_dir / "best" / "model.zip").is_file()
    assert (run_dir / "validation_t99.png").is_file()
    meta = json.loads((run_dir / "model.json").read_text())
    assert meta["trained_by"] == "cem" and meta["weights"] == records[1]["weights"]
    out = tmp_path / "bench.json"
    argv = ["benchmark", "--families", "random-20", "--policies", f"nearest-path,{run_dir}"]
    assert main([*argv, "--episodes", "1", "--split", "validation", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert rows[1]["success"] == 1.0


@pytest.mark.slow
def test_the_ablation_script_scores_every_part_on_validation_episodes(tmp_path: Path) -> None:
    out = tmp_path / "ablation.json"
    argv = ["--episodes", "1", "--out", str(tmp_path / "models"), "--json", str(out)]
    assert main(ablation.benchmark_command([*argv, "--no-progress"], EXPLORER_DQN)) == 0
    rows = json.loads(out.read_text())["rows"]
    policies = {row["policy"] for row in rows}
    expected = {"nearest-path", "path-only", "tour-rule", "near-rule", "fill-rule", "explorer-dqn"}
    assert policies == expected | {"frontier-rule"}
    assert all(row["seeds"][0] == 800_000 for row in rows)
    tour_rule = json.loads((tmp_path / "models" / "tour-rule" / "model.json").read_text())
    assert tour_rule["weights"]["tour"] == -0.5 and tour_rule["weights"]["path"] == -1.0


@pytest.mark.slow
def test_the_selection_script_uses_validation_seeds_no_training_run_used(tmp_path: Path) -> None:
    out = tmp_path / "selection.json"
    argv = ["--episodes", "1", "--heuristics", "nearest-path,cost-utility", "--json", str(out)]
    assert selection.main([*argv, "--no-progress"]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert {row["policy"] for row in rows} == {"nearest-path", "cost-utility", "frontier-rule"}
    assert all(row["seeds"] == [800_100] for row in rows)
    for bad in (["--first", "900000"], ["--heuristics", ""]):  # a held-out seed; no heuristic
        with pytest.raises(SystemExit):
            selection.main(bad)


@pytest.mark.slow
def test_the_tour_sweep_scores_hand_set_rules_on_training_seeds(tmp_path: Path) -> None:
    out = tmp_path / "sweep.json"
    argv = ["--weights=-0.5,-1", "--episodes", "1", "--out", str(tmp_path / "m")]
    assert tour_sweep.main([*argv, "--json", str(out), "--no-progress"]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert {row["policy"] for row in rows} == {"nearest-path", "tour-0.5", "tour-1"}
    assert all(row["seeds"] == [700_000] for row in rows)
    rule = json.loads((tmp_path / "m" / "tour-1" / "model.json").read_text())
    assert rule["weights"]["tour"] == -1.0 and rule["trained_by"] == "hand-set"
    for bad in (["--first", "800000"], ["--weights", "a,b"]):
        with pytest.raises(SystemExit):
            tour_sweep.main(bad)


def test_hand_set_weights_must_name_features(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="unknown feature"):
        save_hand_set({"path": -1.0, "tuor": -0.5}, tmp_path, load_experiment("explorer-cem"))


@pytest.mark.slow
def test_the_near_probe_scores_what_the_env_feature_would(tmp_path: Path) -> None:
    from frontier_marl.policies.linear_scorer import weight_vector
    from frontier_marl.sim.features import NEAR
    from frontier_marl.training.cem import play_scorer

    cfg = load_experiment("explorer-cem", ["env.unknown_near=false"]).env_configs()[2]  # rooms-32
    seeds = [5, 6, 7]
    t99, _ = play_scorer(cfg, seeds, near_probe.scorer(feature_names(cfg), NEAR, -0.5))
    featured = load_experiment("explorer-cem", ["env.unknown_near=true"]).env_configs()[2]
    rule = {"path": -1.0, "tour": -0.5, "unknown_near": -0.5}
    expected, _ = play_t99(featured, seeds, weight_vector(rule, feature_names(featured), "rule"))
    assert np.array_equal(t99, expected, equal_nan=True)
    out = tmp_path / "probe.json"
    argv = ["--radii", "8", "--weights=-0.4", "--episodes", "1", "--json", str(out)]
    assert near_probe.main(argv) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [row["family"] for row in rows] == [
        "random-20", "random-30", "rooms-32", "rooms-64", "rooms-96-fine", "floorplan-96"
    ]  # fmt: skip
    assert all(set(row) == {"family", "rule", "R8 W-0.4"} for row in rows)
    for bad in (["--first", "800000"], ["--radii", "a"]):
        with pytest.raises(SystemExit):
            near_probe.main(bad)


@pytest.mark.slow
def test_the_weight_sensitivity_scales_the_named_weights_on_training_seeds(tmp_path: Path) -> None:
    names = ["path", "size", "tour", "unknown_near"]
    weights = np.array([-1.0, 0.8, -0.5, -0.4])
    scaled = weight_sensitivity.scaled
    assert scaled(weights, names, "lengths", 2.0).tolist() == [-2.0, 0.8, -1.0, -0.4]
    assert scaled(weights, names, "size", 0.5).tolist() == [-1.0, 0.4, -0.5, -0.4]
    out = tmp_path / "sensitivity.json"
    argv = ["--directions", "tour:1,lengths:3", "--seed-sets", "730000,731000", "--episodes", "2"]
    assert weight_sensitivity.main([*argv, "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert len(rows) == 6 * 2 * 2  # families x seed sets x directions
    unchanged = [row for row in rows if row["direction"] == "tour:1"]
    assert all(row["change"] == 0.0 for row in unchanged)  # the same weights, the same episodes
    assert {row["first_seed"] for row in rows} == {730000, 731000}
    bad_inputs = (
        ["--seed-sets", "800000"],  # a validation seed
        ["--seed-sets", "730000,730001", "--episodes", "2"],  # overlapping sets
        ["--directions", "tuor:2"],
        ["--directions", "tour"],
        ["--episodes", "1"],
    )
    for bad in bad_inputs:
        with pytest.raises(SystemExit):
            weight_sensitivity.main(bad)


@pytest.mark.slow
def test_the_true_gain_probe_reveals_no_more_than_the_belief_leaves_unknown(tmp_path: Path) -> None:
    from frontier_marl.training.cem import play_scorer

    cfg = load_experiment("explorer-cem").env_configs()[2]  # rooms-32
    checked = []

    def score(observations: dict, env) -> np.ndarray:
        true = true_gain_probe.disc_gains(env, "true")
        belief = true_gain_probe.disc_gains(env, "belief")
        valid = observations["action_mask"].astype(bool)
        assert np.all(true[~valid] == 0) and np.all(belief[~valid] == 0)
        assert np.all((true >= 0) & (true <= belief + 1e-12) & (belief <= 1))
        checked.append(true[valid].sum())
        return -observations["slots"][..., 0].astype(np.float64)  # nearest-path

    play_scorer(cfg, [3, 4, 5], score)
    assert len(checked) > 10 and sum(checked) > 0  # decisions with something to reveal
    out = tmp_path / "probe.json"
    argv = ["--weights=0,0.1", "--kinds", "true", "--episodes", "2", "--json", str(out)]
    assert true_gain_probe.main(argv) == 0
    rows = json.loads(out.read_text())["rows"]
    assert len(rows) == 6 * 2  # families x weights
    assert all(row["change"] == 0.0 for row in rows if row["weight"] == 0)
    for bad in (
        ["--first", "900000"],
        ["--kinds", "oracle"],
        ["--weights", "a"],
        ["--episodes", "1"],
    ):
        with pytest.raises(SystemExit):
            true_gain_probe.main(bad)


def test_paired_change_is_the_mean_relative_t99_and_its_standard_error() -> None:
    from frontier_marl.training.cem import changes_text, paired_change

    change = paired_change(np.array([110.0, 90.0]), np.array([100.0, 100.0]))
    assert change["change"] == pytest.approx(0.0) and change["stderr"] == pytest.approx(0.1)
    assert changes_text({"a": change}) == "a +0.00±10.00"
