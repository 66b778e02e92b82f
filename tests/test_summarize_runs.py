"""The run summaries of training/summarize_runs.py on a tiny run: the summary holds what docs
cite, no artefacts."""

from __future__ import annotations

import json
from pathlib import Path

from frontier_marl.cli.main import main as cli
from frontier_marl.experiments.summarize_runs import main


def test_a_run_folder_becomes_one_small_summary(tmp_path: Path) -> None:
    run_dir = tmp_path / "run"
    args = ["train", "config01", "--steps", "1200", "--out", str(run_dir), "--no-progress"]
    sets = ["train.validate_every=600", "train.validation_episodes=2", "train.eval_episodes=2"]
    assert cli([*args, *[x for s in sets for x in ("--set", s)]]) == 0
    out = tmp_path / "summaries"
    assert main([str(run_dir), "--out", str(out), "--machine", "test", "--window", "400"]) == 0
    summary = json.loads((out / "run.json").read_text())
    assert summary["experiment"]["name"] == "config01"
    assert summary["num_timesteps"] == 1200
    assert summary["machine"] != "test"  # the run recorded its own machine
    assert summary["sessions"][0]["end_step"] == 1200
    assert [v["step"] for v in summary["validation"]] == [600, 1200]
    rows = summary["evaluation"]["rows"]
    assert rows[0]["episodes"] == 2 and len(rows[0]["per_episode"]) == 2
    assert all("curve" not in e for row in rows for e in row["per_episode"])
    assert summary["best"]["validation"]["step"] in (600, 1200)
    windows = summary["learning_curve"]["windows"]
    starts = [w["start"] for w in windows]
    assert starts == sorted(starts) and all(s % 400 == 0 for s in starts)
    assert all(w["end"] == w["start"] + 400 for w in windows)
    assert sum(w["td_loss_count"] for w in windows) > 0
    assert (out / "run.json").stat().st_size < 100_000
