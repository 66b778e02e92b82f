"""Evaluation of a trained model with the thesis protocol, beside a heuristic.

The episodes are run by :func:`frontier_marl.evaluation.evaluate` (one protocol for models and
heuristics); an SB3 model acts through :class:`frontier_marl.evaluation.ModelPolicy` with
``deterministic=True`` (epsilon = 0), a map-aware scorer (``explorer``) through its
:class:`~frontier_marl.policies.map_explorer.MapExplorer` (:func:`evaluate_map_scorer`). Before
any episode an SB3 model is checked against the env
(:func:`~frontier_marl.policies.metadata.check_compatible`). Each episode is a task of its own
(:class:`EvaluationTask`), so the episodes can run in worker processes or on a Ray cluster.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig, config_to_dict, make_config
from frontier_marl.evaluation.benchmark.contenders import own_world
from frontier_marl.evaluation.model_refs import ModelRef, ScorerMaker, cached_scorer, source_of
from frontier_marl.evaluation.protocol import evaluate
from frontier_marl.evaluation.records import EvaluationResult
from frontier_marl.policies import ModelPolicy, Policy, make_policy
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_SETTINGS
from frontier_marl.policies.metadata import env_config_from_metadata
from frontier_marl.policies.models import LoadedModel, check_model_env
from frontier_marl.utils.parallel import map_tasks

#: An action taken in more than this share of all decisions flags a degenerate policy.
DEGENERACY_THRESHOLD = 0.9


def degeneracy(shares: Sequence[float], threshold: float = DEGENERACY_THRESHOLD) -> dict[str, Any]:
    """Whether one action takes more than ``threshold`` of all decisions."""
    if not shares:
        return {
            "degenerate": False,
            "dominant_action": None,
            "dominant_share": 0.0,
            "threshold": threshold,
        }
    top = max(range(len(shares)), key=lambda i: shares[i])
    return {
        "degenerate": bool(shares[top] > threshold),
        "dominant_action": int(top),
        "dominant_share": float(shares[top]),
        "threshold": threshold,
    }


@dataclass(frozen=True)
class SB3PolicyMaker:
    """A picklable factory of the saved SB3 model ``ref``'s deterministic policy."""

    ref: ModelRef
    label: str

    def __call__(self) -> Policy:
        return ModelPolicy(self.ref.get().model, name=self.label, deterministic=True)


@dataclass(frozen=True)
class EvaluationTask:
    """One episode of :func:`evaluate_model`, the unit of work: the model (``make`` set: a
    picklable factory of its policy) or the heuristic ``policy`` (seeded with
    ``policy_seed``) from reset seed ``seed``."""

    policy: str
    make: Callable[[], Policy] | None
    config: EnvConfig
    seed: int
    policy_seed: int

    def __str__(self) -> str:
        return f"episode {self.seed} of {self.policy}"


def play_evaluation_episode(task: EvaluationTask) -> EvaluationResult:
    """The protocol on one episode (wherever it runs, the same result)."""
    policy = task.make() if task.make is not None else make_policy(task.policy, task.policy_seed)
    return evaluate({"config": task.config}, policy, episodes=1, seed=task.seed)


def evaluate_model(
    loaded: LoadedModel,
    cfg: EnvConfig,
    episodes: int = 30,
    seed: int = 0,
    heuristics: Sequence[str] = ("greedy-distance",),
    name: str = "model",
    on_episode: Callable[[str, int], None] | None = None,
    jobs: int | None = 1,
    ray_address: str | None = None,
    progress: bool = False,
) -> dict[str, Any]:
    """The SB3 model and each heuristic on the same episodes (seeds ``seed ..
    seed+episodes-1``), in ``jobs`` processes (``None``: every core) or on the Ray cluster at
    ``ray_address`` (:func:`~frontier_marl.utils.parallel.map_tasks`; the same result either
    way).

    Returns a JSON-able dict: ``model`` (the model's row with ``degeneracy``), ``heuristics``
    (one row per heuristic), ``rows`` (all rows, model first), the env config and the model
    file. Rows are :meth:`EvaluationResult.to_dict` outputs (per-episode curves included).
    """
    check_model_env(loaded, cfg)
    make = SB3PolicyMaker(ModelRef(source_of(loaded.path), loaded), name)
    meta = loaded.metadata or {}
    steps = int(getattr(loaded.model, "num_timesteps", meta.get("num_timesteps", 0)))
    result = _beside_heuristics(
        make, name, cfg, episodes, seed, heuristics, on_episode, jobs, ray_address, progress
    )
    return {"model_path": str(loaded.path), "kind": "sb3", "num_timesteps": steps, **result}


def evaluate_map_scorer(
    folder: Path,
    cfg: EnvConfig,
    episodes: int = 30,
    seed: int = 0,
    heuristics: Sequence[str] = ("greedy-distance",),
    name: str = "model",
    jobs: int | None = 1,
    ray_address: str | None = None,
    progress: bool = False,
) -> dict[str, Any]:
    """:func:`evaluate_model` for a saved map-aware scorer (:mod:`frontier_marl.policies.
    map_explorer`, in ``folder``) on ``cfg`` (:func:`map_scorer_env_config`); the result
    records how many labelled candidates it was fitted on (``labels``) instead of steps."""
    source = str(Path(folder).resolve())
    _, metadata = cached_scorer(source)  # fails here (e.g. no torch), not in an episode
    result = _beside_heuristics(
        ScorerMaker(source, name), name, cfg, episodes, seed, heuristics, None, jobs,
        ray_address, progress,
    )  # fmt: skip
    labels = int(metadata.get("labels", 0))
    return {"model_path": source, "kind": "map-scorer", "labels": labels, **result}


