"""Environment configuration: frozen dataclasses, presets, and validation.

Every parameter of the simulator lives here, is validated once when the config is built, and
produces a ``ValueError`` that names the parameter and its allowed range. Presets reproduce the
thesis's two geometries; any keyword overrides the preset::

    cfg = make_config(preset="thesis-20x20", n_agents=2, centroid="relative")

Options that the thesis left open are marked "open choice" below; ``docs/thesis-mapping.md``
lists them with the reason for each default.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Any, Literal, get_args

from frontier_marl.core.map_files import load_map
from frontier_marl.utils.checks import (
    check_bool,
    check_choice,
    check_finite,
    check_int,
    check_range,
)

CentroidEncoding = Literal["absolute", "relative", "distance", "none"]
MapMode = Literal["static", "dynamic"]
MapGenerator = Literal["random", "rooms", "floorplan"]
StartCells = Literal["largest-component", "any-free"]
SensorModel = Literal["square", "raycast"]
GainModel = Literal["size", "unknown"]
ThresholdBasis = Literal["all", "free", "reachable"]
RewardKind = Literal["reward1", "reward2", "travel"]
TeammateEncoding = Literal["none", "positions", "positions+targets"]
FeatureLayout = Literal["thesis", "explorer"]
CommitRule = Literal["none", "until-progress", "until-reached"]
FULL_PATH = "full"


@dataclass(frozen=True)
class ObservationConfig:
    """What each robot observes (the thesis's Table 4.1 axes).

    Attributes:
        centroid: encoding of each cluster slot's centroid: ``absolute`` (row, col),
            ``relative`` (drow, dcol) to the robot, ``distance`` (Euclidean) only, or ``none``.
        agent_position: include the robot's own (row, col); makes the observation a ``Dict``.
        info_gain: include each slot's information gain.
        sort_by_distance: order slots by increasing distance from the robot (else label order).
        action_mask: add an ``action_mask`` key (valid slots) to a ``Dict`` observation.
        normalize: divide positions by the map size and gains by the map area (open choice;
            ``False`` keeps raw cell units as the thesis's description implies).
        teammates: add a ``teammates`` key to the ``Dict`` observation: the other robots'
            ``positions`` (row, col each, in agent order), or ``positions+targets`` (also the
            cell each is heading to; zeros before its first decision or when idle).
        features: ``thesis`` (the axes above) or ``explorer``: size-independent per-slot
            features (:mod:`frontier_marl.sim.features`); the axes above are then unused.
        commit: narrow the action mask to the previous target's slot: ``until-progress``, or
            ``until-reached``; ``none`` keeps every live slot (docs/environment.md).
        tour: with ``features="explorer"``, one more feature per slot: the length of the
            nearest-neighbour tour from the slot's target through every other live slot's
            target (:func:`frontier_marl.sim.features.tour_lengths`).
        turn: with ``features="explorer"``, one more feature per slot: how far the slot's
            target turns the robot away from its motion over its last steps
            (:func:`frontier_marl.sim.features.turn_costs`).
        unknown_near: with ``features="explorer"``, one more feature per slot: the unknown
            fraction of the 25 x 25 square around the slot's target
            (:func:`frontier_marl.sim.features.unknown_near`).
        near_ranges: the unknown_near square's half-side in sensor ranges (rounded, at least
            one cell); ``None`` keeps the fixed 12 cells, whatever the sensor.
        fill: with ``features="explorer"``, one more feature per slot: the cluster's size over
            ``max_cluster_cells`` (:func:`frontier_marl.sim.features.cluster_fill`).
        utility: with ``features="explorer"``, one more feature per slot: cost-utility's log
            utility weighed by the sensor range (:func:`frontier_marl.sim.features.log_utility`).
    """

    centroid: CentroidEncoding = "absolute"
    agent_position: bool = True
    info_gain: bool = False
    sort_by_distance: bool = False
    action_mask: bool = False
    normalize: bool = False
    teammates: TeammateEncoding = "none"
    features: FeatureLayout = "thesis"
    commit: CommitRule = "none"
    tour: bool = False
    turn: bool = False
    unknown_near: bool = False
    near_ranges: float | None = None
    fill: bool = False
    utility: bool = False

    def validate(self) -> None:
        check_choice("features", self.features, get_args(FeatureLayout))
        check_choice("commit", self.commit, get_args(CommitRule))
        check_choice("centroid", self.centroid, get_args(CentroidEncoding))
        check_choice("teammates", self.teammates, get_args(TeammateEncoding))
        for name in (
            "agent_position",
            "info_gain",
            "sort_by_distance",
            "action_mask",
            "normalize",
            "tour",
            "turn",
            "unknown_near",
            "fill",
            "utility",
        ):
            check_bool(name, getattr(self, name))
        for name in ("tour", "turn", "unknown_near", "fill", "utility"):
            if getattr(self, name) and self.features != "explorer":
                raise ValueError(
                    f"{name}=True needs features='explorer' (it is a per-slot feature)"
                )
        if self.near_ranges is not None:
            check_range("near_ranges", self.near_ranges, 0.0, 50.0, low_open=True)
            if not self.unknown_near:
                raise ValueError(
                    "near_ranges sizes the unknown_near square: it needs unknown_near=True"
                )
        if self.centroid == "none" and not self.info_gain:
            raise ValueError(
                "observation is empty: centroid='none' needs info_gain=True "
                "(the thesis's 'info gain only' layout)"
            )

    @property
    def is_dict(self) -> bool:
        """Whether the observation space is a ``Dict`` (else a flat ``Box``)."""
        return (
            self.agent_position
            or self.action_mask
            or self.teammates != "none"
            or self.features == "explorer"
        )


@dataclass(frozen=True)
class RewardConfig:
    """The thesis's two reward tables (docs/environment.md) and their open parameters.

    Attributes:
        kind: ``reward1`` (harsh, padding truncates), ``reward2`` (soft, oscillation penalty),
            or ``travel`` (beyond the thesis, aligned with the distance metrics T90/T99: each
            robot pays ``travel_cost`` per cell it walked, an idle step counting as one cell,
            instead of the no-new-cell and oscillation terms).
        explore_threshold: explored fraction that ends the episode well (open choice;
            0.85 by calibration, docs/calibration.md).
        threshold_basis: what the fraction counts: ``all`` cells known, ``free`` true-free
            cells known, or ``reachable`` free cells reachable from the start that are known.
        max_steps: decision steps before truncation with the step-limit penalty (open choice;
            400, about one step per cell, confirmed by calibration; scales with the area).
        no_progress_limit: consecutive steps without a new cell that truncate the episode.
        oscillation_window: Reward 2 penalises a step whose target differs from the previous
            step's target but equals one of the targets chosen in the ``oscillation_window``
            steps before that (A -> B -> A cycling). Open choice.
        team_weight: how a robot's cell reward mixes its own newly revealed cells (0, the
            default and the thesis with one robot) with the whole team's (1):
            ``cell_reward * ((1 - w) * own + w * team)``. The other shaping terms (no new cell,
            padding, oscillation) stay each robot's own.
        cell_reward: reward per newly known cell.
        no_new_cell_penalty, padding_penalty, goal_bonus, step_limit_penalty,
        no_progress_penalty, oscillation_penalty: the table's constants; ``padding_penalty``
            defaults by ``kind`` (-1.0 for Reward 1, -0.1 otherwise) when left ``None``.
        travel_cost: the ``travel`` reward's term per cell walked (idle: one cell).
    """

    kind: RewardKind = "reward2"
    explore_threshold: float = 0.85
    threshold_basis: ThresholdBasis = "reachable"
    max_steps: int = 400
    no_progress_limit: int = 20
    oscillation_window: int = 4
    team_weight: float = 0.0
    cell_reward: float = 0.05
    no_new_cell_penalty: float = -0.05
    padding_penalty: float | None = None
    goal_bonus: float = 1.0
    step_limit_penalty: float = -1.0
    no_progress_penalty: float = -0.5
    oscillation_penalty: float = -0.05
    travel_cost: float = -0.02

    def validate(self) -> None:
        check_choice("reward", self.kind, get_args(RewardKind))
        check_choice("threshold_basis", self.threshold_basis, get_args(ThresholdBasis))
        check_range("explore_threshold", self.explore_threshold, 0.0, 1.0, low_open=True)
        check_int("max_steps", self.max_steps, 1)
        check_int("no_progress_limit", self.no_progress_limit, 1)
        check_int("oscillation_window", self.oscillation_window, 1)
        check_range("team_weight", self.team_weight, 0.0, 1.0)
        for name in (
            "cell_reward",
            "no_new_cell_penalty",
            "goal_bonus",
            "step_limit_penalty",
            "no_progress_penalty",
            "oscillation_penalty",
            "travel_cost",
        ):
            check_finite(name, getattr(self, name))
        if self.padding_penalty is not None:
            check_finite("padding_penalty", self.padding_penalty)

    @property
    def padding(self) -> float:
        """The padding-slot penalty in force."""
        if self.padding_penalty is not None:
            return self.padding_penalty
        return -1.0 if self.kind == "reward1" else -0.1

    @property
    def padding_truncates(self) -> bool:
        """Reward 1 truncates the episode when a padding slot is chosen."""
        return self.kind == "reward1"


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
        if self.map_path is not None:
            if not isinstance(self.map_path, str):
                raise ValueError(f"map_path must be a file path string, got {self.map_path!r}")
            if self.map_mode != "static":
                raise ValueError(
                    "map_mode must be 'static' with map_path (a file holds one fixed layout)"
                )
            if self.map_scale != 1:
                raise ValueError("map_scale applies to generated layouts, not to map_path")
        check_int("perception_range", self.perception_range, 1, max(self.height, self.width))
        check_choice("sensor", self.sensor, get_args(SensorModel))
        if self.cells_per_step != FULL_PATH:
            check_int("cells_per_step", self.cells_per_step, 1, extra_allowed="'full'")
        check_int("connectivity", self.connectivity, 4, 8)
        check_choice("connectivity", self.connectivity, (4, 8))
        check_int("max_cluster_cells", self.max_cluster_cells, 1)
        check_int("n_slots", self.n_slots, 1, 256)
        check_choice("gain", self.gain, get_args(GainModel))
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
        return _apply_overrides(self, overrides)


#: Presets. ``thesis-20x20`` is the calibrated default (docs/calibration.md). The others are
#: derived from it by rule, not by fitting: ``thesis-30x30`` has size 30x30 and perception
#: range 5 (the thesis's second geometry), ``max_steps`` proportional to the number of cells
#: (400 * 900 / 400) and ``max_cluster_cells`` = 2r + 2 (the edge of a sensor window plus one,
#: 8 at r = 3); ``rooms-32`` is a 32x32 rooms-and-corridors map at the thesis's range (r = 3,
#: ``max_steps`` 400 * 1024 / 400). Every other parameter is unchanged.
PRESETS: dict[str, dict[str, Any]] = {
    "thesis-20x20": {},
    "thesis-30x30": {
        "height": 30,
        "width": 30,
        "perception_range": 5,
        "max_steps": 900,
        "max_cluster_cells": 12,
    },
    "rooms-32": {
        "map_generator": "rooms",
        "height": 32,
        "width": 32,
        "max_steps": 1024,
    },
}

_OBS_KEYS = {f.name for f in dataclasses.fields(ObservationConfig)}
_REWARD_KEYS = {f.name for f in dataclasses.fields(RewardConfig)} - {"kind"}
_ENV_KEYS = {f.name for f in dataclasses.fields(EnvConfig)} - {"observation", "reward"}


def config_keys() -> list[str]:
    """Every flat keyword accepted by :func:`make_config`."""
    return sorted(_ENV_KEYS | _OBS_KEYS | _REWARD_KEYS | {"reward", "preset", "config"})


def make_config(preset: str | None = "thesis-20x20", **overrides: Any) -> EnvConfig:
    """Build a validated :class:`EnvConfig` from a preset plus flat keyword overrides.

    Keys are the fields of :class:`EnvConfig`, :class:`ObservationConfig` and
    :class:`RewardConfig` (``reward`` takes the reward kind, ``reward1`` or ``reward2``).
    A ready ``EnvConfig`` may be passed as ``config=`` instead of a preset.
    """
    base = overrides.pop("config", None)
    if base is None:
        if preset is None:
            preset = "thesis-20x20"
        if preset not in PRESETS:
            raise ValueError(f"preset must be one of {sorted(PRESETS)}, got {preset!r}")
        base = _apply_overrides(EnvConfig(), dict(PRESETS[preset]))
    elif not isinstance(base, EnvConfig):
        raise ValueError(f"config must be an EnvConfig, got {type(base).__name__}")
    return _apply_overrides(base, overrides)


def _apply_overrides(cfg: EnvConfig, overrides: dict[str, Any]) -> EnvConfig:
    unknown = set(overrides) - (_ENV_KEYS | _OBS_KEYS | _REWARD_KEYS | {"reward", "observation"})
    if unknown:
        raise ValueError(
            f"unknown parameter(s) {sorted(unknown)}; allowed: {', '.join(config_keys())}"
        )
    env_kw = {k: v for k, v in overrides.items() if k in _ENV_KEYS}
    if env_kw.get("map_path") is not None:
        if isinstance(env_kw["map_path"], os.PathLike):
            env_kw["map_path"] = os.fspath(env_kw["map_path"])
        if not isinstance(env_kw["map_path"], str):
            raise ValueError(f"map_path must be a file path, got {env_kw['map_path']!r}")
        env_kw.update(_shape_from_map_file(env_kw["map_path"], env_kw))
    obs_kw = {k: v for k, v in overrides.items() if k in _OBS_KEYS}
    rew_kw = {k: v for k, v in overrides.items() if k in _REWARD_KEYS}
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


def config_to_dict(cfg: EnvConfig) -> dict[str, Any]:
    """A flat dictionary that :func:`make_config` turns back into ``cfg``."""
    flat: dict[str, Any] = {k: getattr(cfg, k) for k in sorted(_ENV_KEYS)}
    flat.update({k: getattr(cfg.observation, k) for k in sorted(_OBS_KEYS)})
    flat.update({k: getattr(cfg.reward, k) for k in sorted(_REWARD_KEYS)})
    flat["reward"] = cfg.reward.kind
    return flat
