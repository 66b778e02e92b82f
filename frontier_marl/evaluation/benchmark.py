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
:mod:`frontier_marl.evaluation.benchmark_stats`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig, ObservationConfig, config_to_dict, make_config
from frontier_marl.evaluation.policies import Policy
from frontier_marl.evaluation.records import EpisodeRecord, EvaluationResult

#: Held-out episode seeds of every family (episode i: seed 900_000 + i); never used for
#: training, validation or tuning.
HELDOUT_SEEDS = range(900_000, 1_000_000)
#: Seeds for training on a family (documented for learned policies; disjoint from the others).
TRAIN_SEEDS = range(0, 800_000)
#: Seeds for validation (model selection) on a family.
VALIDATION_SEEDS = range(800_000, 900_000)
DEFAULT_EPISODES = 30
SPLITS = ("heldout", "validation")
#: Slots offered to the heuristics: the env's maximum, so they choose among every reachable
#: cluster (the benchmark counts the decisions where all of them were full).
HEURISTIC_SLOTS = 256
COVERAGE = 0.99
#: Settings a learned model keeps from its own training config: what it observes and acts on.
OBSERVATION_KEYS: tuple[str, ...] = (
    *(f.name for f in dataclasses.fields(ObservationConfig)),
    "n_slots",
    "gain",
    "reward",
)
#: Keys that the command's ``--set`` may not change (the family or another option sets them).
RESERVED_KEYS = ("preset", "config", "map_path", "n_agents")
MAP_SUFFIXES = (".pgm", ".png", ".txt")


@dataclass(frozen=True)
class MapFamily:
    """A map family: env keyword arguments (``env``, for :func:`frontier_marl.parallel_env`,
    before the episode settings), held-out episode seeds, and the seed ranges reserved for
    training and validation on it (disjoint from the held-out ones). ``maps`` lists the files
    of a family of loaded maps (empty for a generator); episode ``i`` uses ``maps[i % M]``."""

    name: str
    env: tuple[tuple[str, Any], ...]
    description: str = ""
    maps: tuple[str, ...] = ()
    heldout: range = HELDOUT_SEEDS
    train: range = TRAIN_SEEDS
    validation: range = VALIDATION_SEEDS

    def __post_init__(self) -> None:
        for a, b in ((self.heldout, self.train), (self.heldout, self.validation)):
            if a.start < b.stop and b.start < a.stop:
                raise ValueError(f"family {self.name}: held-out seeds overlap {b}")

    @property
    def env_kwargs(self) -> dict[str, Any]:
        return dict(self.env)

    def seeds(self, episodes: int, split: str = "heldout") -> list[int]:
        """The reset seeds of the first ``episodes`` episodes of ``split``: ``heldout`` (the
        report's) or ``validation`` (for model selection and tuning)."""
        if split not in SPLITS:
            raise ValueError(f"split must be one of {list(SPLITS)}, got {split!r}")
        seeds = self.heldout if split == "heldout" else self.validation
        if episodes < 1 or episodes > len(seeds):
            raise ValueError(f"episodes must be in [1, {len(seeds)}], got {episodes}")
        return list(seeds[:episodes])


def _family(name: str, description: str, **env: Any) -> MapFamily:
    return MapFamily(name, (*env.items(), ("map_mode", "dynamic")), description)


#: The built-in families: the thesis's two random geometries (dynamic, 10 % obstacles on
#: average: each layout's density drawn from U(0, 0.3)) and rooms and corridors at two sizes.
_ROOMS_64 = {"height": 64, "width": 64, "perception_range": 5}
FAMILIES: dict[str, MapFamily] = {
    f.name: f
    for f in (
        _family("random-20", "20x20 random obstacles, r = 3", preset="thesis-20x20"),
        _family("random-30", "30x30 random obstacles, r = 5", preset="thesis-30x30"),
        _family("rooms-32", "32x32 rooms and corridors, r = 3", preset="rooms-32"),
        _family("rooms-64", "64x64 rooms and corridors, r = 5", preset="rooms-32", **_ROOMS_64),
    )
}


def family(name: str) -> MapFamily:
    """A built-in family by name (ValueError naming the valid ones)."""
    if name not in FAMILIES:
        raise ValueError(f"unknown family {name!r}; valid: {', '.join(FAMILIES)}")
    return FAMILIES[name]


def map_files(paths: Sequence[str | Path]) -> list[str]:
    """The map files named by ``paths``: files as given, folders as their sorted .pgm/.png/.txt
    files, names of the package's example maps as their files."""
    from frontier_marl.example_maps import resolve_map

    files: list[str] = []
    for given in paths:
        path = Path(resolve_map(str(given)))
        if path.is_dir():
            found = sorted(p for p in path.iterdir() if p.suffix.lower() in MAP_SUFFIXES)
            if not found:
                raise ValueError(f"map folder {path} holds no .pgm, .png or .txt map")
            files += [str(p) for p in found]
        elif path.is_file():
            files.append(str(path))
        else:
            raise ValueError(f"map file {given} does not exist")
    if not files:
        raise ValueError("no map file given")
    return files


