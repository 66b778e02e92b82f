"""The incremental-step counts (issue 34 §1's "measure which pays"): a hand-made window, and
the distance-field count on random play (tiny budgets; no timing)."""

from __future__ import annotations

import numpy as np

from frontier_marl.experiments.speed import incremental_potential
from frontier_marl.experiments.speed.bench_vector_env import CONFIG01


def test_the_window_is_the_box_around_the_changes_widened_by_one_and_clipped() -> None:
    changed = np.zeros((6, 7), dtype=bool)
    assert incremental_potential.window_area(changed) == 0
    changed[2, 3] = True
    assert incremental_potential.window_area(changed) == 9
    changed[0, 6] = True  # rows 0-3, cols 2-6 after clipping
    assert incremental_potential.window_area(changed) == 4 * 5


def test_a_robot_that_moves_changes_every_reachable_distance() -> None:
    """Each decision moves the robot by one cell on a bipartite grid, so every cell reachable
    before and after is one step nearer or farther: an incremental field saves nothing."""
    row = incremental_potential.potential(CONFIG01, worlds=2, steps=40)
    assert row["world_steps"] > 0
    assert row["moved"] >= 0.9
    assert 0.9 <= row["distance_changed_share"] <= 1.0
    assert 0 < row["window_share"] < 0.5
    assert row["frontier_changed"] <= row["window"]


def test_the_floor_times_every_kernel_of_a_changed_world() -> None:
    row = incremental_potential.potential(CONFIG01, worlds=2, steps=5)
    kernels = row["kernel_cpu_us"]
    assert set(kernels) == {
        "frontier masks",
        "scipy label",
        "clusters and gains",
        "slots (a distance field per robot)",
        "explored fraction",
    }
    assert all(value >= 0 for value in kernels.values()) and row["step_cpu_us"] > 0
