"""Map families of the exploration benchmark: generators and loaded maps, their seed ranges,
and the world config of a family's episodes (docs/benchmark.md).

A :class:`MapFamily` is a generator of maps with fixed held-out episode seeds and the seed
ranges reserved for training and validation; a family of loaded maps (:func:`map_family`)
cycles its episodes through its files. :func:`variant_configs` gives the world every policy
faces: the family's env, the episode end (99 % of the reachable free cells, or a generous limit
scaled to the map) and the heuristics' slots.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig, ObservationConfig, config_to_dict, make_config
from frontier_marl.core.example_maps import resolve_map

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
#: average: each layout's density drawn from U(0, 0.3)), rooms and corridors at two sizes, and
#: rooms-32 layouts on a 3x finer grid: walls and doors 3 cells thick and a sensor that spans
#: 13 cells, as on real floor plans at 0.1 m a cell (the Explore-Bench regime), where the
#: frontier breaks into long pieces and the specks that shadows leave. ``floorplan-96``: whole
#: buildings split into rooms by thin walls with doors (no solid rock between rooms), drawn on
#: a 48x48 layout at map_scale 2, with the same sensor: the Explore-Bench floor plans' regime.
_ROOMS_64 = {"height": 64, "width": 64, "perception_range": 5}
_ROOMS_96_FINE = {"height": 96, "width": 96, "map_scale": 3, "perception_range": 13}
_FLOORPLAN_96 = {"height": 96, "width": 96, "map_scale": 2, "perception_range": 13}
FAMILIES: dict[str, MapFamily] = {
    f.name: f
    for f in (
        _family("random-20", "20x20 random obstacles, r = 3", preset="thesis-20x20"),
        _family("random-30", "30x30 random obstacles, r = 5", preset="thesis-30x30"),
        _family("rooms-32", "32x32 rooms and corridors, r = 3", preset="rooms-32"),
        _family("rooms-64", "64x64 rooms and corridors, r = 5", preset="rooms-32", **_ROOMS_64),
        _family(
            "rooms-96-fine",
            "96x96 rooms and corridors on a 3x finer grid (map_scale = 3), r = 13",
            preset="rooms-32",
            **_ROOMS_96_FINE,
        ),
        _family(
            "floorplan-96",
            "96x96 buildings split into rooms by thin walls with doors (map_scale = 2), r = 13",
            preset="rooms-32",
            map_generator="floorplan",
            **_FLOORPLAN_96,
        ),
    )
}


def family(name: str) -> MapFamily:
    """A built-in family by name (ValueError naming the valid ones)."""
    if name not in FAMILIES:
        raise ValueError(f"unknown family {name!r}; valid: {', '.join(FAMILIES)}")
    return FAMILIES[name]


def check_families(names: Any, what: str = "families") -> None:
    """ValueError naming ``what`` unless ``names`` is a list of built-in family names."""
    if not isinstance(names, tuple | list) or not all(isinstance(n, str) for n in names):
        raise ValueError(f"{what} must be a list of family names, got {names!r}")
    for name in names:
        try:
            family(name)
        except ValueError as exc:
            raise ValueError(f"{what}: {exc}") from None


def map_files(paths: Sequence[str | Path]) -> list[str]:
    """The map files named by ``paths``: files as given, folders as their sorted .pgm/.png/.txt
    files, names of the package's example maps as their files."""
    files: list[str] = []
    for given in paths:
        path = Path(resolve_map(str(given)))
        if path.is_dir():
            found = sorted(p for p in path.iterdir() if p.suffix.lower() in MAP_SUFFIXES)
            if not found:
                raise ValueError(f"map folder {path} holds no .pgm, .png or .txt map{_hint(path)}")
            files += [str(p) for p in found]
        elif path.is_file():
            files.append(str(path))
        else:
            raise ValueError(f"map file {given} does not exist")
    if not files:
        raise ValueError("no map file given")
    return files


def _hint(folder: Path) -> str:
    """Which subfolders of ``folder`` hold maps (a folder is not searched recursively)."""
    holding = sorted(
        sub.name
        for sub in folder.iterdir()
        if sub.is_dir() and any(p.suffix.lower() in MAP_SUFFIXES for p in sub.iterdir())
    )
    return f" (its subfolders {', '.join(holding)} do: pass one of them)" if holding else ""


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
