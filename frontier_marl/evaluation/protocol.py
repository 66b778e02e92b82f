"""The thesis's evaluation protocol as a library function.

:func:`evaluate` runs a policy for ``episodes`` episodes; episode ``i`` resets the env with seed
``seed + i`` (and the policy with the same seed). On a static map every episode shares the
layout drawn from the config's ``map_seed`` (recorded in the result) and only the start cell
changes; on dynamic maps each seed also draws a fresh layout. Reported, as in the thesis
(docs/thesis-mapping.md):

* total episode reward: mean and *population* standard deviation (numpy's default, the same as
  SB3's ``evaluate_policy``). With a team, an episode's reward is the mean over robots of each
  robot's return (the sum of its rewards over the episode); per-robot returns are kept too;
* terminations: episodes that ended by reaching the exploration threshold
  (``end_reason == "threshold"``), plus a count of every end reason;
* the action histogram: the share of each slot among all decisions of all robots;
* decision steps and cells travelled (the team's sum of ``travelled``) per episode;
* cells travelled when coverage of the reachable free region (info ``coverage``) first reaches
  each level of ``coverage_levels`` (default 0.90 and 0.99), with how many episodes got there;
* a coverage-versus-cells-travelled curve per episode (see :mod:`frontier_marl.evaluation.metrics`).

With a team (``n_agents > 1``) the result and its dict also hold the team metrics:

* ``makespan``: the longest single robot path (cells) at the episode's end; robots move at
  the same time, so this is the time the team took, in cell moves;
* ``makespan_to_coverage``: the longest single path when coverage first reaches each level
  (``cells_to_coverage`` stays the team's total cells travelled to that level);
* ``overlap``: :func:`~frontier_marl.evaluation.metrics.overlap_ratio` of the robots'
  ``seen`` masks at the episode's end (sum of the areas each robot perceived / their union
  - 1; 0 for one robot), when the env exposes its world;
* ``makespan_curve``: coverage versus the longest single path (coverage versus time), per
  episode; the row index of both curves is the decision step.

The env may be a dict of keyword arguments for :func:`frontier_marl.parallel_env`, a
zero-argument factory, or an env instance: a PettingZoo ``ParallelEnv`` or a single-robot
Gymnasium env (possibly wrapped, e.g. for a learned model). The policy is anything with the
:class:`~frontier_marl.evaluation.Policy` interface; wrap a plain ``obs -> action`` callable or an
SB3 model with :class:`~frontier_marl.evaluation.CallablePolicy` /
:class:`~frontier_marl.evaluation.ModelPolicy`.
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from frontier_marl.evaluation.metrics import (
    cells_to_coverage,
    coverage_curve,
    makespan_curve,
    overlap_ratio,
)
from frontier_marl.evaluation.records import (
    DEFAULT_LEVELS,
    EpisodeRecord,
    EvaluationResult,
    level_key,
)
from frontier_marl.policies.base import Policy
from frontier_marl.sim.rewards import reason_name

# --------------------------------------------------------------------------- env adapters


class _TeamView:
    """Runs a ParallelEnv or a single-robot Gymnasium env through one dict-based interface."""

    def __init__(self, env: Any) -> None:
        self.env = env
        self.single = isinstance(env, gym.Env)
        if self.single:
            self.agents = ["robot_0"]
            self.n_slots = int(env.action_space.n)
        else:
            self.agents = list(env.possible_agents)
            self.n_slots = int(env.action_space(self.agents[0]).n)

    def reset(self, seed: int) -> tuple[dict[str, Any], dict[str, Any]]:
        if self.single:
            obs, info = self.env.reset(seed=seed)
            return {"robot_0": obs}, {"robot_0": info}
        return self.env.reset(seed=seed)

    def step(self, actions: dict[str, int]) -> tuple[dict, dict, bool, dict]:
        """Returns observations, rewards, done, infos."""
        if self.single:
            obs, reward, terminated, truncated, info = self.env.step(actions["robot_0"])
            return (
                {"robot_0": obs},
                {"robot_0": float(reward)},
                bool(terminated or truncated),
                {"robot_0": info},
            )
        obs, rewards, terminations, truncations, infos = self.env.step(actions)
        done = all(terminations[a] or truncations[a] for a in rewards) or not self.env.agents
        return obs, rewards, done, infos

    def seen(self) -> np.ndarray | None:
        """The robots' (N, H, W) ``seen`` masks, or ``None`` if the env hides its world."""
        unwrapped = getattr(self.env, "unwrapped", self.env)
        try:
            world = unwrapped.world
        except (AttributeError, RuntimeError):
            return None
        seen = getattr(world, "seen", None)
        return None if seen is None else np.asarray(seen)


def _config_of(env: Any) -> Any:
    for candidate in (env, getattr(env, "unwrapped", None)):
        config = getattr(candidate, "config", None)
        if config is not None:
            return config
    return None


EnvSpec = Mapping[str, Any] | Callable[[], Any] | Any


def _build_env(env: EnvSpec) -> tuple[Any, bool]:
    """The env to run and whether this module created it (and so must close it)."""
    if isinstance(env, Mapping):
        import frontier_marl

        return frontier_marl.parallel_env(**dict(env)), True
    if isinstance(env, type) or (callable(env) and not hasattr(env, "reset")):
        return env(), True
    return env, False


# --------------------------------------------------------------------------- protocol


