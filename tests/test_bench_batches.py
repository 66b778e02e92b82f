"""The batch benchmark script runs and reports what it says (tiny budgets; no timing asserted)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from frontier_marl.experiments.speed import bench_batches


def test_the_batch_benchmark_reports_every_setting_and_map_size(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(bench_batches, "BATCHES", (1, 2))
    monkeypatch.setattr(bench_batches, "MEMORY_SIZES", (16,))
    out = tmp_path / "batches.json"
    assert bench_batches.main(["--seconds", "0.05", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    settings = {(r["setting"], r["worlds"]) for r in report["decisions"]}
    assert settings == {(s, n) for s in bench_batches.SETTINGS for n in (1, 2)}
    assert all(r["decisions_per_s"] > 0 for r in report["decisions"])
    (memory,) = report["memory"]
    assert memory["map"] == "16x16" and memory["bytes_per_world"] > 16 * 16


def test_a_larger_batch_holds_more_memory() -> None:
    kwargs = {**bench_batches.ROOMS_64, "height": 16, "width": 16}
    assert bench_batches.held_bytes(kwargs, 8, 2) > bench_batches.held_bytes(kwargs, 1, 2)
