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

Statistics (T99, T90, success, the paired difference to the best heuristic) are in
:mod:`frontier_marl.evaluation.benchmark.stats`.
"""

from __future__ import annotations

import inspect
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig, config_to_dict, make_config
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.evaluation.benchmark.families import (
    COVERAGE,
    DEFAULT_EPISODES,
    FAMILIES,
    OBSERVATION_KEYS,
    MapFamily,
    variant_configs,
    world_settings,
)
from frontier_marl.evaluation.benchmark.stats import compare, summary_row
from frontier_marl.evaluation.protocol import evaluate
from frontier_marl.evaluation.records import EpisodeRecord, EvaluationResult
from frontier_marl.policies.base import ModelPolicy, Policy, slot_table
from frontier_marl.policies.lookahead import LookaheadOracle
from frontier_marl.policies.metadata import ModelEnvMismatchError
from frontier_marl.policies.models import (
    PRETRAINED,
    check_model_env,
    load_model,
    map_scorer_folder,
)
from frontier_marl.policies.registry import POLICIES, env_settings, make_policy
from frontier_marl.utils.progress import progress_bar

ORACLE = "lookahead-oracle"


@dataclass
class Contender:
    """A policy of the benchmark: a heuristic (by registry name) or a learned model.

    ``make`` returns a fresh :class:`~frontier_marl.evaluation.Policy`; ``config`` turns a
    family's world config into the config this policy runs with (the same for a heuristic;
    the model's observation settings on the same world for a model).
    """

    name: str
    heuristic: bool
    make: Callable[[], Any]
    config: Callable[[EnvConfig], EnvConfig]


def default_commit(agents: int) -> str:
    """The heuristics' commit rule in the benchmark (see the module docstring)."""
    return "until-progress" if agents == 1 else "none"


def heuristic(name: str, commit: str = "until-progress") -> Contender:
    """A heuristic of the registry, with ``commit`` where it takes one; one that reads an
    observation layout of its own (``frontier-rule``) runs with it on the family's world."""
    accepted = inspect.signature(POLICIES[name]).parameters
    options = {"commit": commit} if "commit" in accepted else {}
    own = env_settings(name)

    def config(world: EnvConfig) -> EnvConfig:
        return make_config(None, **{**world_settings(world), **own}) if own else world

    return Contender(name, True, lambda: make_policy(name, 0, **options), config)


def model(name: str) -> Contender:
    """A saved or shipped SB3 model (``thesis-config01``, a run folder, a model.zip)."""
    try:
        loaded = load_model(name)
    except Exception as exc:  # e.g. a file that is not an SB3 zip
        raise ValueError(f"cannot load model {name}: {exc}") from exc
    if loaded.metadata is None:
        raise ValueError(f"model {name}: no metadata saved beside it (its observation settings)")
    saved = config_to_dict(loaded.env_config())

    def config(world: EnvConfig) -> EnvConfig:
        own = {k: saved[k] for k in OBSERVATION_KEYS}
        cfg = make_config(None, **{**world_settings(world), **own})
        check_model_env(loaded, cfg)
        return cfg

    label = Path(name).stem if name.endswith(".zip") else Path(name).name
    return Contender(label, False, lambda: ModelPolicy(loaded.model, name=label), config)


def map_model(folder: Path, label: str) -> Contender:
    """A saved map-aware scorer (:mod:`frontier_marl.policies.map_explorer`): it chooses among
    frontier-rule's slots, in frontier-rule's env on each world. Needs torch."""
    try:  # torch is the train extra's
        from frontier_marl.policies.map_explorer import MapExplorer, load_scorer
    except ModuleNotFoundError as exc:
        raise ValueError(
            f"model {label}: a map scorer needs torch ({exc.name} is not installed): "
            "pip install 'frontier-marl[train]'"
        ) from None
    scorer, _ = load_scorer(folder)
    rule = heuristic("frontier-rule")
    return Contender(label, False, lambda: MapExplorer(scorer, label), rule.config)


def oracle() -> Contender:
    """``lookahead-oracle`` (:mod:`frontier_marl.policies.lookahead`): it reads the true map,
    so it is reported beside the others but never counts as the best heuristic."""
    return Contender(LookaheadOracle.name, False, LookaheadOracle, lambda cfg: cfg)


def contenders(names: Sequence[str], commit: str = "until-progress") -> list[Contender]:
    """Heuristics by name, ``lookahead-oracle`` and models by name or path; ValueError for
    anything else."""
    out = []
    for name in names:
        if name in POLICIES:
            out.append(heuristic(name, commit))
        elif name == ORACLE:
            out.append(oracle())
        elif (folder := map_scorer_folder(name)) is not None:
            out.append(map_model(folder, Path(name).name if Path(name).exists() else name))
        elif name in PRETRAINED or Path(name).exists():
            out.append(model(name))
        else:
            raise ValueError(
                f"unknown policy {name!r}: not a heuristic ({', '.join(POLICIES)}), {ORACLE}, "
                f"a shipped model ({', '.join(PRETRAINED)}), nor a model file or run folder"
            )
    labels = [contender.name for contender in out]
    repeated = sorted({label for label in labels if labels.count(label) > 1})
    if repeated:
        raise ValueError(
            f"two policies share the label {', '.join(map(repr, repeated))} (a model is "
            "labelled by its folder): copy one to a folder of another name"
        )
    return out


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


