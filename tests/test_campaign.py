"""``frontier-marl campaign`` on Ray Tune with tiny budgets.

The Ray tests start a local Ray instance (2 CPUs, no dashboard) and are skipped when
``ray[tune]`` is not installed; the missing-Ray error path is tested by hiding the module.
"""

from __future__ import annotations

import csv
import json
import signal
import sys
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("supersuit")

from frontier_marl.cli.main import main  # noqa: E402

pytestmark = pytest.mark.slow  # starts a local Ray instance

CONFIGS = ("config01", "config04")


def test_missing_ray_exits_2_with_install_hint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` now raises ImportError
    monkeypatch.setitem(sys.modules, "ray.tune", None)
    code = main(
        [
            "campaign",
            "--configs",
            "config01",
            "--steps",
            "1000",
            "--out",
            str(tmp_path / "c"),
            "--no-progress",
        ]
    )
    assert code == 2
    assert 'pip install "frontier-marl[ray]"' in capsys.readouterr().err
    assert not (tmp_path / "c").exists()


def test_require_ray_raises_an_import_error(monkeypatch: pytest.MonkeyPatch) -> None:
    from frontier_marl.experiments.ray_tune import RayNotInstalledError, require_ray

    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(RayNotInstalledError, match=r"frontier-marl\[ray\]"):
        require_ray()
    assert issubclass(RayNotInstalledError, ImportError)


def test_build_grid_lists_configs_seeds_budgets(tmp_path: Path) -> None:
    from frontier_marl.experiments.campaign import build_grid

    trials = build_grid(
        CONFIGS,
        [0, 1],
        [1000, 500],
        tmp_path,
        eval_episodes=2,
        overrides=["train.checkpoint_every=0"],
    )
    assert len(trials) == 8
    assert len({t.run_dir for t in trials}) == 8
    first = trials[0]
    assert (first.config, first.seed, first.steps) == ("config01", 0, 1000)
    train = first.experiment["train"]
    assert train["torch_threads"] == 1
    assert (train["total_timesteps"], train["seed"], train["eval_episodes"]) == (1000, 0, 2)
    assert train["checkpoint_every"] == 0
    assert Path(first.run_dir) == tmp_path.resolve() / "runs" / "config01" / "seed0_steps1000"
    with pytest.raises(ValueError, match="neither a file nor a shipped config"):
        build_grid(["no-such-config"], [0], [1000], tmp_path)
    with pytest.raises(ValueError, match="steps"):
        build_grid(CONFIGS, [0], [0], tmp_path)


@pytest.fixture(scope="module")
def local_ray():
    ray = pytest.importorskip("ray")
    pytest.importorskip("ray.tune")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield ray
    ray.shutdown()


@pytest.fixture(scope="module")
def campaign(local_ray, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    out = tmp_path_factory.mktemp("campaign") / "out"
    # one trial at a time: the test machine has two cores and other work on them
    args = [
        "campaign",
        "--configs",
        ",".join(CONFIGS),
        "--seeds",
        "0",
        "--steps",
        "1000",
        "--episodes",
        "2",
        "--out",
        str(out),
        "--max-concurrent",
        "1",
        "--no-progress",
    ]
    handler = signal.getsignal(signal.SIGINT)
    assert main(args) == 0
    # Ray Tune's fit installs its own SIGINT handler and leaves it; the campaign restores ours
    assert signal.getsignal(signal.SIGINT) is handler
    return out, args


def test_campaign_collects_one_row_per_trial(campaign: tuple[Path, list[str]]) -> None:
    out, _args = campaign
    table = json.loads((out / "campaign.json").read_text())
    rows = table["rows"]
    assert [row["config"] for row in rows] == list(CONFIGS)
    for row in rows:
        assert row["status"] == "ok"
        assert (row["seed"], row["steps"], row["episodes"]) == (0, 1000, 2)
        assert 0 <= row["terminations"] <= 2
        assert isinstance(row["mean_reward"], float) and row["std_reward"] >= 0
        assert len(row["action_shares"]) == 4
        assert sum(row["action_shares"]) == pytest.approx(1.0, abs=1e-6)
        assert isinstance(row["degenerate"], bool)
        assert row["wall_time_s"] > 0 and row["trial_wall_time_s"] >= row["wall_time_s"]
        assert (Path(row["run_dir"]) / "model.zip").is_file()
        assert (Path(row["run_dir"]) / "evaluation.json").is_file()
    assert rows[0]["thesis"].startswith("15.55 ± 2.45")
    assert rows[1]["thesis"].startswith("16.91 ± 0.57")
    assert table["budgets"] == [1000] and table["seeds"] == [0]
    with (out / "campaign.csv").open() as handle:
        csv_rows = list(csv.DictReader(handle))
    assert [r["config"] for r in csv_rows] == list(CONFIGS)
    markdown = (out / "campaign.md").read_text()
    assert "| config01 | 0 | 1000 |" in markdown


def test_campaign_table_matches_the_run_folders(campaign: tuple[Path, list[str]]) -> None:
    from frontier_marl.experiments.results import collect_runs

    out, _args = campaign
    table = json.loads((out / "campaign.json").read_text())["rows"]
    on_disk = collect_runs(out / "runs")
    assert [(r["config"], r["seed"], r["steps"]) for r in on_disk] == [
        (r["config"], r["seed"], r["steps"]) for r in table
    ]
    for disk, reported in zip(on_disk, table, strict=True):
        assert disk["mean_reward"] == pytest.approx(reported["mean_reward"])
        assert disk["action_shares"] == pytest.approx(reported["action_shares"])


def test_campaign_rerun_reuses_finished_runs(campaign: tuple[Path, list[str]]) -> None:
    out, args = campaign
    before = json.loads((out / "campaign.json").read_text())["rows"]
    assert main(args) == 0
    after = json.loads((out / "campaign.json").read_text())["rows"]
    assert [row["reused"] for row in after] == [True, True]
    assert [r["mean_reward"] for r in after] == pytest.approx([r["mean_reward"] for r in before])


def test_campaign_refuses_a_run_folder_of_another_experiment(
    campaign: tuple[Path, list[str]],
) -> None:
    from frontier_marl.experiments.campaign import build_grid, run_trial

    out, _args = campaign
    changed = build_grid(
        ["config01"], [0], [1000], out, eval_episodes=2, overrides=["env.reward=reward1"]
    )[0]
    with pytest.raises(ValueError, match="settings differ"):
        run_trial(changed)
