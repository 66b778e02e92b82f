"""``frontier-marl train`` and ``frontier-marl evaluate`` end to end, with tiny budgets."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("supersuit")

from frontier_marl.cli.main import main
from frontier_marl.policies.models import pretrained_model_dir  # noqa: E402

TINY_CONFIG = """
name = "tiny-cli"
description = "a 10 x 10 smoke test"

[env]
preset = "thesis-20x20"
height = 10
width = 10
perception_range = 2
reward = "reward2"

[dqn]
learning_starts = 100

[train]
total_timesteps = 800
checkpoint_every = 400
eval_episodes = 2
log_interval = 2
"""


@pytest.fixture(scope="module")
def trained(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("cli")
    config = root / "tiny.toml"
    config.write_text(TINY_CONFIG)
    run_dir = root / "run"
    code = main(["train", str(config), "--out", str(run_dir), "--seed", "3", "--no-progress"])
    assert code == 0
    return config, run_dir


def test_train_command_writes_run_folder(trained: tuple[Path, Path], capsys) -> None:
    _config, run_dir = trained
    for name in ("model.zip", "model.json", "evaluation.json", "actions.png", "learning_curve.png"):
        assert (run_dir / name).is_file(), name
    assert list((run_dir / "tb").glob("events.out.tfevents.*"))
    meta = json.loads((run_dir / "model.json").read_text())
    assert meta["experiment"]["train"]["seed"] == 3
    assert meta["num_timesteps"] == 800


def test_train_resume_extends_the_run(trained: tuple[Path, Path], tmp_path: Path, capsys) -> None:
    import shutil

    _config, run_dir = trained
    copy = tmp_path / "run"
    shutil.copytree(run_dir, copy)
    code = main(
        [
            "train",
            "--resume",
            str(copy),
            "--steps",
            "1000",
            "--no-progress",
            "--set",
            "train.eval_episodes=1",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "resuming at step 800" in out
    assert "trained 200 steps" in out
    assert json.loads((copy / "model.json").read_text())["num_timesteps"] == 1000
    assert json.loads((copy / "evaluation.json").read_text())["model"]["episodes"] == 1


def test_train_refuses_bad_input_cleanly(
    trained: tuple[Path, Path], tmp_path: Path, capsys
) -> None:
    config, run_dir = trained
    assert main(["train", str(config), "--set", "env.centroid=polar", "--no-progress"]) == 2
    assert "centroid" in capsys.readouterr().err
    assert main(["train", str(tmp_path / "missing.toml")]) == 2
    assert "not found" in capsys.readouterr().err
    assert main(["train", str(config), "--out", str(run_dir), "--no-progress"]) == 2
    assert "--resume" in capsys.readouterr().err
    assert main(["train", "--resume", str(run_dir), "--set", "env.reward=reward1"]) == 2
    assert "cannot change" in capsys.readouterr().err
    assert main(["train"]) == 2


def test_evaluate_command_reports_and_writes_json(
    trained: tuple[Path, Path], tmp_path: Path, capsys
) -> None:
    _config, run_dir = trained
    out_json = tmp_path / "eval.json"
    plot = tmp_path / "actions.png"
    code = main(
        [
            "evaluate",
            str(run_dir / "model.zip"),
            "--episodes",
            "3",
            "--seed",
            "5",
            "--map-mode",
            "dynamic",
            "--json",
            str(out_json),
            "--plot",
            str(plot),
            "--no-progress",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "greedy-distance" in out and "degenerate" in out
    result = json.loads(out_json.read_text())
    assert result["env_config"]["map_mode"] == "dynamic"
    assert result["env_config"]["height"] == 10  # the training env, from model.json
    model, greedy = result["rows"]
    assert model["seeds"] == greedy["seeds"] == [5, 6, 7]
    for row in (model, greedy):
        assert {"mean_reward", "std_reward", "terminations", "action_shares", "degeneracy"} <= set(
            row
        )
        assert sum(row["action_shares"]) == pytest.approx(1.0)
    assert plot.is_file() and plot.stat().st_size > 0


def test_evaluate_refuses_a_mismatched_env(trained: tuple[Path, Path], capsys) -> None:
    _config, run_dir = trained
    code = main(
        ["evaluate", str(run_dir), "--episodes", "1", "--no-progress", "--set", "centroid=relative"]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert "does not match" in err and "centroid" in err and "Traceback" not in err
    code = main(
        ["evaluate", str(run_dir), "--episodes", "1", "--no-progress", "--preset", "thesis-30x30"]
    )
    assert code == 2
    assert "height" in capsys.readouterr().err


def test_evaluate_missing_model(tmp_path: Path, capsys) -> None:
    assert main(["evaluate", str(tmp_path / "nothing.zip"), "--no-progress"]) == 2
    assert "not found" in capsys.readouterr().err


def test_evaluate_a_team_with_the_shared_parameter_model(
    trained: tuple[Path, Path], tmp_path: Path, capsys
) -> None:
    _config, run_dir = trained
    out_json = tmp_path / "team.json"
    code = main(
        [
            "evaluate",
            str(run_dir),
            "--agents",
            "3",
            "--episodes",
            "2",
            "--json",
            str(out_json),
            "--no-progress",
        ]
    )
    assert code == 0
    result = json.loads(out_json.read_text())
    assert result["env_config"]["n_agents"] == 3
    model, _greedy = result["rows"]
    assert model["n_agents"] == 3
    # every robot acted every step: decisions = 3 x steps in each episode
    for episode in model["per_episode"]:
        assert sum(episode["action_counts"]) == 3 * episode["steps"]


def test_evaluate_the_shipped_model_by_name(tmp_path: Path, capsys) -> None:
    out_json = tmp_path / "shipped.json"
    code = main(
        [
            "evaluate",
            "thesis-config01",
            "--episodes",
            "2",
            "--heuristics",
            "",
            "--json",
            str(out_json),
            "--no-progress",
        ]
    )
    assert code == 0
    result = json.loads(out_json.read_text())
    # The best-validated policy of a 1e6-step run (chosen at step 340,000).
    assert result["num_timesteps"] == 340_000
    assert result["env_config"]["height"] == 20
    meta = json.loads((pretrained_model_dir("thesis-config01") / "model.json").read_text())
    assert meta["experiment"]["train"]["total_timesteps"] == 1_000_000
    assert meta["validation"]["step"] == 340_000 and meta["validation"]["seed"] == 1000
    (model,) = result["rows"]
    assert model["episodes"] == 2 and sum(model["action_shares"]) == pytest.approx(1.0)


@pytest.mark.slow
def test_train_the_explorer_on_families_and_benchmark_it(tmp_path: Path, capsys) -> None:
    """The shipped explorer config trains (tiny budget) on the four families with the slot
    scorer, resumes, and the benchmark runs the model on validation episodes of every size."""
    run_dir = tmp_path / "explorer"
    overrides = ["--set", "dqn.learning_starts=50", "--set", "train.n_envs=1", "--no-progress"]
    assert main(["train", "explorer-dqn", "--steps", "300", "--out", str(run_dir), *overrides]) == 0
    meta = json.loads((run_dir / "model.json").read_text())
    assert meta["observation_layout"]["features"] == "explorer"
    assert "height" not in meta["observation_layout"]
    assert main(["train", "--resume", str(run_dir), "--steps", "400", "--no-progress"]) == 0
    out = tmp_path / "bench.json"
    code = main(
        ["benchmark", "--policies", f"nearest-path,{run_dir}", "--episodes", "1",
         "--split", "validation", "--json", str(out), "--no-progress"]
    )  # fmt: skip
    assert code == 0
    rows = json.loads(out.read_text())["rows"]
    assert {row["family"] for row in rows if row["policy"] == "explorer"} == {
        "random-20", "random-30", "rooms-32", "rooms-64", "rooms-96-fine", "floorplan-96"
    }  # fmt: skip
    assert all(row["seeds"][0] == 800_000 for row in rows)


def test_train_a_team_model_on_families_and_team_sizes(tmp_path: Path) -> None:
    """The team-explorer config trains (tiny budget) one parameter-shared model on every
    family and team size, validates it by makespan against utility-discount, and the benchmark
    runs it with a team size it was not validated on."""
    run_dir = tmp_path / "team"
    overrides = ["--set", "dqn.learning_starts=50", "--set", "train.n_envs=1", "--no-progress"]
    overrides += ["--set", "train.validate_every=300", "--set", "train.validation_episodes=1"]
    overrides += ["--set", "train.agents=[2, 3]"]
    assert (
        main(["train", "team-explorer", "--steps", "300", "--out", str(run_dir), *overrides]) == 0
    )
    meta = json.loads((run_dir / "model.json").read_text())
    assert meta["observation_layout"]["n_agents"] is None  # the layout fits every team size
    assert meta["experiment"]["train"]["agents"] == [2, 3]
    (record,) = [
        json.loads(line) for line in (run_dir / "validation.jsonl").read_text().splitlines()
    ]
    assert record["reference"] == "utility-discount" and record["metric"] == "makespan99"
    assert set(record["by_family"]) == {"random-30", "rooms-64"}
    out = tmp_path / "bench.json"
    argv = ["benchmark", "--families", "random-30", "--agents", "4", "--policies"]
    argv += [f"utility-discount,{run_dir}", "--episodes", "1", "--split", "validation"]
    assert main([*argv, "--json", str(out), "--no-progress"]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [row["agents"] for row in rows] == [4, 4]
    assert rows[1]["best_heuristic_makespan"] == "utility-discount"


@pytest.mark.parametrize(
    "agents, message",
    [([0], "team sizes >= 1"), ([], "team sizes >= 1"), ([True], "team sizes >= 1")],
)
def test_bad_team_sizes_are_refused(agents: list, message: str) -> None:
    from frontier_marl.training.experiment import load_experiment

    with pytest.raises(ValueError, match=message):
        load_experiment("team-explorer", [f"train.agents={agents}".replace("True", "true")])


def test_team_sizes_need_families() -> None:
    from frontier_marl.training.experiment import load_experiment

    with pytest.raises(ValueError, match="needs train.families"):
        load_experiment("config01", ["train.agents=[2]"])
