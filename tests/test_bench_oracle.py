"""benchmarks/bench_oracle.py: the timed process imports the tree it is given."""

from __future__ import annotations

from pathlib import Path

import pytest

from frontier_marl.experiments.speed.bench_oracle import run_tree

ROOT = Path(__file__).resolve().parent.parent


def test_a_tree_is_timed_with_its_own_package() -> None:
    report = run_tree(ROOT, "random-20", 1)
    assert report["seconds"] > 0
    assert report["t99"] == [88.0]  # validation episode 0 (as in test_branching)


def test_a_folder_without_the_package_is_refused(tmp_path: Path) -> None:
    with pytest.raises(RuntimeError, match="imported another frontier_marl"):
        run_tree(tmp_path, "random-20", 1)