def _beside_heuristics(
    make: Callable[[], Policy],
    name: str,
    cfg: EnvConfig,
    episodes: int,
    seed: int,
    heuristics: Sequence[str],
    on_episode: Callable[[str, int], None] | None,
    jobs: int | None,
    ray_address: str | None,
    progress: bool,
) -> dict[str, Any]:
    """The protocol's rows for the policy ``make`` builds and for each heuristic, on the same
    episodes (the part of the result shared by every kind of model)."""
    labels = [name, *heuristics]
    tasks = [
        EvaluationTask(label, make if i == 0 else None, cfg, seed + k, seed)
        for i, label in enumerate(labels)
        for k in range(episodes)
    ]

    def done(index: int, _result: EvaluationResult) -> None:
        if on_episode is not None:
            on_episode(tasks[index].policy, index % episodes)

    results = map_tasks(
        play_evaluation_episode,
        tasks,
        jobs,
        ray_address=ray_address,
        progress=progress,
        unit="ep",
        on_done=done,
    )
    rows = []
    for i in range(len(labels)):
        part = results[i * episodes : (i + 1) * episodes]
        row = replace(part[0], episodes=[r.episodes[0] for r in part]).to_dict()
        row["degeneracy"] = degeneracy(row["action_shares"])
        rows.append(row)
    return {
        "deterministic": True,
        "episodes": episodes,
        "seed": seed,
        "env_config": config_to_dict(cfg),
        "model": rows[0],
        "heuristics": rows[1:],
        "rows": rows,
    }


def evaluation_env_config(
    loaded: LoadedModel,
    preset: str | None = None,
    overrides: dict[str, Any] | None = None,
) -> EnvConfig:
    """The env to evaluate on: the model's training env (from its metadata) with overrides.

    A bare SB3 file has no record of its env: ``preset`` and ``overrides`` must name it
    (ValueError otherwise), and the spaces check still refuses an env whose observations
    differ from the model's in shape, dtype or bounds.
    """
    overrides = dict(overrides or {})
    if loaded.metadata is not None:
        if preset is not None:
            base = make_config(preset)
            saved = env_config_from_metadata(loaded.metadata)
            # keep the model's observation/reward choices, take the preset's geometry
            geometry = {k: getattr(base, k) for k in ("height", "width", "perception_range")}
            return make_config(config=saved, **{**geometry, **overrides})
        return env_config_from_metadata(loaded.metadata, **overrides)
    if preset is None and not overrides:
        raise ValueError(
            f"model {loaded.path} has no model.json, so the env it was trained on is unknown: "
            "name it with --preset and --set KEY=VALUE (e.g. --preset thesis-20x20 "
            "--set normalize=true)"
        )
    return make_config(preset or "thesis-20x20", **overrides)


def map_scorer_env_config(
    preset: str | None = None, overrides: dict[str, Any] | None = None
) -> EnvConfig:
    """The env to evaluate a map-aware scorer on: the world of ``preset`` (default
    ``thesis-20x20``) with ``overrides``, observed as frontier-rule observes it (the scorer
    chooses among frontier-rule's slots). ValueError for an override of an observation setting
    the scorer reads, rather than dropping it."""
    overrides = dict(overrides or {})
    fixed = sorted(
        key for key, value in overrides.items()
        if key in FRONTIER_RULE_SETTINGS and value != FRONTIER_RULE_SETTINGS[key]
    )  # fmt: skip
    if fixed:
        raise ValueError(
            f"a map scorer reads frontier-rule's observation, so {', '.join(fixed)} cannot be "
            f"set (it is {', '.join(repr(FRONTIER_RULE_SETTINGS[k]) for k in fixed)})"
        )
    world = make_config(preset or "thesis-20x20", **overrides)
    return own_world(FRONTIER_RULE_SETTINGS, world)


def format_comparison(result: dict[str, Any]) -> str:
    """A plain-text table: one line per policy, then the degeneracy verdict."""
    lines = []
    header = f"{'policy':<18} {'mean':>8} {'std':>7} {'term.':>7}  action shares"
    lines.append(header)
    lines.append("-" * len(header))
    for row in result["rows"]:
        shares = " ".join(f"{s:.1%}" for s in row["action_shares"])
        lines.append(
            f"{row['policy']:<18} {row['mean_reward']:>8.2f} {row['std_reward']:>7.2f} "
            f"{row['terminations']:>3}/{row['episodes']:<3}  {shares}"
        )
    deg = result["model"]["degeneracy"]
    verdict = (
        f"DEGENERATE: action {deg['dominant_action']} in {deg['dominant_share']:.1%} of steps "
        f"(> {deg['threshold']:.0%})"
        if deg["degenerate"]
        else f"not degenerate (most frequent action {deg['dominant_action']}: "
        f"{deg['dominant_share']:.1%} of steps)"
    )
    lines.append(f"model: {verdict}")
    return "\n".join(lines)
