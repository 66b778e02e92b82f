"""The vector-step breakdown runs, nests its parts and leaves the env's code as it found it
(tiny budgets; no timing asserted)."""

from __future__ import annotations

import json
from pathlib import Path

from frontier_marl.experiments.speed import bench_vector_step
from frontier_marl.sim import batch_engine


def test_the_breakdown_reports_every_part_and_restores_the_env(tmp_path: Path) -> None:
    kernels = (batch_engine.before_labelling, batch_engine.after_labelling)
    out = tmp_path / "step.json"
    assert bench_vector_step.main(["--worlds", "2", "--steps", "20", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    per_step = report["us_per_step"]
    assert set(per_step) == {part for part, _, _ in bench_vector_step.PARTS}
    assert all(value > 0 for part, value in per_step.items() if part != "autoresets")
    after = "after the labelling (clusters, slots, explored fraction, rewards)"
    assert per_step["step"] > per_step["mdp.step"] > per_step[after]
    assert (batch_engine.before_labelling, batch_engine.after_labelling) == kernels


def test_the_interleaved_step_cost_reports_both_figures() -> None:
    from frontier_marl.experiments.speed.bench_vector_env import interleaved_step_cost

    cost = interleaved_step_cost(2, 20, rounds=1)
    assert cost["n_envs"] == 2
    assert cost["us_per_step_alone"] > 0 and cost["us_per_step_interleaved"] > 0
