"""Frontier-selection policies behind one interface, and the registry of heuristics by name.

A :class:`Policy` picks one cluster slot per robot. It works with the single-robot Gymnasium
env (:meth:`Policy.act`) and with every robot of the PettingZoo ParallelEnv
(:meth:`Policy.act_team`)::

    policy = make_policy("greedy-distance")
    policy.reset(seed=0)
    obs, infos = par_env.reset(seed=0)
    actions = policy.act_team(obs, infos)          # {"robot_0": slot, ...}

The heuristics are in :mod:`frontier_marl.policies.heuristics` (one robot at a time) and
:mod:`frontier_marl.policies.team` (the whole team jointly). With no live cluster every
heuristic returns slot 0 (the env's idle action).

Learned models plug in through :class:`CallablePolicy` (any ``obs -> action`` callable) or
:class:`ModelPolicy` (anything with SB3's ``predict(obs, deterministic=...)``).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from frontier_marl.envs.infos import slot_table
from frontier_marl.envs.layout import ObservationLayout

Info = Mapping[str, Any]


class Policy:
    """Base class: one decision per robot from its observation and step info.

    Subclasses override :meth:`act` (one robot) or :meth:`act_team` (all robots at once, for
    joint policies). ``deterministic`` tells evaluators whether two runs with the same seeds
    give the same actions.
    """

    name: str = "policy"
    deterministic: bool = True

    def reset(self, seed: int | None = None) -> None:
        """Start a new episode; ``seed`` reseeds any internal randomness."""

    def attach(self, env: Any) -> None:
        """Give the policy the env it is about to act in (default: ignored)."""

    def act(self, obs: Any, info: Info) -> int:
        """The slot chosen by one robot."""
        raise NotImplementedError

    def act_team(
        self, observations: Mapping[str, Any], infos: Mapping[str, Info]
    ) -> dict[str, int]:
        """One slot per robot (the keys of ``observations``), each robot deciding alone."""
        return {agent: self.act(obs, infos[agent]) for agent, obs in observations.items()}

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r})"


#: ``commit`` values of the heuristics: re-decide every step (the thesis's greedy rule), keep
#: the previous target while the last step revealed no new cell, keep it until it is
#: reached or no longer offered (decide only on arrival), or re-decide every step until the
#: robot is caught in a cycle, then keep it until a new cell is seen.
COMMIT_RULES: tuple[str, ...] = ("none", "until-progress", "until-reached", "on-cycle")


def check_commit(commit: str) -> str:
    if commit not in COMMIT_RULES:
        raise ValueError(f"commit must be one of {list(COMMIT_RULES)}, got {commit!r}")
    return commit


class HeuristicPolicy(Policy):
    """A policy that applies :meth:`choose` to each robot's info independently.

    Args:
        commit: ``none`` re-decides at every step. ``until-progress`` keeps the target the robot
            headed for in the last step (``info["target"]``) while that step revealed no new
            cell (``info["new_cells"] == 0``) and the target is still offered in a slot: the
            clusters have not changed, so the robot walks on instead of turning back and forth
            between two clusters (docs/calibration.md, "Livelocks"). ``until-reached`` keeps
            it whatever the step revealed, until it is reached or no longer offered.
            ``on-cycle`` re-decides every step as ``none`` does until the robot stands again on
            a cell it stood on since the last new cell was seen (:class:`CycleWatch`): from
            there it would make the same choices again and turn in a cycle until the
            no-progress rule ends the episode, so from then until a new cell is seen it keeps
            its target (while offered). With a team, "a new cell" is one any robot revealed.
    """

    def __init__(self, commit: str = "none") -> None:
        self.commit = check_commit(commit)
        self._watch = CycleWatch()

    def reset(self, seed: int | None = None) -> None:
        self._watch.clear()

    def act(self, obs: Any, info: Info) -> int:
        if self.commit == "on-cycle":
            kept = self._watch.kept(None, info, bool(info["new_cells"]))
            return int(self.choose(info)) if kept is None else kept
        if self.commit != "none":
            kept = kept_slot(info, self.commit)
            if kept is not None:
                return kept
        return int(self.choose(info))

    def act_team(
        self, observations: Mapping[str, Any], infos: Mapping[str, Info]
    ) -> dict[str, int]:
        if self.commit != "on-cycle":
            return super().act_team(observations, infos)
        progressed = any(infos[agent]["new_cells"] for agent in observations)
        chosen = {}
        for agent in observations:
            kept = self._watch.kept(agent, infos[agent], progressed)
            chosen[agent] = int(self.choose(infos[agent])) if kept is None else kept
        return chosen

    def choose(self, info: Info) -> int:
        raise NotImplementedError


def kept_slot(info: Info, commit: str = "until-progress") -> int | None:
    """The slot of the robot's previous target while it is still offered (and, for
    ``until-progress``, while its last step revealed nothing), else ``None``."""
    if commit == "until-progress" and info["new_cells"]:
        return None
    return previous_target_slot(info)


class CycleWatch:
    """Per robot: the cells it has stood on since the last new cell was seen, and whether it
    has stood on one of them again since (the ``on-cycle`` commit rule).

    A heuristic that decides from the slot table alone, standing again on a cell with the
    belief unchanged, sees the slots it saw there and makes the same choice: one robot is then
    in a cycle that only the no-progress rule ends (docs/calibration.md, "Table 6.5"). Robots
    are told apart by a key (the agent name); a new episode (``info["step"] == 0``) or a step
    that revealed a cell (``progressed``) clears the robot's record.
    """

    def __init__(self) -> None:
        self._cells: dict[Any, set[tuple[int, int]]] = {}
        self._cycling: set[Any] = set()

    def clear(self) -> None:
        self._cells.clear()
        self._cycling.clear()

    def cycling(self, key: Any, info: Info, progressed: bool) -> bool:
        """Record the robot's cell; whether it has stood on a cell twice since progress."""
        if progressed or info["step"] == 0:
            self._cells.pop(key, None)
            self._cycling.discard(key)
        cells = self._cells.setdefault(key, set())
        cell = (int(info["position"][0]), int(info["position"][1]))
        if cell in cells:
            self._cycling.add(key)
        cells.add(cell)
        return key in self._cycling

    def kept(self, key: Any, info: Info, progressed: bool) -> int | None:
        """The slot of the robot's previous target while it is cycling (and that target is
        still offered), else ``None``."""
        return previous_target_slot(info) if self.cycling(key, info, progressed) else None


