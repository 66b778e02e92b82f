"""The whole simulator configuration, :class:`EnvConfig`: grid, maps, robots, sensor, clustering,
episode end, and the observation and reward options."""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Any, get_args

from frontier_marl.config.options import (
    FULL_PATH,
    GainModel,
    MapGenerator,
    MapMode,
    ObservationConfig,
    RewardConfig,
    RewardKind,
    SensorModel,
    StartCells,
)
from frontier_marl.core.map_files import load_map
from frontier_marl.utils.checks import (
    check_choice,
    check_int,
    check_range,
)


@dataclass(frozen=True)
class EnvConfig:
    """The whole simulator configuration.

    Attributes:
        height, width: grid size in cells.
        n_agents: robots sharing one belief grid (1 = the thesis MDP).
        map_generator: ``random`` (independent obstacles with ``obstacle_prob``), ``rooms``
            (rectangular rooms joined by corridors) or ``floorplan`` (a building that fills
            the grid, split into rooms by thin walls with doors); ``obstacle_prob`` is used by
            ``random`` only.
        obstacle_prob: probability that a cell is an obstacle (open choice; 0.1 by
            calibration against the thesis's 20x20 baselines, docs/calibration.md).
        obstacle_prob_spread: draw each dynamic random layout's obstacle probability
            uniformly from ``obstacle_prob`` +- this, clipped to [0, 0.9] (open choice; 0.2,
            so U(0, 0.3) around the 0.1 default: the setting that gives dynamic maps the
            thesis's lower means and wider spread, docs/calibration.md); 0 keeps it fixed.
            The static layout always uses ``obstacle_prob``.
        start_cells: where robots start: ``largest-component`` (distinct random cells of the
            largest 4-connected free component) or ``any-free`` (of all free cells, so a robot
            may start in a small pocket; the reachable region is then the pocket). Open choice.
        map_mode: ``static`` (one layout from ``map_seed``) or ``dynamic`` (new layout per reset).
        map_seed: seed of the static layout, recorded so results are comparable across runs.
        map_path: load the (static) layout from a .txt, .pgm or .png file instead of drawing
            it; the file sets ``height`` and ``width``.
        map_scale: draw the layout at ``height / k`` x ``width / k`` cells and make each of its
            cells a k x k block: the same kind of floor plan on a grid k times finer (walls
            and doors k cells thick, rooms k times wider). 1 (the default) draws it cell by
            cell; ``height`` and ``width`` must be multiples of k; generated layouts only.
        perception_range: sensor range r in cells.
        sensor: ``square`` (Chebyshev window, no occlusion) or ``raycast`` (Euclidean disc with
            line of sight through free cells). Open choice; ``raycast`` by calibration.
        cells_per_step: cells a robot moves per decision, or ``"full"`` to walk the whole path
            to its target. Open choice; 1 by calibration (``full`` erases the thesis's gap
            between the two greedy heuristics).
        connectivity: 4 or 8, the neighbourhood used to group frontier cells into clusters.
        max_cluster_cells: clusters larger than this are split recursively (open choice;
            2r + 2: 8 at r = 3, 12 at r = 5).
        n_slots: N_max, the number of cluster slots (the action space size).
        gain: information gain of a cluster: its ``size`` or the ``unknown`` cells around it.
        observation: see :class:`ObservationConfig`.
        reward: see :class:`RewardConfig`.
    """

    height: int = 20
    width: int = 20
    n_agents: int = 1
    map_generator: MapGenerator = "random"
    obstacle_prob: float = 0.1
    obstacle_prob_spread: float = 0.2
    start_cells: StartCells = "largest-component"
    map_mode: MapMode = "static"
    map_seed: int = 0
    map_path: str | None = None
    map_scale: int = 1
    perception_range: int = 3
    sensor: SensorModel = "raycast"
    cells_per_step: int | str = 1
    connectivity: int = 8
    max_cluster_cells: int = 8
    n_slots: int = 4
    gain: GainModel = "size"
    observation: ObservationConfig = field(default_factory=ObservationConfig)
    reward: RewardConfig = field(default_factory=RewardConfig)

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        """Raise ``ValueError`` naming the first parameter out of its allowed range."""
        self._validate_layout()
        self._validate_map_path()
        check_int("perception_range", self.perception_range, 1, max(self.height, self.width))
        check_choice("sensor", self.sensor, get_args(SensorModel))
        if self.cells_per_step != FULL_PATH:
            check_int("cells_per_step", self.cells_per_step, 1, extra_allowed="'full'")
        check_int("connectivity", self.connectivity, 4, 8)
        check_choice("connectivity", self.connectivity, (4, 8))
        check_int("max_cluster_cells", self.max_cluster_cells, 1)
        check_int("n_slots", self.n_slots, 1, 256)
        check_choice("gain", self.gain, get_args(GainModel))
        self._validate_parts()

    def _validate_layout(self) -> None:
        """Size, team, generator, obstacles, scale and map mode."""
        check_int("height", self.height, 3, 4096)
        check_int("width", self.width, 3, 4096)
        check_int("n_agents", self.n_agents, 1, 64)
        check_choice("map_generator", self.map_generator, get_args(MapGenerator))
        check_range("obstacle_prob", self.obstacle_prob, 0.0, 0.9)
        check_range("obstacle_prob_spread", self.obstacle_prob_spread, 0.0, 0.5)
        check_choice("start_cells", self.start_cells, get_args(StartCells))
        check_int("map_scale", self.map_scale, 1, 64)
        if self.height % self.map_scale or self.width % self.map_scale:
            raise ValueError(
                f"height and width must be multiples of map_scale={self.map_scale}, "
                f"got {self.height}x{self.width}"
            )
        layout = (self.height // self.map_scale, self.width // self.map_scale)
        if self.map_generator != "random" and min(layout) < 5:
            raise ValueError(
                f"map_generator={self.map_generator!r} needs a layout of at least 5x5 cells "
                f"(height and width / map_scale), got {layout[0]}x{layout[1]}"
            )
        check_choice("map_mode", self.map_mode, get_args(MapMode))
        check_int("map_seed", self.map_seed, 0)

    def _validate_map_path(self) -> None:
        if self.map_path is None:
            return
        if not isinstance(self.map_path, str):
            raise ValueError(f"map_path must be a file path string, got {self.map_path!r}")
        if self.map_mode != "static":
            raise ValueError(
                "map_mode must be 'static' with map_path (a file holds one fixed layout)"
            )
        if self.map_scale != 1:
            raise ValueError("map_scale applies to generated layouts, not to map_path")

    def _validate_parts(self) -> None:
        """The observation and reward configs, and the teammates' need for a team."""
        if not isinstance(self.observation, ObservationConfig):
            raise ValueError("observation must be an ObservationConfig")
        if not isinstance(self.reward, RewardConfig):
            raise ValueError("reward must be a RewardConfig")
        self.observation.validate()
        self.reward.validate()
        if self.observation.teammates != "none" and self.n_agents < 2:
            raise ValueError(
                f"teammates={self.observation.teammates!r} needs n_agents >= 2, "
                f"got n_agents={self.n_agents}"
            )

    @property
    def shape(self) -> tuple[int, int]:
        return (self.height, self.width)

    @property
    def walks_full_path(self) -> bool:
        return self.cells_per_step == FULL_PATH

    def replace(self, **overrides: Any) -> EnvConfig:
        """A copy with flat overrides applied (see :func:`make_config` for the keys)."""
        return apply_overrides(self, overrides)


OBS_KEYS = {f.name for f in dataclasses.fields(ObservationConfig)}
REWARD_KEYS = {f.name for f in dataclasses.fields(RewardConfig)} - {"kind"}
ENV_KEYS = {f.name for f in dataclasses.fields(EnvConfig)} - {"observation", "reward"}


#: Other libraries' names for a keyword: PettingZoo calls the step limit ``max_cycles``.
ALIASES = {"max_cycles": "max_steps"}


class UnknownKeywordError(TypeError, ValueError):
    """An unknown keyword: a ``TypeError``, as Python raises for an unexpected keyword argument
    (clients such as TorchRL's ``GymEnv`` retry without a keyword on it), and a ``ValueError``,
    as every other bad parameter of the config."""


def config_keys() -> list[str]:
    """Every flat keyword accepted by :func:`make_config`."""
    return sorted(ENV_KEYS | OBS_KEYS | REWARD_KEYS | {"reward", "preset", "config"})


def reject_unknown(given: Any, allowed: Any, owner: str) -> None:
    """Raise :class:`UnknownKeywordError` naming the keywords of ``given`` that ``allowed``
    lacks (Python's wording) and listing the allowed ones."""
    unknown = sorted(set(given) - set(allowed))
    if unknown:
        names = ", ".join(repr(name) for name in unknown)  # Python's wording: clients match it
        what = "an unexpected keyword argument"
        if len(unknown) > 1:
            what = "unexpected keyword arguments"
        raise UnknownKeywordError(
            f"{owner}() got {what} {names}; allowed: {', '.join(sorted(allowed))}"
        )


def resolve_aliases(overrides: dict[str, Any]) -> dict[str, Any]:
    """``overrides`` with :data:`ALIASES` renamed (``TypeError`` if both names are given)."""
    for alias, name in ALIASES.items():
        if alias in overrides:
            if name in overrides:
                raise TypeError(f"give {name} or {alias} (another name for it), not both")
            overrides = {**overrides, name: overrides[alias]}
            del overrides[alias]
    return overrides


def apply_overrides(cfg: EnvConfig, overrides: dict[str, Any]) -> EnvConfig:
    """``cfg`` with flat keyword overrides applied (validated by the dataclasses)."""
    overrides = resolve_aliases(overrides)
    allowed = ENV_KEYS | OBS_KEYS | REWARD_KEYS | {"reward", "observation"}
    if set(overrides) - allowed:
        reject_unknown(overrides, allowed | set(config_keys()) | set(ALIASES), "make_config")
    env_kw = {k: v for k, v in overrides.items() if k in ENV_KEYS}
    if env_kw.get("map_path") is not None:
        if isinstance(env_kw["map_path"], os.PathLike):
            env_kw["map_path"] = os.fspath(env_kw["map_path"])
        if not isinstance(env_kw["map_path"], str):
            raise ValueError(f"map_path must be a file path, got {env_kw['map_path']!r}")
        env_kw.update(_shape_from_map_file(env_kw["map_path"], env_kw))
    obs_kw = {k: v for k, v in overrides.items() if k in OBS_KEYS}
    rew_kw = {k: v for k, v in overrides.items() if k in REWARD_KEYS}
    observation = overrides.get("observation", cfg.observation)
    reward = cfg.reward
    if "reward" in overrides:
        value = overrides["reward"]
        if isinstance(value, RewardConfig):
            reward = value
        else:
            check_choice("reward", value, get_args(RewardKind))
            rew_kw["kind"] = value
    if isinstance(observation, ObservationConfig) and obs_kw:
        observation = dataclasses.replace(observation, **obs_kw)
    if isinstance(reward, RewardConfig) and rew_kw:
        reward = dataclasses.replace(reward, **rew_kw)
    return dataclasses.replace(cfg, observation=observation, reward=reward, **env_kw)


def _shape_from_map_file(path: str, overrides: dict[str, Any]) -> dict[str, int]:
    """The grid size of the map file at ``path``; ValueError if ``overrides`` contradict it."""
    try:
        height, width = load_map(path).shape
    except ValueError as error:
        raise ValueError(f"map_path: {error}") from error
    for name, size in (("height", height), ("width", width)):
        if name in overrides and overrides[name] != size:
            raise ValueError(
                f"{name}={overrides[name]} contradicts map_path {path} ({name} {size})"
            )
    return {"height": height, "width": width}
