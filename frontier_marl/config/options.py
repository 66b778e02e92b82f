"""What each robot observes and how it is rewarded: :class:`ObservationConfig` and
:class:`RewardConfig` (the thesis's Table 4.1 axes and reward tables), and the names of every
choice-valued option."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

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
