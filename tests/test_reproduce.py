"""``frontier-marl reproduce`` end to end with a tiny budget.

The run starts from a working directory outside the repository, so the config lookup
(``config01`` -> the config shipped in the package) is exercised as after an install. Nothing
here checks learning quality.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("supersuit")

from frontier_marl.cli.main import main  # noqa: E402
from frontier_marl.experiments.reproduce import HEURISTICS, reproduce  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
STEPS, EPISODES = 2000, 3
VALIDATED_CONFIG = (
    'name = "config01"\n'
    'description = "configuration 1 with validation"\n'
    '[env]\npreset = "thesis-20x20"\ncentroid = "absolute"\nagent_position = true\n'
    'info_gain = false\nsort_by_distance = false\nreward = "reward2"\n'
    "[train]\nvalidate_every = 500\nvalidation_episodes = 2\n"
)


@pytest.fixture(scope="module")
def reproduced(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    elsewhere = tmp_path_factory.mktemp("cwd")
    out = tmp_path_factory.mktemp("reproduce") / "out"
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(elsewhere)  # not the repository: the config must still be found
        stdout = io.StringIO()
        with contextlib.redirect_stdout(stdout):
            code = main(
                [
                    "reproduce",
                    "--steps",
                    str(STEPS),
                    "--episodes",
                    str(EPISODES),
                    "--out",
                    str(out),
                    "--seed",
                    "1",
                    "--no-progress",
                ]
            )
    assert code == 0, stdout.getvalue()
    return out, stdout.getvalue()


def test_reproduce_writes_table_figures_and_run(reproduced: tuple[Path, str]) -> None:
    out, _stdout = reproduced
    run_dir = out / "config01_seed1"
    for name in (
        "comparison.md",
        "comparison.json",
        "comparison_rewards.png",
        "comparison_actions.png",
        "learning_curve.png",
        "baselines.json",
    ):
        path = out / name
        assert path.is_file() and path.stat().st_size > 0, name
    for name in ("model.zip", "model.json", "evaluation.json", "actions.png"):
        assert (run_dir / name).is_file(), name
    assert list((run_dir / "tb").glob("events.out.tfevents.*"))


def test_reproduce_json_has_dqn_and_heuristic_rows_with_thesis_figures(
    reproduced: tuple[Path, str],
) -> None:
    out, _stdout = reproduced
    table = json.loads((out / "comparison.json").read_text())
    rows = {row["policy"]: row for row in table["rows"]}
    assert list(rows) == ["DQN config01", *HEURISTICS]
    dqn = rows["DQN config01"]
    assert dqn["kind"] == "dqn"
    assert dqn["episodes"] == EPISODES
    assert (dqn["thesis_mean"], dqn["thesis_std"]) == (15.55, 2.45)
    assert (dqn["thesis_terminations"], dqn["thesis_episodes"]) == (25, 30)
    assert dqn["thesis_action_shares"] == [0.506, 0.254, 0.212, 0.028]
    assert sum(dqn["action_shares"]) == pytest.approx(1.0)
    assert isinstance(dqn["degenerate"], bool)
    assert (rows["greedy-distance"]["thesis_mean"], rows["greedy-distance"]["thesis_std"]) == (
        16.48,
        1.78,
    )
    assert (rows["greedy-gain"]["thesis_mean"], rows["greedy-gain"]["thesis_std"]) == (15.01, 1.12)
    assert rows["cost-utility"]["thesis_mean"] is None
    assert rows["random"]["thesis_mean"] is None
    for name in HEURISTICS:
        assert rows[name]["kind"] == "heuristic"
        assert rows[name]["episodes"] == EPISODES
    assert table["training"]["steps"] == STEPS
    assert table["training"]["seeds"] == [1]
    assert [run["seed"] for run in table["training"]["runs"]] == [1]
    assert table["setting"]["map_mode"] == "static"
    assert table["setting"]["seeds"] == [0, EPISODES - 1]
    assert set(table["checks"]) == {
        "max_share_at_most_70pct",
        "three_actions_above_2pct",
        "mean_at_least_13.1",
    }
    [summary] = table["summaries"]
    assert summary["config"] == "config01"
    assert summary["mean_reward"] == pytest.approx(dqn["mean_reward"])
    assert table["seed_spread"]["means"] == [pytest.approx(dqn["mean_reward"])]


def test_heuristics_ran_on_the_dqn_evaluation_episodes(reproduced: tuple[Path, str]) -> None:
    """The run's own evaluation (model + greedy-distance) and the baselines used the same
    env and seeds: greedy-distance (deterministic) gives identical episode rewards."""
    out, _stdout = reproduced
    evaluation = json.loads((out / "config01_seed1" / "evaluation.json").read_text())
    baselines = {row["policy"]: row for row in json.loads((out / "baselines.json").read_text())}
    greedy = evaluation["heuristics"][0]
    assert greedy["policy"] == "greedy-distance"
    assert baselines["greedy-distance"]["seeds"] == evaluation["model"]["seeds"]
    assert baselines["greedy-distance"]["rewards"] == pytest.approx(greedy["rewards"])


def test_reproduce_prints_table_and_summary_with_paths(reproduced: tuple[Path, str]) -> None:
    out, stdout = reproduced
    markdown = (out / "comparison.md").read_text()
    for text in (
        "15.55 ± 2.45",
        "16.48 ± 1.78",
        "15.01 ± 1.12",
        "25/30",
        "50.6/25.4/21.2/2.8 %",
        "| DQN config01 |",
        "| random |",
    ):
        assert text in markdown, text
        assert text in stdout, text
    assert "Summary" in stdout
    assert str(out / "comparison.json") in stdout
    assert str(out / "comparison_rewards.png") in stdout


def test_reproduce_refuses_existing_run_then_resumes(
    reproduced: tuple[Path, str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import shutil

    out, _stdout = reproduced
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    args = ["reproduce", "--episodes", "1", "--out", str(copy), "--seed", "1", "--no-progress"]
    assert main([*args, "--steps", str(STEPS)]) == 2
    assert "--resume" in capsys.readouterr().err
    assert main([*args, "--steps", str(STEPS + 400), "--resume"]) == 0
    assert "resuming at step 2000" in capsys.readouterr().out
    table = json.loads((copy / "comparison.json").read_text())
    assert table["training"]["steps"] == STEPS + 400
    assert all(row["episodes"] == 1 for row in table["rows"])
    sessions = json.loads((copy / "config01_seed1" / "run.json").read_text())["sessions"]
    assert [(s["start_step"], s["end_step"]) for s in sessions] == [
        (0, STEPS),
        (STEPS, STEPS + 400),
    ]


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"steps": 0}, "steps"),
        ({"seeds": [-1]}, "seeds"),
        ({"seeds": []}, "seeds"),
        ({"seeds": [0, 0]}, "distinct"),
        ({"jobs": 0}, "jobs"),
        ({"episodes": 0}, "episodes"),
    ],
)
def test_reproduce_rejects_bad_input(kwargs: dict, name: str, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=name):
        reproduce(tmp_path, progress=False, log=lambda _text: None, **kwargs)
    assert not any(tmp_path.iterdir())


def test_config_names_resolve_from_any_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from frontier_marl.training.experiment import load_experiment, shipped_configs

    monkeypatch.chdir(tmp_path)
    assert {"config01", "config12", "team_30x30"} <= set(shipped_configs())
    experiment = load_experiment("config01")
    assert experiment.name == "config01" and experiment.source == "config01 (shipped)"
    assert load_experiment("config01.toml").to_dict() == experiment.to_dict()
    with pytest.raises(ValueError, match="neither a file nor a shipped config"):
        load_experiment("no-such-config")
    (tmp_path / "mine.toml").write_text('name = "mine"\n')  # a file path wins over names
    assert load_experiment(tmp_path / "mine.toml").name == "mine"


def test_reproduce_reports_the_best_validated_policy_beside_the_final_model(
    tmp_path: Path,
) -> None:
    config = tmp_path / "validated.toml"
    config.write_text(VALIDATED_CONFIG)
    result = reproduce(
        tmp_path / "out",
        steps=1000,
        seeds=[0],
        episodes=2,
        config=config,
        heuristics=("greedy-distance",),
        progress=False,
        log=lambda _line: None,
    )
    table = result.table
    assert table is not None
    rows = table["rows"]
    assert [row["policy"] for row in rows] == [
        "DQN config01",
        "DQN config01, final model",
        "greedy-distance",
    ]
    [run_dir] = result.run_dirs
    best = json.loads((run_dir / "best" / "evaluation.json").read_text())
    final = json.loads((run_dir / "evaluation.json").read_text())
    assert rows[0]["mean_reward"] == best["model"]["mean_reward"]
    assert rows[1]["mean_reward"] == final["model"]["mean_reward"]
    assert rows[0]["thesis_mean"] == 15.55 and rows[1]["thesis_mean"] is None
    step = best["validation"]["step"]
    [run] = table["training"]["runs"]
    assert run["reported_policy"].startswith(f"best-validated policy (step {step},")
    assert table["summaries"][0]["mean_reward"] == best["model"]["mean_reward"]
    assert f"best-validated policy (step {step}," in (result.out / "comparison.md").read_text()


@pytest.mark.slow
def test_reproduce_with_two_seeds_pools_them_and_reports_each(tmp_path: Path) -> None:
    config = tmp_path / "validated.toml"
    config.write_text(VALIDATED_CONFIG)
    result = reproduce(
        tmp_path / "out",
        steps=1000,
        seeds=[0, 1],
        jobs=2,
        episodes=2,
        config=config,
        heuristics=("greedy-distance",),
        progress=False,
        log=lambda _line: None,
    )
    table = result.table
    assert table is not None and not result.interrupted
    assert result.run_dirs == [
        tmp_path / "out" / "config01_seed0",
        tmp_path / "out" / "config01_seed1",
    ]
    best = [json.loads((d / "best" / "evaluation.json").read_text()) for d in result.run_dirs]
    final = [json.loads((d / "evaluation.json").read_text()) for d in result.run_dirs]
    rows = table["rows"]
    steps = [b["validation"]["step"] for b in best]
    assert [row["policy"] for row in rows] == [
        "DQN config01",
        f"DQN config01, seed 0 (step {steps[0]})",
        f"DQN config01, seed 1 (step {steps[1]})",
        "DQN config01, final models",
        "greedy-distance",
    ]
    pooled, seed0, seed1, finals = rows[:4]
    best_means = [b["model"]["mean_reward"] for b in best]
    assert pooled["episodes"] == 4 and pooled["thesis_mean"] == 15.55
    assert pooled["mean_reward"] == pytest.approx(sum(best_means) / 2)
    assert pooled["terminations"] == sum(b["model"]["terminations"] for b in best)
    assert pooled["degenerate"] == (seed0["degenerate"] or seed1["degenerate"])
    assert [seed0["mean_reward"], seed1["mean_reward"]] == best_means
    assert finals["mean_reward"] == pytest.approx(sum(f["model"]["mean_reward"] for f in final) / 2)
    spread = table["seed_spread"]
    assert spread["seeds"] == [0, 1] and spread["means"] == best_means
    assert spread["std"] == pytest.approx(abs(best_means[0] - best_means[1]) / 2)
    assert table["checks"]["mean_at_least_13.1"] == (pooled["mean_reward"] >= 13.1)
    assert [run["seed"] for run in table["training"]["runs"]] == [0, 1]
    assert [s["seed"] for s in table["summaries"]] == [0, 1]
    markdown = (result.out / "comparison.md").read_text()
    assert "Across seeds:" in markdown and "seeds 0, 1 (2 runs at a time)" in markdown
    assert (result.out / "learning_curve.png").stat().st_size > 0


GENUINE = {"action_shares": [0.5, 0.3, 0.15, 0.05]}
DEGENERATE = {"action_shares": [0.95, 0.05, 0.0, 0.0]}


def test_genuine_checks_ask_every_seed_to_be_genuine_and_the_mean_to_reach_the_bar() -> None:
    from frontier_marl.experiments.comparison import genuine_checks

    assert genuine_checks([GENUINE, GENUINE], 13.1) == {
        "max_share_at_most_70pct": True,
        "three_actions_above_2pct": True,
        "mean_at_least_13.1": True,
    }
    mixed = genuine_checks([GENUINE, DEGENERATE], 15.0)
    assert not mixed["max_share_at_most_70pct"] and not mixed["three_actions_above_2pct"]
    assert mixed["mean_at_least_13.1"]
    assert not genuine_checks([GENUINE], 13.09)["mean_at_least_13.1"]


def test_pool_evaluations_holds_every_run_s_episodes() -> None:
    from frontier_marl.experiments.comparison import pool_evaluations

    a = {
        "episodes": 2,
        "rewards": [10.0, 12.0],
        "terminations": 1,
        "action_counts": [10, 0, 0, 0],
        "action_shares": [1.0, 0.0, 0.0, 0.0],
        "mean_travelled": 5.0,
    }
    b = {
        "episodes": 2,
        "rewards": [14.0, 16.0],
        "terminations": 2,
        "action_counts": [0, 2, 4, 4],
        "action_shares": [0.0, 0.2, 0.4, 0.4],
        "mean_travelled": 7.0,
    }
    pooled = pool_evaluations([a, b], "both")
    assert pooled["policy"] == "both" and pooled["episodes"] == 4
    assert pooled["rewards"] == [10.0, 12.0, 14.0, 16.0]
    assert pooled["mean_reward"] == pytest.approx(13.0)
    assert pooled["std_reward"] == pytest.approx(5.0**0.5)  # population std of the 4 episodes
    assert pooled["terminations"] == 3
    assert pooled["action_counts"] == [10, 2, 4, 4]
    assert pooled["action_shares"] == pytest.approx([0.5, 0.1, 0.2, 0.2])
    assert pooled["mean_travelled"] == pytest.approx(6.0)
    # 50 % slot 0 overall, but run a alone is degenerate: the pooled row says so
    assert pooled["degeneracy"]["degenerate"]
    assert not pool_evaluations([b, b], "b twice")["degeneracy"]["degenerate"]
