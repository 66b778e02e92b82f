"""The adapters' info dicts, built from the engine's typed step (one dict per robot).

``full`` (the default) holds, per robot: ``explored_fraction`` (the threshold's basis),
``coverage`` (of the reachable free region), ``new_cells``, ``action_mask``, ``slots`` (the
robot's :class:`~frontier_marl.core.slots.SlotTable`: cluster, centroid, target, Euclidean
distance, path length, size and gain of each slot, for the slots its next action refers to),
``path`` (cells occupied this step, start included), ``target`` (the cell it headed for, or
``None``), ``position``, ``travelled``, ``padding``, ``oscillation``, ``step`` and
``end_reason``. ``minimal`` keeps only what training and the evaluation protocol read:
``explored_fraction``, ``coverage``, ``new_cells``, ``action_mask``, ``travelled``, ``step`` and
``end_reason``.
"""

from __future__ import annotations

from typing import Any

from frontier_marl.sim.engine import ExplorationMDP, StepResult

INFO_LEVELS = ("full", "minimal")


class StepInfo(dict):  # type: ignore[type-arg]
    """One robot's info dict. ``copy.deepcopy`` of it is a shallow copy.

    SB3's ``DummyVecEnv`` deep-copies every info on every step, in case an env reuses and
    mutates them. This env never does: each step builds fresh values and never touches them
    again, so a shallow copy is as safe and far cheaper. Treat the values as read-only.
    """

    __slots__ = ()

    def __deepcopy__(self, memo: dict[int, Any]) -> StepInfo:
        return StepInfo(self)


def check_info_level(level: str) -> str:
    if level not in INFO_LEVELS:
        raise ValueError(f"info must be one of {list(INFO_LEVELS)}, got {level!r}")
    return level


def build_infos(mdp: ExplorationMDP, result: StepResult | None, level: str) -> list[StepInfo]:
    """Per robot, the info after ``result`` (``None``: right after reset)."""
    world = mdp.world
    assert world is not None
    fraction = world.explored_fraction(mdp.cfg.reward.threshold_basis)
    coverage = world.explored_fraction("reachable")
    travelled = world.travelled.tolist()
    masks = mdp.action_masks()
    n = len(masks)
    new_cells = [0] * n if result is None else result.move.new_cells.tolist()
    reason = "" if result is None else result.outcome.reason
    common = {"explored_fraction": fraction, "coverage": coverage, "step": mdp.steps}
    infos = [
        StepInfo(
            common,
            new_cells=new_cells[agent],
            action_mask=masks[agent],
            travelled=travelled[agent],
            end_reason=reason,
        )
        for agent in range(n)
    ]
    if level == "minimal":
        return infos
    positions = [tuple(cell) for cell in world.positions.tolist()]
    if result is None:
        paths = [world.positions[agent][None, :].copy() for agent in range(n)]
        targets: list[tuple[int, int] | None] = [None] * n
        padding = oscillation = [False] * n
    else:
        paths = result.move.paths
        targets = [None if row < 0 else (row, col) for row, col in result.targets.tolist()]
        padding, oscillation = result.padding.tolist(), result.oscillation.tolist()
    tables = mdp.slot_tables()
    for agent, info in enumerate(infos):
        info.update(
            slots=tables[agent],
            path=paths[agent],
            target=targets[agent],
            position=positions[agent],
            padding=padding[agent],
            oscillation=oscillation[agent],
        )
    return infos
