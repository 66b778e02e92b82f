"""The map explorer's inference benchmark runs and reports what it says (no timing asserted)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("torch")

from frontier_marl.experiments.speed import bench_map_explorer  # noqa: E402
from frontier_marl.policies.map_crops import slot_crops  # noqa: E402


def test_the_inference_benchmark_counts_real_decisions_and_splits_their_time(
    tmp_path: Path,
) -> None:
    out = tmp_path / "inference.json"
    args = ["--family", "random-20", "--episodes", "1", "--json", str(out)]
    assert bench_map_explorer.main(args) == 0
    report = json.loads(out.read_text())
    assert report["family"] == "random-20" and report["torch_threads"] == 1
    assert report["decisions"] > 0 and report["candidates_per_decision"] >= 2
    assert report["decisions_per_s"] > 0 and 0 < report["crops_share"] < 1
    assert bench_map_explorer.map_explorer.slot_crops is slot_crops  # the timer is taken off