def run_episode(
    view: _TeamView,
    policy: Policy,
    seed: int,
    coverage_levels: Sequence[float] = DEFAULT_LEVELS,
    max_steps: int | None = None,
) -> EpisodeRecord:
    """One episode of ``policy`` from reset seed ``seed``."""
    policy.reset(seed)
    observations, infos = view.reset(seed)
    agents = list(observations)
    returns = dict.fromkeys(agents, 0.0)
    counts = np.zeros(view.n_slots, dtype=np.int64)
    robot_travelled = [[int(infos[a]["travelled"]) for a in agents]]
    coverage = [float(infos[agents[0]]["coverage"])]
    steps = 0
    done = False
    while not done and (max_steps is None or steps < max_steps):
        actions = policy.act_team(observations, infos)
        for agent in agents:
            slot = int(actions[agent])
            if 0 <= slot < view.n_slots:
                counts[slot] += 1
        observations, rewards, done, infos = view.step(actions)
        for agent in agents:
            returns[agent] += float(rewards[agent])
        steps += 1
        robot_travelled.append([int(infos[a]["travelled"]) for a in agents])
        coverage.append(float(infos[agents[0]]["coverage"]))
    last = infos[agents[0]]
    per_robot = np.asarray(robot_travelled, dtype=np.int64)
    travelled = per_robot.sum(axis=1).tolist()
    curve = coverage_curve(travelled, coverage)
    time_curve = makespan_curve(per_robot, coverage)
    robot_rewards = [returns[a] for a in agents]
    seen = view.seen()
    return EpisodeRecord(
        seed=seed,
        reward=float(np.mean(robot_rewards)),
        robot_rewards=robot_rewards,
        steps=steps,
        end_reason=reason_name(last.get("end_reason", 0)) if done else "max_steps",
        travelled=travelled[-1],
        coverage=coverage[-1],
        explored_fraction=float(last.get("explored_fraction", float("nan"))),
        action_counts=counts.tolist(),
        cells_to_coverage={
            level_key(level): cells_to_coverage(curve, level) for level in coverage_levels
        },
        curve=curve,
        robot_travelled=per_robot[-1].tolist(),
        makespan=int(per_robot[-1].max()),
        makespan_to_coverage={
            level_key(level): cells_to_coverage(time_curve, level) for level in coverage_levels
        },
        overlap=None if seen is None else overlap_ratio(seen),
        makespan_curve=time_curve,
    )


def evaluate(
    env: EnvSpec,
    policy: Policy,
    episodes: int = 30,
    seed: int = 0,
    *,
    map_mode: str | None = None,
    coverage_levels: Sequence[float] = DEFAULT_LEVELS,
    max_steps: int | None = None,
    on_episode: Callable[[int, EpisodeRecord], None] | None = None,
) -> EvaluationResult:
    """Run the evaluation protocol (see the module docstring).

    Args:
        env: kwargs for :func:`frontier_marl.parallel_env` (e.g. ``{"preset": "thesis-20x20",
            "map_mode": "static"}``), a zero-argument env factory, or an env instance.
        policy: a :class:`~frontier_marl.evaluation.Policy`; it is attached to the env once and
            reset with each episode's seed.
        episodes: number of episodes (>= 1).
        seed: episode ``i`` uses reset seed ``seed + i``.
        map_mode: ``static`` or ``dynamic``, merged into ``env`` when it is a kwargs dict.
        coverage_levels: coverage levels for the cells-travelled metric, each in (0, 1].
        max_steps: optional cap on decision steps per episode (end reason ``max_steps``);
            ``None`` runs until the env ends the episode.
        on_episode: called with ``(i, record)`` after each episode (e.g. a progress bar).
    """
    episodes, seed = _checked_counts(episodes, seed)
    env = _with_map_mode(env, map_mode)
    _check_limits(coverage_levels, max_steps)
    instance, owned = _build_env(env)
    try:
        view = _TeamView(instance)
        policy.attach(instance)
        records = []
        for i in range(episodes):
            record = run_episode(view, policy, seed + i, coverage_levels, max_steps)
            records.append(record)
            if on_episode is not None:
                on_episode(i, record)
    finally:
        if owned:
            instance.close()
    config = _config_of(instance)
    config_dict = map_mode = map_seed = None
    if config is not None:
        from frontier_marl.config import config_to_dict

        config_dict = config_to_dict(config)
        map_mode = config.map_mode
        map_seed = config.map_seed if config.map_mode == "static" else None
    return EvaluationResult(
        policy=getattr(policy, "name", type(policy).__name__),
        seed=seed,
        n_slots=view.n_slots,
        n_agents=len(view.agents),
        coverage_levels=tuple(float(level) for level in coverage_levels),
        episodes=records,
        config=config_dict,
        map_mode=map_mode,
        map_seed=map_seed,
    )


def _checked_counts(episodes: Any, seed: Any) -> tuple[int, int]:
    """``episodes`` (>= 1) and ``seed`` (>= 0) as ints, or a ValueError naming the bad one."""
    if isinstance(episodes, bool) or not isinstance(episodes, numbers.Integral) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise ValueError(f"seed must be an integer >= 0, got {seed!r}")
    return int(episodes), int(seed)


def _with_map_mode(env: EnvSpec, map_mode: str | None) -> EnvSpec:
    """``env`` with ``map_mode`` merged in (env kwargs only)."""
    if map_mode is None:
        return env
    if map_mode not in ("static", "dynamic"):
        raise ValueError(f"map_mode must be 'static' or 'dynamic', got {map_mode!r}")
    if not isinstance(env, Mapping):
        raise ValueError("map_mode= needs env kwargs; set it on the env you pass instead")
    return {**env, "map_mode": map_mode}


def _check_limits(coverage_levels: Sequence[float], max_steps: int | None) -> None:
    for level in coverage_levels:
        if not 0.0 < level <= 1.0:
            raise ValueError(f"coverage_levels must lie in (0, 1], got {level!r}")
    if max_steps is not None and max_steps < 1:
        raise ValueError(f"max_steps must be >= 1 or None, got {max_steps!r}")
