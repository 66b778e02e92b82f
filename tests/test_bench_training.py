"""The speed benchmarks with tiny budgets: their reports are consistent."""

from __future__ import annotations

import json
from pathlib import Path

from frontier_marl.experiments.speed import bench_env, bench_labelling, bench_training


def test_stage_report_is_consistent(tmp_path: Path) -> None:
    out = tmp_path / "speed.json"
    assert bench_training.main(["config01", "--steps", "600", "--stages", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["steps"] == 600
    shares = [report[k] for k in report if k.startswith("share_")]
    assert abs(sum(shares) - 1.0) < 0.01  # env + vector layers + gradient steps + rest
    stages = report["stages"]
    assert set(stages) == {
        "before_labelling",
        "label_stale",
        "after_labelling",
        "observations",
        "build_infos",
        "reset",
    }
    assert stages["before_labelling"]["calls"] == 600 - 1  # one per env step, the first left out
    assert stages["reset"]["calls"] >= 1
    # The stages run inside the env step, so together they take less time than it does.
    inside_step = sum(stages[k]["us_per_env_step"] for k in stages if k not in ("reset",))
    assert 0 < inside_step < report["us_per_env_step"] + 1.0


def test_benchmark_leaves_the_env_unpatched(tmp_path: Path) -> None:
    from frontier_marl.core import worlds
    from frontier_marl.sim import batch_engine, engine

    def patchable() -> tuple[object, ...]:
        return (
            worlds.Worlds.label_stale,
            batch_engine.after_labelling,
            engine.ExplorationMDP.reset,
        )

    before = patchable()
    bench_training.main(["config01", "--steps", "200", "--stages"])
    assert patchable() == before


def test_labelling_benchmark_counts(tmp_path: Path) -> None:
    out = tmp_path / "labelling.json"
    assert bench_labelling.main(["--steps", "300", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    rollout = report["rollout"]
    assert rollout["steps"] == 300
    assert 0 < rollout["labellings"] <= 300 + 300  # at most one per step and one per reset
    assert 0 <= rollout["same_frontier"] < rollout["labellings"]
    assert all(cost > 0 for cost in report["us_per_call"].values())
    assert list(report["tiled_vs_stacked"]) == [
        f"{n} x {s}x{s}" for n, s in bench_labelling.BATCHES
    ]
    assert all(row["tiled_us"] > 0 for row in report["tiled_vs_stacked"].values())
    from scipy import ndimage

    from frontier_marl.core import frontiers

    assert frontiers.ndimage.label is ndimage.label  # the counting wrapper was removed


def test_env_share_interleaves_equal_runs() -> None:
    report = bench_env.dqn_env_share(600, 3)
    assert report["steps"] == 600 and report["chunks"] == 3
    assert report["seconds_null"] > 0 and report["seconds_env"] > 0
    expected = (report["seconds_env"] - report["seconds_null"]) / report["seconds_env"]
    assert report["env_share"] == expected
    assert len(report["env_share_by_chunk"]) == 3
    assert report["env_share_standard_error"] >= 0
