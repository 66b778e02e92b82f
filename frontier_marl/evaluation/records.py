"""Evaluation records: what one episode produced, and the protocol's summary over episodes.

:class:`EpisodeRecord` holds one episode's return, steps, end reason, travel, coverage curve
and (teams) makespan and overlap; :class:`EvaluationResult` holds the records and computes the
protocol's statistics (see :mod:`frontier_marl.evaluation.protocol`); both turn into
JSON-able dicts.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from frontier_marl.evaluation.metrics import action_shares, mean_std

DEFAULT_LEVELS: tuple[float, ...] = (0.90, 0.99)


def level_key(level: float) -> str:
    """The JSON key of a coverage level, e.g. ``0.9 -> "0.90"``."""
    return f"{level:.2f}"


@dataclass
class EpisodeRecord:
    """What one evaluation episode produced."""

    seed: int
    reward: float  # team mean of the robots' returns (= the return with one robot)
    robot_rewards: list[float]
    steps: int
    end_reason: str
    travelled: int  # team total
    coverage: float  # final coverage of the reachable free region
    explored_fraction: float  # final explored fraction (the threshold's basis)
    action_counts: list[int]
    cells_to_coverage: dict[str, float | None]  # level_key -> cells travelled, None = never
    curve: np.ndarray  # (L, 2) cells travelled, coverage
    robot_travelled: list[int] = field(default_factory=list)  # per robot, at the end
    makespan: int = 0  # longest single robot path at the end
    makespan_to_coverage: dict[str, float | None] = field(default_factory=dict)
    overlap: float | None = None  # overlap ratio of the robots' seen masks at the end
    makespan_curve: np.ndarray | None = None  # (L, 2) longest single path, coverage

    @property
    def is_team(self) -> bool:
        return len(self.robot_travelled) > 1

    @property
    def reached_threshold(self) -> bool:
        return self.end_reason == "threshold"

    def to_dict(self, curve: bool = True) -> dict[str, Any]:
        out: dict[str, Any] = {
            "seed": self.seed,
            "reward": self.reward,
            "robot_rewards": list(self.robot_rewards),
            "steps": self.steps,
            "end_reason": self.end_reason,
            "travelled": self.travelled,
            "coverage": self.coverage,
            "explored_fraction": self.explored_fraction,
            "action_counts": list(self.action_counts),
            "cells_to_coverage": dict(self.cells_to_coverage),
        }
        if self.is_team:
            out["robot_travelled"] = list(self.robot_travelled)
            out["makespan"] = self.makespan
            out["makespan_to_coverage"] = dict(self.makespan_to_coverage)
            out["overlap"] = self.overlap
        if curve:
            out["curve"] = _curve_list(self.curve)
            if self.is_team and self.makespan_curve is not None:
                out["makespan_curve"] = _curve_list(self.makespan_curve)
        return out


def _curve_list(curve: np.ndarray) -> list[list[float]]:
    return [[int(t), round(float(c), 6)] for t, c in curve]


def _level_stats(level: float, values: list[float | None]) -> dict[str, Any]:
    """Episodes that reached ``level`` and the mean/std of ``values`` over those."""
    reached = [v for v in values if v is not None]
    mean, std = mean_std(reached)
    return {
        "level": level,
        "reached": len(reached),
        "mean": None if not reached else mean,
        "std": None if not reached else std,
        "per_episode": values,
    }


@dataclass
class EvaluationResult:
    """Per-episode records and the protocol's summary statistics."""

    policy: str
    seed: int
    n_slots: int
    n_agents: int
    coverage_levels: tuple[float, ...]
    episodes: list[EpisodeRecord]
    config: dict[str, Any] | None = None
    map_mode: str | None = None
    map_seed: int | None = None  # the static layout's seed; None for dynamic maps
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def rewards(self) -> list[float]:
        return [e.reward for e in self.episodes]

    @property
    def mean_reward(self) -> float:
        return mean_std(self.rewards)[0]

    @property
    def std_reward(self) -> float:
        return mean_std(self.rewards)[1]

    @property
    def terminations(self) -> int:
        """Episodes that ended by reaching the exploration threshold."""
        return sum(e.reached_threshold for e in self.episodes)

    @property
    def end_reasons(self) -> dict[str, int]:
        return dict(sorted(Counter(e.end_reason for e in self.episodes).items()))

    @property
    def action_counts(self) -> list[int]:
        counts = np.zeros(self.n_slots, dtype=np.int64)
        for e in self.episodes:
            counts += np.asarray(e.action_counts, dtype=np.int64)
        return counts.tolist()

    @property
    def action_shares(self) -> list[float]:
        return action_shares(self.action_counts)

    def stat(self, name: str) -> tuple[float, float]:
        """Mean and population std of a per-episode number (``steps``, ``travelled``...)."""
        return mean_std([getattr(e, name) for e in self.episodes])

    def cells_to(self, level: float) -> dict[str, Any]:
        """Cells travelled to reach ``level``: episodes that got there, mean/std over those."""
        key = level_key(level)
        return _level_stats(level, [e.cells_to_coverage.get(key) for e in self.episodes])

    def makespan_to(self, level: float) -> dict[str, Any]:
        """Longest single robot path when coverage first reaches ``level`` (as
        :meth:`cells_to`)."""
        key = level_key(level)
        return _level_stats(level, [e.makespan_to_coverage.get(key) for e in self.episodes])

    def team_summary(self) -> dict[str, Any]:
        """The team metrics of :meth:`to_dict` (makespan, makespan to each level, overlap)."""
        makespan_mean, makespan_std = self.stat("makespan")
        overlaps = [e.overlap for e in self.episodes if e.overlap is not None]
        overlap_mean, overlap_std = mean_std(overlaps)
        return {
            "mean_makespan": makespan_mean,
            "std_makespan": makespan_std,
            "makespan_to_coverage": {
                level_key(level): self.makespan_to(level) for level in self.coverage_levels
            },
            "mean_overlap": overlap_mean if overlaps else None,
            "std_overlap": overlap_std if overlaps else None,
        }

    def to_dict(self, curves: bool = True) -> dict[str, Any]:
        """A JSON-able summary row plus the per-episode records (with curves if asked)."""
        steps_mean, steps_std = self.stat("steps")
        travelled_mean, travelled_std = self.stat("travelled")
        coverage_mean, _ = self.stat("coverage")
        return {
            "policy": self.policy,
            "episodes": len(self.episodes),
            "seed": self.seed,
            "seeds": [e.seed for e in self.episodes],
            "n_agents": self.n_agents,
            "n_slots": self.n_slots,
            "map_mode": self.map_mode,
            "map_seed": self.map_seed,
            "mean_reward": self.mean_reward,
            "std_reward": self.std_reward,
            "rewards": self.rewards,
            "terminations": self.terminations,
            "end_reasons": self.end_reasons,
            "action_counts": self.action_counts,
            "action_shares": self.action_shares,
            "mean_steps": steps_mean,
            "std_steps": steps_std,
            "mean_travelled": travelled_mean,
            "std_travelled": travelled_std,
            "mean_final_coverage": coverage_mean,
            "cells_to_coverage": {
                level_key(level): self.cells_to(level) for level in self.coverage_levels
            },
            **(self.team_summary() if self.n_agents > 1 else {}),
            "config": self.config,
            **self.extra,
            "per_episode": [e.to_dict(curve=curves) for e in self.episodes],
        }
