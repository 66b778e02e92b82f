"""The movement transition in one compiled call: plan, walk in sub-steps, sense.

Multi-robot rules (documented in docs/environment.md):

* Robots move in sub-steps of one cell. In each sub-step they act in agent order; a robot
  whose next cell is occupied by another robot *at that moment* waits (its path is kept).
  Hence no two robots ever share a cell, and two robots can never swap cells (the first to
  act finds the other's cell occupied and waits, then so does the second).
* A robot senses at every cell it enters. A cell newly known in a sub-step is credited to the
  first robot (in agent order) that sensed it, so the robots' ``new_cells`` add up to the
  number of cells the team revealed.
* Paths are planned with A* on the known-free cells (other robots are not obstacles; a
  blocked robot waits). A plan is reused while the belief is unchanged and the target is the
  same, which keeps it optimal (a suffix of a shortest path is a shortest path).
"""

from __future__ import annotations

import numpy as np

from frontier_marl.core.compiled import compiled
from frontier_marl.core.grid import FREE
from frontier_marl.core.planning import astar_into
from frontier_marl.core.sensing import reveal


@compiled
def walk(
    true_grid: np.ndarray,
    belief: np.ndarray,
    seen: np.ndarray,
    positions: np.ndarray,
    travelled: np.ndarray,
    goals: np.ndarray,
    plans: np.ndarray,
    plan_meta: np.ndarray,
    version: int,
    cells_per_step: int,
    offsets: np.ndarray,
    between: np.ndarray,
    new_cells: np.ndarray,
    walked: np.ndarray,
    walked_len: np.ndarray,
    reached: np.ndarray,
    search: tuple,
) -> int:
    """``World.move`` (see the module docstring); returns the new belief version.

    State (changed in place): ``belief``, ``seen`` (N, H, W), ``positions`` and ``travelled``;
    the plan cache: ``plans[a, first:end]`` is robot a's remaining path and ``plan_meta[a]`` =
    (goal row, goal col, first, end, belief version planned on; -1 when robot a has no plan).
    ``goals[a]`` is robot a's target, row -1 to stay; ``cells_per_step`` is -1 for the whole
    path. Sensing is :func:`reveal` with ``offsets``/``between``. Outputs:
    ``new_cells`` (N,), ``walked[a, :walked_len[a]]`` (the cells robot a occupied, start
    included) and ``reached`` (N,). ``search``: the planner's scratch
    (:func:`~frontier_marl.core.planning.path_search_scratch`).
    """
    n = positions.shape[0]
    first = np.zeros(n, dtype=np.int64)  # index in plans[a] of the next cell to enter
    end = np.zeros(n, dtype=np.int64)  # one past the last cell this step may enter
    path_length = np.zeros(n, dtype=np.int64)  # moves left to the target
    for a in range(n):
        new_cells[a] = 0
        reached[a] = False
        walked[a, 0, 0] = positions[a, 0]
        walked[a, 0, 1] = positions[a, 1]
        walked_len[a] = 1
        goal_row = goals[a, 0]
        goal_col = goals[a, 1]
        if goal_row < 0:
            continue
        row = positions[a, 0]
        col = positions[a, 1]
        start = plan_meta[a, 2]
        cached = (
            plan_meta[a, 4] == version
            and plan_meta[a, 0] == goal_row
            and plan_meta[a, 1] == goal_col
            and plan_meta[a, 3] > start
            and plans[a, start, 0] == row
            and plans[a, start, 1] == col
        )
        if not cached:
            length = astar_into(belief, FREE, row, col, goal_row, goal_col, plans[a], search)
            if length == 0:
                plan_meta[a, 4] = -1
                continue
            plan_meta[a, 0] = goal_row
            plan_meta[a, 1] = goal_col
            plan_meta[a, 2] = 0
            plan_meta[a, 3] = length
            plan_meta[a, 4] = version
            start = 0
        path_length[a] = plan_meta[a, 3] - start - 1
        first[a] = start + 1
        end[a] = plan_meta[a, 3]
        if cells_per_step >= 0:
            end[a] = min(end[a], start + 1 + cells_per_step)
    progress = np.zeros(n, dtype=np.int64)
    sub_step = 0
    while cells_per_step < 0 or sub_step < cells_per_step:
        moved = False
        for a in range(n):
            index = first[a] + progress[a]
            if index >= end[a]:
                continue
            row = plans[a, index, 0]
            col = plans[a, index, 1]
            occupied = False
            for b in range(n):
                if b != a and positions[b, 0] == row and positions[b, 1] == col:
                    occupied = True
                    break
            if occupied:  # wait; the path is kept
                continue
            positions[a, 0] = row
            positions[a, 1] = col
            walked[a, walked_len[a], 0] = row
            walked[a, walked_len[a], 1] = col
            walked_len[a] += 1
            progress[a] += 1
            count = reveal(true_grid, belief, seen[a], row, col, offsets, between)
            if count:
                version += 1
            new_cells[a] += count
            moved = True
        sub_step += 1
        if not moved:
            break
    for a in range(n):
        if progress[a]:
            plan_meta[a, 2] += progress[a]
        travelled[a] += progress[a]
        reached[a] = path_length[a] > 0 and path_length[a] == progress[a]
    return version