def previous_target_slot(info: Info) -> int | None:
    """The slot offering the target the robot headed for in its last step, if any."""
    previous = target_cell(info.get("target"))
    if previous is None:
        return None
    table = slot_table(info)
    for slot in range(table.live):
        if (table.target[slot, 0], table.target[slot, 1]) == previous:
            return slot
    return None


def target_cell(target: Any) -> tuple[int, int] | None:
    """An info's ``target`` (row -1: none; ``None`` and tuples taken too) as a cell or
    ``None``."""
    if target is None or int(target[0]) < 0:
        return None
    return int(target[0]), int(target[1])


def first_by(*keys: np.ndarray) -> int:
    """The index that sorts first by ``keys`` (the first key most significant; ties: lowest)."""
    return int(np.lexsort((np.arange(len(keys[0])), *reversed(keys)))[0])


class CallablePolicy(Policy):
    """Wraps any ``obs -> action`` callable (e.g. a trained network) as a :class:`Policy`."""

    def __init__(self, fn: Callable[[Any], Any], name: str = "callable") -> None:
        self.fn = fn
        self.name = name

    def act(self, obs: Any, info: Info) -> int:
        return _as_slot(self.fn(obs))


class ModelPolicy(Policy):
    """Wraps a model with SB3's ``predict(obs, deterministic=...) -> (action, state)``; a
    model whose ``predict`` takes ``action_masks`` (sb3-contrib's ``MaskablePPO``) gets the
    env's action mask (``info["action_mask"]``). A deterministic model whose policy masks
    invalid slots itself (``policy.masks_invalid_slots``: the slot scorers) is not asked when
    one slot is valid (a commitment, the last cluster): it would take that slot anyway. An
    observation in the classic layout (``{"observation", "action_mask"}``) is turned back into
    the flat layout of the model's observation space first."""

    def __init__(self, model: Any, name: str = "model", deterministic: bool = True) -> None:
        if not hasattr(model, "predict"):
            raise ValueError(f"model must have a predict() method, got {type(model).__name__}")
        self.model = model
        self.name = name
        self.deterministic = deterministic
        self.takes_masks = "action_masks" in inspect.signature(model.predict).parameters
        space = getattr(model, "observation_space", None)
        self.layout = None if space is None else ObservationLayout(space, "flat")
        masks_itself = getattr(getattr(model, "policy", None), "masks_invalid_slots", False)
        self.skips_forced = deterministic and masks_itself is True

    def act(self, obs: Any, info: Info) -> int:
        if self.skips_forced and "action_mask" in info:
            valid = np.flatnonzero(info["action_mask"])
            if len(valid) == 1:
                return int(valid[0])
        masks = {}
        if self.takes_masks and "action_mask" in info:
            masks["action_masks"] = np.asarray(info["action_mask"], dtype=bool)
        if self.layout is not None:
            obs = self.layout.unwrap(obs)  # a model takes the flat layout it was trained on
        action, _ = self.model.predict(obs, deterministic=self.deterministic, **masks)
        return _as_slot(action)


def _as_slot(action: Any) -> int:
    value = np.asarray(action)
    if value.size != 1:
        raise ValueError(f"a policy must return one slot index, got shape {value.shape}")
    return int(value.reshape(()).item())


#: Heuristic name (as used on the command line) -> class.