def run_family(
    fam: MapFamily,
    contender: Contender,
    worlds: Sequence[EnvConfig],
    episodes: int,
    on_episode: Callable[[EpisodeRecord], None] | None = None,
    split: str = "heldout",
) -> EvaluationResult:
    """``episodes`` episodes of ``split`` (:meth:`MapFamily.seeds`) of one policy on one
    family (``worlds`` from :func:`variant_configs`); the result's ``extra`` holds the family,
    maps and seeds."""
    start = time.perf_counter()
    seeds = fam.seeds(episodes, split)
    configs = [contender.config(world) for world in worlds]
    envs = [FrontierParallelEnv(config=cfg) for cfg in configs]
    policy = _SlotWatch(contender.make())
    records: list[EpisodeRecord] = []
    maps: list[str | None] = []
    try:
        for i, seed in enumerate(seeds):
            env = envs[i % len(envs)]
            record = evaluate(env, policy, episodes=1, seed=seed).episodes[0]
            records.append(record)
            maps.append(configs[i % len(envs)].map_path)
            if on_episode is not None:
                on_episode(record)
    finally:
        for env in envs:
            env.close()
    result = EvaluationResult(
        policy=contender.name,
        seed=seeds[0],
        n_slots=configs[0].n_slots,
        n_agents=configs[0].n_agents,
        coverage_levels=(0.90, COVERAGE),
        episodes=records,
        config=config_to_dict(configs[0]),
        map_mode=configs[0].map_mode,
    )
    result.extra.update(
        family=fam.name,
        heuristic=contender.heuristic,
        maps=[Path(m).name for m in fam.maps],
        episode_maps=[None if m is None else Path(m).name for m in maps],
        saturated_decisions=policy.saturated,
        wall_seconds=time.perf_counter() - start,
    )
    return result


def run_benchmark(
    families: Sequence[MapFamily],
    policies: Sequence[Contender],
    episodes: int = DEFAULT_EPISODES,
    agents: int = 1,
    overrides: Mapping[str, Any] | None = None,
    progress: bool = False,
    log: Callable[[str], None] | None = None,
    split: str = "heldout",
) -> list[dict[str, Any]]:
    """Every policy on every family's held-out (or ``validation``) episodes; one row per
    (family, policy) with
    the comparison to the family's best heuristic
    (:func:`~frontier_marl.evaluation.benchmark.stats.compare`). A model that cannot act on a
    family (e.g. another map size) is skipped there, with a note to ``log``."""
    if len({fam.name for fam in families}) < len(families):
        raise ValueError(f"family names must be distinct, got {[f.name for f in families]}")
    worlds = [variant_configs(fam, overrides, agents) for fam in families]
    for fam in families:
        fam.seeds(episodes, split)  # validates the episode count and the split
    rows = []
    total = len(families) * len(policies) * episodes
    with progress_bar(total, disable=not progress, unit="ep") as bar:
        for fam, configs in zip(families, worlds, strict=True):
            for contender in policies:
                bar.set_description(f"{fam.name} {contender.name}")
                try:
                    result = run_family(
                        fam, contender, configs, episodes, lambda _r: bar.update(1), split
                    )
                except ModelEnvMismatchError as exc:
                    if contender.heuristic:
                        raise
                    bar.update(episodes)
                    if log is not None:
                        log(f"{contender.name} skipped on {fam.name}: {exc}")
                    continue
                rows.append(summary_row(result))
    try:
        return compare(rows)
    except Exception as error:  # the statistics must never lose the episodes already run
        if log is not None:
            log(f"warning: the comparison failed ({type(error).__name__}: {error}); rows kept")
        for row in rows:
            row["comparison_error"] = f"{type(error).__name__}: {error}"
        return rows


def run_on_seeds(
    names: Sequence[str], seeds: range, episodes: int, progress: bool = False
) -> list[dict[str, Any]]:
    """:func:`run_benchmark` of the policies ``names`` on the first ``episodes`` of ``seeds``
    of every built-in family, one robot (for the benchmark scripts that choose and probe
    models on validation or training seeds; :class:`MapFamily` refuses held-out ones)."""
    families = [replace(fam, validation=seeds) for fam in FAMILIES.values()]
    return run_benchmark(
        families, contenders(names), episodes, progress=progress, split="validation"
    )
