"""The exploration-efficiency benchmark (``frontier-marl benchmark``): map families and runs.

A :class:`MapFamily` is a generator of maps with fixed held-out episode seeds; the four built-in
families (:data:`FAMILIES`) draw a fresh layout per episode, a family of loaded maps
(:func:`map_family`) cycles its episodes through its files. Every policy of a run faces the same
episodes: episode ``i`` of a family uses reset seed ``heldout[i]`` (and, for loaded maps, map
``i mod M``), and the reset seed alone draws the layout and the start cells, whatever the
observation settings. The episode settings are the same for every policy
(:func:`episode_settings`): the episode ends at 99 % of the reachable free cells known, or at a
generous limit scaled to the map; ``cells_per_step`` (how far one decision moves a robot) is
the family's, for every policy alike.

Heuristics see every reachable cluster (``n_slots`` = :data:`HEURISTIC_SLOTS`, the most the env
allows; decisions where all slots were full are counted in ``saturated_decisions``). Their
``commit`` rule is :func:`default_commit`'s: ``until-progress`` for one robot (it prevents the
livelocks of re-deciding every cell), ``none`` for teams (a blocked robot that keeps its target
can deadlock head-on with a teammate in a corridor while nothing new is seen). A learned model
keeps its own observation settings (:data:`OBSERVATION_KEYS`, from its saved metadata) and takes
everything else (map, sensor, movement, episode end) from the family.

One episode (:class:`EpisodeTask`: a policy, a world, a reset seed) is the unit of work: a run
plays its episodes with :func:`~frontier_marl.utils.parallel.map_tasks`, in this process, in
worker processes (``jobs``) or on a Ray cluster (``ray_address``), each with a fresh policy and
env (:func:`play_episode`), and reassembles them in order: the same rows wherever they ran. The
policies are in :mod:`~frontier_marl.evaluation.benchmark.contenders` (re-exported here).
Statistics (T99, T90, success, the paired difference to the best heuristic) are in
:mod:`frontier_marl.evaluation.benchmark.stats`.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig, config_to_dict
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.evaluation.benchmark.contenders import (
    ORACLE,
    TEAM_ORACLE,
    Contender,
    contenders,
    default_commit,
    heuristic,
    map_model,
    model,
    oracle,
    team_oracle,
)
from frontier_marl.evaluation.benchmark.families import (
    COVERAGE,
    DEFAULT_EPISODES,
    FAMILIES,
    MapFamily,
    variant_configs,
)
from frontier_marl.evaluation.benchmark.stats import compare, summary_row
from frontier_marl.evaluation.protocol import evaluate
from frontier_marl.evaluation.records import EpisodeRecord, EvaluationResult
from frontier_marl.policies.base import Policy, slot_table
from frontier_marl.policies.metadata import ModelEnvMismatchError
from frontier_marl.utils.parallel import map_tasks

__all__ = [
    "ORACLE",
    "TEAM_ORACLE",
    "Contender",
    "EpisodeTask",
    "contenders",
    "default_commit",
    "heuristic",
    "map_model",
    "model",
    "oracle",
    "play_episode",
    "run_benchmark",
    "run_family",
    "run_on_seeds",
    "team_oracle",
]


class _SlotWatch(Policy):
    """Counts decisions where every slot held a cluster (some clusters may have gone
    unoffered); delegates everything else to the wrapped policy."""

    def __init__(self, policy: Policy) -> None:
        self.policy = policy
        self.name = policy.name
        self.deterministic = policy.deterministic
        self.saturated = 0

    def reset(self, seed: int | None = None) -> None:
        self.policy.reset(seed)

    def attach(self, env: Any) -> None:
        self.policy.attach(env)

    def act_team(self, observations: Any, infos: Mapping[str, Any]) -> dict[str, int]:
        for info in infos.values():
            if "slots" not in info:
                continue
            table = slot_table(info)
            if table.live == len(table.valid):
                self.saturated += 1
        return self.policy.act_team(observations, infos)


@dataclass(frozen=True)
class EpisodeTask:
    """One episode of the benchmark, the unit of work: a policy on a family's world from one
    reset seed (picklable when the contender is, see
    :mod:`~frontier_marl.evaluation.benchmark.contenders`)."""

    family: str
    contender: Contender
    config: EnvConfig
    seed: int

    def __str__(self) -> str:
        return f"episode {self.seed} of {self.contender.name} on {self.family}"


@dataclass
class EpisodeOutcome:
    """What :func:`play_episode` returns: the record, the saturated decisions, the seconds."""

    record: EpisodeRecord
    saturated: int
    seconds: float


def play_episode(task: EpisodeTask) -> EpisodeOutcome:
    """Play ``task`` with a fresh policy in a fresh env (the same wherever it runs)."""
    start = time.perf_counter()
    env = FrontierParallelEnv(config=task.config)
    policy = _SlotWatch(task.contender.make())
    try:
        record = evaluate(env, policy, episodes=1, seed=task.seed).episodes[0]
    finally:
        env.close()
    return EpisodeOutcome(record, policy.saturated, time.perf_counter() - start)


@dataclass
class _Plan:
    """One (family, policy) pair of a run: its configs (one per world) and its episodes."""

    family: MapFamily
    contender: Contender
    configs: list[EnvConfig]
    tasks: list[EpisodeTask]


def _plan(
    fam: MapFamily, contender: Contender, worlds: Sequence[EnvConfig], episodes: int, split: str
) -> _Plan:
    """The episodes of ``contender`` on ``fam``; episode ``i`` on world ``i mod len(worlds)``
    (ModelEnvMismatchError if the policy cannot act there)."""
    configs = [contender.config(world) for world in worlds]
    seeds = fam.seeds(episodes, split)
    tasks = [
        EpisodeTask(fam.name, contender, configs[i % len(configs)], seed)
        for i, seed in enumerate(seeds)
    ]
    return _Plan(fam, contender, configs, tasks)


def _result(plan: _Plan, outcomes: Sequence[EpisodeOutcome]) -> EvaluationResult:
    """The plan's :class:`EvaluationResult`; its ``extra`` holds the family, maps and seeds."""
    configs = plan.configs
    result = EvaluationResult(
        policy=plan.contender.name,
        seed=plan.tasks[0].seed,
        n_slots=configs[0].n_slots,
        n_agents=configs[0].n_agents,
        coverage_levels=(0.90, COVERAGE),
        episodes=[outcome.record for outcome in outcomes],
        config=config_to_dict(configs[0]),
        map_mode=configs[0].map_mode,
    )
    maps = [task.config.map_path for task in plan.tasks]
    result.extra.update(
        family=plan.family.name,
        heuristic=plan.contender.heuristic,
        maps=[Path(m).name for m in plan.family.maps],
        episode_maps=[None if m is None else Path(m).name for m in maps],
        saturated_decisions=sum(outcome.saturated for outcome in outcomes),
        wall_seconds=sum(outcome.seconds for outcome in outcomes),
    )
    return result


