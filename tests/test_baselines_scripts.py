"""The diagnostics behind baselines/livelocks.py and dynamic_maps.py with tiny budgets: they run
and report consistently."""

from __future__ import annotations

import json
from pathlib import Path

from frontier_marl.experiments import dynamic_maps, livelocks, table65


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


def test_table65_reports_each_candidate_against_the_criteria(tmp_path: Path) -> None:
    out = tmp_path / "table65.json"
    argv = ["--episodes", "2", "--only", "default,adopted", "--json", str(out)]
    assert table65.main(argv) == 0
    default, adopted = json.loads(out.read_text())
    assert default["candidate"] == "default" and adopted["candidate"] == "adopted"
    assert len(adopted["cells"]) == 8 and len(adopted["known_within"]) == 4
    assert len(adopted["unknown_moved"]) == 4
    assert set(default["unknown_moved"].values()) == {0.0}  # the reference of the moves
    assert default["calibration_rows_identical"] == {"greedy-distance": True, "greedy-gain": True}
    assert default["changed_episodes"] == {}
    for row in (default, adopted):
        assert isinstance(row["all"], bool) and isinstance(row["gd_ahead_everywhere"], bool)
        for _mean, std, terminations in row["cells"].values():
            assert std >= 0 and 0 <= terminations <= 2
        for changed, finished in row["changed_episodes"].values():
            assert 0 <= finished <= changed <= 2
