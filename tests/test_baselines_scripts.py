"""The diagnostics behind baselines/livelocks.py and dynamic_maps.py with tiny budgets: they run
and report consistently."""

from __future__ import annotations

import json
from pathlib import Path

from frontier_marl.experiments import dynamic_maps, livelocks


def test_livelocks_finds_the_30x30_cycle_and_the_rule_removes_it(tmp_path: Path) -> None:
    out = tmp_path / "stuck.json"
    args = ["--preset", "thesis-30x30", "--episodes", "1", "--seed", "16", "--no-progress"]
    assert livelocks.main([*args, "--policies", "greedy-distance", "--json", str(out)]) == 0
    (record,) = json.loads(out.read_text())["greedy-distance"]
    assert record["seed"] == 16 and record["end_reason"] == "no_progress"
    assert record["alternating"] and record["distinct_targets"] == 2
    fixed = ["--option", "commit=until-progress", "--policies", "greedy-distance"]
    assert livelocks.main([*args, *fixed, "--json", str(out)]) == 0
    assert json.loads(out.read_text())["greedy-distance"] == []


def test_dynamic_maps_reports_every_candidate(tmp_path: Path) -> None:
    out = tmp_path / "dynamic.json"
    assert dynamic_maps.main(["--episodes", "1", "--no-progress", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert len(report["rows"]) == 8 and len(report["static"]) == 4
    for row in report["rows"]:
        assert isinstance(row["pattern"], bool)
        assert len(row["thesis-20x20 greedy-gain"]) == 2