def loaded_map_range(height: int, width: int) -> int:
    """Sensor range for a loaded map: Explore-Bench's 35 cells on its 250-cell floor plans,
    scaled with the map's shorter side (at least 3)."""
    return max(3, round(35 * min(height, width) / 250))


def map_family(paths: Sequence[str | Path], name: str | None = None) -> MapFamily:
    """A family of loaded maps (files or folders, see :func:`map_files`); named ``map:`` and
    the single file or folder given, else ``map:several``."""
    files = map_files(paths)
    if name is None:
        name = "map:" + (Path(str(paths[0])).stem if len(paths) == 1 else "several")
    return MapFamily(
        name,
        (("preset", "thesis-20x20"),),
        f"{len(files)} loaded map(s), sensor range scaled to each map",
        maps=tuple(files),
    )


def episode_settings(height: int, width: int) -> dict[str, Any]:
    """What ends a benchmark episode: 99 % of the reachable free cells known, or a generous
    limit: ``2 * H * W`` decisions, or ``H * W`` decisions in a row without a new cell (no
    shortest walk is that long, so it never cuts one)."""
    return {
        "explore_threshold": COVERAGE,
        "threshold_basis": "reachable",
        "max_steps": 2 * height * width,
        "no_progress_limit": height * width,
    }


def variant_configs(
    fam: MapFamily, overrides: Mapping[str, Any] | None = None, agents: int = 1
) -> list[EnvConfig]:
    """The world config of each of the family's maps (one for a generator): the family's env,
    the episode settings, ``overrides`` (``--set``), ``agents`` robots and the heuristics'
    slots. ``max_cluster_cells`` follows the presets' rule 2r + 2 unless overridden."""
    overrides = dict(overrides or {})
    bad = sorted(set(overrides) & set(RESERVED_KEYS))
    if bad:
        raise ValueError(f"--set {bad[0]}=... is not allowed in the benchmark")
    if not isinstance(agents, int) or agents < 1:
        raise ValueError(f"agents must be an integer >= 1, got {agents!r}")
    out = []
    for path in fam.maps or (None,):
        kwargs = fam.env_kwargs
        if path is not None:
            from frontier_marl.core.map_files import load_map

            height, width = load_map(path).shape
            kwargs.update(map_path=path, perception_range=loaded_map_range(height, width))
        kwargs.update({"n_slots": HEURISTIC_SLOTS, "n_agents": agents, **overrides})
        try:
            shape = make_config(**kwargs).shape  # the size after the overrides
            kwargs.update({**episode_settings(*shape), **overrides})
            r = kwargs.get("perception_range")
            if isinstance(r, int) and "max_cluster_cells" not in overrides:
                kwargs["max_cluster_cells"] = 2 * r + 2
            out.append(make_config(**kwargs))
        except ValueError as exc:
            raise ValueError(f"family {fam.name}: {exc}") from None
    return out


def world_settings(cfg: EnvConfig) -> dict[str, Any]:
    """The flat settings of ``cfg`` that a learned model must share with the heuristics."""
    return {k: v for k, v in config_to_dict(cfg).items() if k not in OBSERVATION_KEYS}


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
    """A heuristic of the registry, with ``commit`` (``random`` has no commit rule)."""
    from frontier_marl.evaluation.registry import make_policy

    options = {} if name == "random" else {"commit": commit}
    return Contender(name, True, lambda: make_policy(name, 0, **options), lambda cfg: cfg)


def model(name: str) -> Contender:
    """A saved or shipped SB3 model (``thesis-config01``, a run folder, a model.zip)."""
    from frontier_marl.evaluation.policies import ModelPolicy
    from frontier_marl.training.evaluate_model import check_model_env, load_model

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


def contenders(names: Sequence[str], commit: str = "until-progress") -> list[Contender]:
    """Heuristics by name and models by name or path; ValueError for anything else."""
    from frontier_marl.evaluation.registry import POLICIES
    from frontier_marl.pretrained import PRETRAINED

    out = []
    for name in names:
        if name in POLICIES:
            out.append(heuristic(name, commit))
        elif name in PRETRAINED or Path(name).exists():
            out.append(model(name))
        else:
            raise ValueError(
                f"unknown policy {name!r}: not a heuristic ({', '.join(POLICIES)}), a shipped "
                f"model ({', '.join(PRETRAINED)}), nor a model file or run folder"
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
            table = info.get("slots")
            if table is not None and table.live == len(table.valid):
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
    import time

    from frontier_marl.envs.parallel import FrontierParallelEnv
    from frontier_marl.evaluation.protocol import evaluate

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
    (:func:`~frontier_marl.evaluation.benchmark_stats.compare`). A model that cannot act on a
    family (e.g. another map size) is skipped there, with a note to ``log``."""
    from frontier_marl.evaluation.benchmark_stats import compare, summary_row
    from frontier_marl.progress import progress_bar
    from frontier_marl.training.metadata import ModelEnvMismatchError

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
    return compare(rows)
