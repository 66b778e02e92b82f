"""The adapters' info dicts, built from the engine's typed step (one dict per robot).

Every value is a number or a fixed-shape numeric array, so tensor and replay-buffer clients
(TorchRL, Tianshou, Gymnasium's vector envs) can batch them. By level:

* ``mask``: ``action_mask`` (int8, ``(n_slots,)``);
* ``minimal``: adds ``explored_fraction`` (the threshold's basis), ``coverage`` (of the
  reachable free region), ``new_cells``, ``travelled``, ``step`` and ``end_reason`` (an int code,
  0 while the episode goes on; :data:`END_REASONS` names it);
* ``full`` (the default): adds ``slots`` (the robot's slot table packed as float64
  ``(n_slots, 10)``, columns :data:`SLOT_COLUMNS`; :func:`slot_table` unpacks it),
  ``target`` (int64 ``(2,)``, the cell it headed for, ``-1`` for none), ``position`` (int64
  ``(2,)``), ``padding`` and ``oscillation``;
* ``debug``: adds ``path`` (int64 ``(k, 2)``, the cells occupied this step, start included; its
  length varies, so it is left out of the other levels).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from frontier_marl.core.slots import SLOT_COLUMNS, SlotTable
from frontier_marl.sim.engine import ExplorationMDP, StepResult
from frontier_marl.sim.rewards import REASONS, reason_name

INFO_LEVELS = ("mask", "minimal", "full", "debug")

#: ``END_REASONS[code]`` is the name of the info's ``end_reason`` code: the bits 1 threshold,
#: 2 no_frontier (terminations), 4 padding, 8 no_progress, 16 step_limit (truncations, joined
#: by ``+``); 0 (``""``) while the episode goes on.
END_REASONS: tuple[str, ...] = REASONS

__all__ = [
    "END_REASONS",
    "INFO_LEVELS",
    "SLOT_COLUMNS",
    "StepInfo",
    "build_infos",
    "check_info_level",
    "reason_name",
    "slot_table",
]


class StepInfo(dict):  # type: ignore[type-arg]
    """One robot's info dict. ``copy.deepcopy`` of it is a shallow copy.

    SB3's ``DummyVecEnv`` deep-copies every info on every step, in case an env reuses and
    mutates them. This env never does: each step builds fresh values and never touches them
    again, so a shallow copy is as safe and far cheaper. Treat the values as read-only.
    """

    __slots__ = ()

    def __deepcopy__(self, memo: dict[int, Any]) -> StepInfo:
        return StepInfo(self)


def check_info_level(level: str, levels: tuple[str, ...] = INFO_LEVELS) -> str:
    if level not in levels:
        raise ValueError(f"info must be one of {list(levels)}, got {level!r}")
    return level


def slot_table(info: Mapping[str, Any]) -> SlotTable:
    """The robot's :class:`~frontier_marl.core.slots.SlotTable` from its info (``full`` or
    ``debug`` level): the packed ``slots`` with the ``action_mask``; a table is taken as is."""
    try:
        value = info["slots"]
        if isinstance(value, SlotTable):
            return value
        return SlotTable.from_packed(value, info["action_mask"])
    except (KeyError, TypeError) as exc:
        raise ValueError(
            "info must hold the robot's 'slots' table (the env's step info with info='full')"
        ) from exc


def build_infos(mdp: ExplorationMDP, result: StepResult | None, level: str) -> list[StepInfo]:
    """Per robot, the info after ``result`` (``None``: right after reset)."""
    world = mdp.world
    assert world is not None
    masks = mdp.action_masks()
    n = len(masks)
    if level == "mask":
        return [StepInfo(action_mask=mask) for mask in masks]
    fraction = mdp.explored
    reachable = mdp.cfg.reward.threshold_basis == "reachable"
    coverage = fraction if reachable else world.explored_fraction("reachable")
    travelled = world.travelled.tolist()
    new_cells = [0] * n if result is None else result.move.new_cells.tolist()
    reason = 0 if result is None else result.outcome.code
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
    positions = world.positions.copy()
    if result is None:
        targets = np.full((n, 2), -1, dtype=np.int64)
        padding = oscillation = [False] * n
    else:
        targets = result.targets.copy()
        padding, oscillation = result.padding.tolist(), result.oscillation.tolist()
    slots = mdp.packed_slots()
    for agent, info in enumerate(infos):
        info.update(
            slots=slots[agent],
            target=targets[agent],
            position=positions[agent],
            padding=padding[agent],
            oscillation=oscillation[agent],
        )
        if level == "debug":
            start = world.positions[agent][None, :].copy()
            info["path"] = start if result is None else result.move.paths[agent]
    return infos
