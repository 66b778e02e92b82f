"""training/diagnose_cycles.py on the shipped model, two episodes."""

from __future__ import annotations

import runpy
from pathlib import Path

from frontier_marl.policies.models import pretrained_model_dir

REPO = Path(__file__).resolve().parents[1]


def test_counts_add_up_for_the_shipped_model():
    diagnose = runpy.run_path(str(REPO / "training" / "diagnose_cycles.py"))["diagnose"]
    result = diagnose(pretrained_model_dir("thesis-config01"), episodes=2)
    ends = sum(value for key, value in result.items() if key.startswith("end: "))
    assert ends == 2
    stuck = result.get("stuck episodes", 0)
    assert stuck == result.get("end: no_progress", 0)
    assert result.get("stuck decisions", 0) == 20 * stuck
    assert result.get("stuck: distinct targets", 0) <= 20 * stuck
