"""The fit benchmark runs and reports what it timed (no timing asserted)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("torch")

from frontier_marl.experiments.speed import bench_map_scorer_fit  # noqa: E402


def test_the_fit_benchmark_reports_its_labels_and_seconds(tmp_path: Path) -> None:
    out = tmp_path / "fit.json"
    assert bench_map_scorer_fit.main(["--episodes", "2", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["decisions"] > 0 and report["candidates"] >= 2 * report["decisions"]
    assert 0 < report["valid_share"] <= 1 and report["seconds_per_epoch"] > 0


def test_the_fit_benchmark_refuses_zero_epochs() -> None:
    with pytest.raises(SystemExit):
        bench_map_scorer_fit.main(["--epochs", "0"])
