"""The diagnostic of training/diagnose_cycles.py on the shipped model, two episodes."""

from __future__ import annotations

from frontier_marl.experiments.diagnose_cycles import diagnose
from frontier_marl.policies.models import pretrained_model_dir


def test_counts_add_up_for_the_shipped_model():
    result = diagnose(pretrained_model_dir("thesis-config01"), episodes=2)
    ends = sum(value for key, value in result.items() if key.startswith("end: "))
    assert ends == 2
    stuck = result.get("stuck episodes", 0)
    assert stuck == result.get("end: no_progress", 0)
    assert result.get("stuck decisions", 0) == 20 * stuck
    assert result.get("stuck: distinct targets", 0) <= 20 * stuck
