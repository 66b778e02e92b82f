"""The calibration (baselines/calibrate.py): the score, the fit test, and a --quick run end to
end."""

from __future__ import annotations

import json

import pytest

from frontier_marl.experiments.calibrate import main
from frontier_marl.experiments.calibration_search import fits, score_of


def row(gd: tuple[float, float], gg: tuple[float, float], n_slots: int = 4) -> dict:
    return {
        "setting": {"n_slots": n_slots},
        "greedy-distance": {"mean": gd[0], "std": gd[1]},
        "greedy-gain": {"mean": gg[0], "std": gg[1]},
    }


def test_score_is_zero_on_the_thesis_figures_and_adds_the_stated_terms():
    assert score_of(row((16.48, 1.78), (15.01, 1.12))) == pytest.approx(0.0)
    # mean errors 0.2 + 0.1, std errors 0.4 + 0.8 weighted 0.25
    assert score_of(row((16.68, 1.38), (14.91, 1.92))) == pytest.approx(0.3 + 0.3)
    # wrong order costs 10, leaving four slots costs 1
    assert score_of(row((15.0, 1.78), (15.01, 1.12))) == pytest.approx(1.48 + 10)
    assert score_of(row((16.48, 1.78), (15.01, 1.12), n_slots=5)) == pytest.approx(1.0)


def test_fits_needs_both_means_within_tolerance_and_greedy_distance_ahead():
    assert fits(row((16.9, 0.0), (15.4, 0.0)), 0.5)
    assert not fits(row((17.0, 0.0), (15.01, 0.0)), 0.5)
    assert not fits(row((16.48, 0.0), (15.6, 0.0)), 0.5)
    assert not fits(row((15.2, 0.0), (15.3, 0.0)), 2.0)


def test_quick_run_writes_a_complete_results_file(tmp_path):
    out = tmp_path / "calibration.json"
    assert main(["--quick", "--out", str(out)]) == 0
    data = json.loads(out.read_text())
    winner = data["winner"]
    assert set(winner["setting"]) == set(data["reference"])
    best = min(data["validation"], key=lambda v: v["total"])
    assert winner["setting"] == best["setting"]
    assert best["total"] == pytest.approx(winner["score"] + best["held_out"]["score"])
    for r in data["rows"]:
        for policy in ("greedy-distance", "greedy-gain"):
            assert r[policy]["std"] >= 0 and 0 <= r[policy]["terminations"] <= data["episodes"]
    assert data["episodes"] == 3 and data["map_seed"] == 0
    assert {"reward1", "dynamic map"} <= set(data["checks"])
    assert "policy_options" not in data  # the plain rules unless --protocol


def test_protocol_gives_greedy_distance_the_thesis_protocol_options(tmp_path):
    out = tmp_path / "calibration.json"
    assert main(["--quick", "--protocol", "--out", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["policy_options"] == {"greedy-distance": {"commit": "on-cycle"}}