def run_family(
    fam: MapFamily,
    contender: Contender,
    worlds: Sequence[EnvConfig],
    episodes: int,
    on_episode: Callable[[EpisodeRecord], None] | None = None,
    split: str = "heldout",
    jobs: int | None = 1,
) -> EvaluationResult:
    """``episodes`` episodes of ``split`` (:meth:`MapFamily.seeds`) of one policy on one
    family (``worlds`` from :func:`variant_configs`), in ``jobs`` processes; the result's
    ``extra`` holds the family, maps and seeds, ``wall_seconds`` the episodes' seconds."""
    plan = _plan(fam, contender, worlds, episodes, split)

    def done(_index: int, outcome: EpisodeOutcome) -> None:
        if on_episode is not None:
            on_episode(outcome.record)

    return _result(plan, map_tasks(play_episode, plan.tasks, jobs, on_done=done))


def run_benchmark(
    families: Sequence[MapFamily],
    policies: Sequence[Contender],
    episodes: int = DEFAULT_EPISODES,
    agents: int = 1,
    overrides: Mapping[str, Any] | None = None,
    progress: bool = False,
    log: Callable[[str], None] | None = None,
    split: str = "heldout",
    jobs: int | None = 1,
    ray_address: str | None = None,
) -> list[dict[str, Any]]:
    """Every policy on every family's held-out (or ``validation``) episodes; one row per
    (family, policy) with the comparison to the family's best heuristic
    (:func:`~frontier_marl.evaluation.benchmark.stats.compare`). A model that cannot act on a
    family (e.g. another map size) is skipped there, with a note to ``log``. The episodes run
    in ``jobs`` processes (``None``: every core) or on the Ray cluster at ``ray_address``
    (:func:`~frontier_marl.utils.parallel.map_tasks`); the rows are the same either way."""
    if len({fam.name for fam in families}) < len(families):
        raise ValueError(f"family names must be distinct, got {[f.name for f in families]}")
    worlds = [variant_configs(fam, overrides, agents) for fam in families]
    for fam in families:
        fam.seeds(episodes, split)  # validates the episode count and the split
    plans = []
    for fam, configs in zip(families, worlds, strict=True):
        for contender in policies:
            try:
                plans.append(_plan(fam, contender, configs, episodes, split))
            except ModelEnvMismatchError as exc:
                if contender.heuristic:
                    raise
                if log is not None:
                    log(f"{contender.name} skipped on {fam.name}: {exc}")
    tasks = [task for plan in plans for task in plan.tasks]
    outcomes = map_tasks(
        play_episode, tasks, jobs, ray_address=ray_address, progress=progress, unit="ep"
    )
    rows = [
        summary_row(_result(plan, outcomes[i * episodes : (i + 1) * episodes]))
        for i, plan in enumerate(plans)
    ]
    try:
        return compare(rows)
    except Exception as error:  # the statistics must never lose the episodes already run
        if log is not None:
            log(f"warning: the comparison failed ({type(error).__name__}: {error}); rows kept")
        for row in rows:
            row["comparison_error"] = f"{type(error).__name__}: {error}"
        return rows


def run_on_seeds(
    names: Sequence[str], seeds: range, episodes: int, progress: bool = False, jobs: int = 1
) -> list[dict[str, Any]]:
    """:func:`run_benchmark` of the policies ``names`` on the first ``episodes`` of ``seeds``
    of every built-in family, one robot (for the benchmark scripts that choose and probe
    models on validation or training seeds; :class:`MapFamily` refuses held-out ones)."""
    families = [replace(fam, validation=seeds) for fam in FAMILIES.values()]
    return run_benchmark(
        families, contenders(names), episodes, progress=progress, split="validation", jobs=jobs
    )
