"""benchmarks/bench_revisions.py with a tiny budget: it times each tree in its own process."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # times two source trees in subprocesses

REPO = Path(__file__).resolve().parents[1]


def test_comparing_the_checkout_with_itself(tmp_path: Path) -> None:
    out = tmp_path / "revisions.json"
    script = REPO / "benchmarks" / "bench_revisions.py"
    args = ["--rounds", "2", "--steps", "200", "--dqn-steps", "0", "--json", str(out)]
    subprocess.run([sys.executable, str(script), str(REPO), *args], check=True, timeout=300)
    report = json.loads(out.read_text())
    assert len(report["runs"]["before"]) == len(report["runs"]["after"]) == 2
    for rows in report["runs"].values():
        for row in rows:
            assert Path(row["package"]).is_relative_to(REPO)
            assert row["step_us"] > 0 and row["step_us_training"] > 0
            assert row["parallel_step_us"] > 0 and row["parallel_step_cpu_us"] > 0
    assert set(report["median_ratio_after_before"]) == {
        "step_us",
        "step_cpu_us",
        "step_us_training",
        "step_cpu_us_training",
        "parallel_step_us",
        "parallel_step_cpu_us",
    }
