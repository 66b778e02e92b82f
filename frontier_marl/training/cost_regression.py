"""``train.algorithm = "cost-regression"``: the map-aware explorer, fitted to true-map costs.

Each round (``[regression]``, :class:`~frontier_marl.training.settings.RegressionSettings`):

1. **label**: ``label_episodes`` fresh training episodes of every family (seeds from the
   family's training range) are played in the scorer's env (frontier-rule's observation on the
   family's world); round 0 follows frontier-rule, later rounds the scorer with the rule taking
   a ``rule_share`` of the decisions (DAgger). Every real decision (or one in
   ``label_every``; a family may set both counts for itself in ``per_family``) is labelled
   with each candidate's cost-to-go on the true map (:mod:`~frontier_marl.training.
   cost_to_go`; the rollouts finished by ``finisher``), in ``label_workers`` processes;
   ``RUN/labels/round<r>.npz``;
2. **fit**: a new scorer on every label so far (:mod:`~frontier_marl.training.regression`),
   on one torch thread whatever ``train.torch_threads`` says (:func:`fitted`);
3. **validate**: the scorer and frontier-rule on the first ``train.validation_episodes``
   validation episodes of every family; the score is minus the mean per-episode relative T99
   difference to the rule (``RUN/validation.jsonl``); the best round's scorer is kept in
   ``RUN/best/``, the last in ``RUN/``.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch

from frontier_marl.config import EnvConfig, make_config
from frontier_marl.evaluation.benchmark.families import family, variant_configs, world_settings
from frontier_marl.evaluation.benchmark.run import Contender, heuristic, run_family
from frontier_marl.evaluation.records import level_key
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_WEIGHTS
from frontier_marl.policies.linear_scorer import feature_names, weight_vector
from frontier_marl.policies.lookahead import LinearScorerBase
from frontier_marl.policies.map_crops import crop_shape
from frontier_marl.policies.map_explorer import (
    MAP_EXPLORER_SETTINGS,
    MapExplorer,
    new_scorer,
    save_map_explorer,
)
from frontier_marl.training.cost_to_go import Candidates, Samples, label_episode
from frontier_marl.training.experiment import Experiment
from frontier_marl.training.family_validation import FAILURE
from frontier_marl.training.regression import family_weights, fit, group
from frontier_marl.training.results import TrainResult
from frontier_marl.training.settings import RegressionSettings
from frontier_marl.utils.parallel import map_tasks
from frontier_marl.utils.progress import progress_bar as make_bar

LOG_FILE = "validation.jsonl"


def scorer_config(world: EnvConfig) -> EnvConfig:
    """The scorer's env on a family's world: frontier-rule's observation settings."""
    return make_config(None, **{**world_settings(world), **MAP_EXPLORER_SETTINGS})


def _round_record(
    model: Any, validation: Validation, reg: RegressionSettings, round_: int, n_labels: int
) -> dict[str, Any]:
    """Validate ``model`` at every rule weight; the record of the round at the best one."""
    tried = {weight: validation(model, weight) for weight in reg.rule_weights}
    weight = max(tried, key=lambda w: tried[w]["score"])
    record = {"round": round_, "labels": n_labels, **tried[weight]}
    record["rule_weight"] = weight
    record["by_rule_weight"] = {str(w): t["vs_frontier_rule"] for w, t in tried.items()}
    record["by_rule_weight_and_family"] = {str(w): t["by_family"] for w, t in tried.items()}
    return record


def train_cost_regression(
    experiment: Experiment, run_dir: Path, progress_bar: bool = True
) -> TrainResult:
    """Run the rounds of the module docstring for ``experiment`` into ``run_dir``."""
    settings = experiment.train
    reg = RegressionSettings(**experiment.regression)
    torch.manual_seed(settings.seed)
    started, cpu_started = time.perf_counter(), time.process_time()
    rng = np.random.default_rng(settings.seed)
    names = list(settings.families)
    count = {name: reg.rounds * reg.label_episodes_of(name) for name in names}
    seeds = {name: rng.permutation(np.asarray(family(name).train))[: count[name]] for name in names}
    validation = Validation(names, settings.validation_episodes)
    labels, model, best = [], None, -np.inf
    (run_dir / "labels").mkdir(parents=True, exist_ok=True)
    log = run_dir / LOG_FILE
    log.write_text("")
    bar = make_bar(reg.rounds, disable=not progress_bar, desc="rounds", unit="round")
    for round_ in range(reg.rounds):
        jobs = [
            (name, int(seed))
            for name in names
            for seed in np.array_split(seeds[name], reg.rounds)[round_]
        ]
        state = None if model is None else model.state_dict()
        samples = label_round(jobs, state, reg, settings.seed + round_, progress_bar, round_)
        samples.save(run_dir / "labels" / f"round{round_}.npz")
        labels.append(samples)
        model = fitted(Samples.join(labels), reg, settings.seed + round_)
        record = _round_record(model, validation, reg, round_, len(Samples.join(labels)))
        record["wall_s"] = time.perf_counter() - started
        with log.open("a") as handle:
            handle.write(json.dumps(record) + "\n")
        meta = {"trained_by": "cost-regression", "experiment": experiment.to_dict(), **record}
        if record["score"] > best:
            best = record["score"]
            save_map_explorer(model, run_dir / "best", meta)
        bar.update(1)
        bar.set_postfix(vs_rule=f"{-record['score']:+.1%}")
    bar.close()
    save_map_explorer(model, run_dir, meta)
    return _result(run_dir, len(Samples.join(labels)), started, cpu_started)


def _result(run_dir: Path, n_labels: int, started: float, cpu_started: float) -> TrainResult:
    """The run's result: the labels count as its steps."""
    wall = time.perf_counter() - started
    return TrainResult(
        run_dir=run_dir,
        model_path=run_dir / "model.pt",
        num_timesteps=n_labels,
        steps_this_session=n_labels,
        wall_time_s=wall,
        cpu_time_s=time.process_time() - cpu_started,
        interrupted=False,
        files={"model": run_dir / "model.pt", "best": run_dir / "best", "log": run_dir / LOG_FILE},
    )


def label_round(
    jobs: list[tuple[str, int]],
    state: dict[str, Any] | None,
    reg: RegressionSettings,
    seed: int,
    progress: bool = False,
    round_: int = 0,
) -> Samples:
    """The labels of ``jobs`` (family, seed), in ``reg.label_workers`` processes
    (:func:`~frontier_marl.utils.parallel.map_tasks`), with a bar over the episodes when
    ``progress``."""
    tasks = [(name, ep, state, reg, seed) for name, ep in jobs]
    labelled = map_tasks(
        _label,
        tasks,
        reg.label_workers,
        label=_label_name,
        progress=progress,
        desc=f"labels of round {round_}",
        unit="episode",
    )
    return Samples.join(labelled)


def _label_name(task: tuple[Any, ...]) -> str:
    return f"the labels of episode {task[1]} of {task[0]}"


def _label(task: tuple[str, int, dict[str, Any] | None, RegressionSettings, int]) -> Samples:
    name, episode, state, reg, seed = task
    torch.set_num_threads(1)
    (world,) = variant_configs(family(name), None, 1)
    cfg = scorer_config(world)
    weights = weight_vector(FRONTIER_RULE_WEIGHTS, feature_names(cfg), "frontier-rule")
    rule = weights.astype(np.float32)
    model = None
    if state is not None:
        model = new_scorer(len(rule), reg.scorer_width, reg.scorer_members)
        model.load_state_dict(state)
        model.eval()
    choices = np.random.default_rng([seed, episode])

    def behaviour(obs: dict[str, np.ndarray], candidates: Candidates) -> int:
        if model is None or choices.random() < reg.rule_share:
            return int(candidates.slots[int(np.argmax(candidates.features @ rule))])
        crops = torch.as_tensor(candidates.crops)
        features = torch.as_tensor(candidates.features)[None]
        with torch.no_grad():
            regret = model(crops, features, torch.ones((1, len(candidates.slots)), dtype=bool))
        return int(candidates.slots[int(torch.argmin(regret[0]))])

    base = LinearScorerBase(cfg, weights) if reg.finisher == "frontier-rule" else None
    every = reg.label_every_of(name)
    completions = reg.completions_of(name)
    return label_episode(cfg, episode, behaviour, base, name, completions, every)


def fitted(
    samples: Samples,
    reg: RegressionSettings,
    seed: int,
    loss: str = "regret",
    scale: np.ndarray | None = None,
) -> Any:
    """A new scorer fitted to ``samples`` (with ``loss``, :data:`~frontier_marl.training.
    regression.LOSSES`, on the target of :func:`~frontier_marl.training.regression.group`),
    initialised and shuffled from ``seed`` alone: the same arguments give the same scorer, in
    any process. The fit runs on one torch thread: on two, the same fit gave different
    weights from one process to the next (measured 2026-12-07), on one the same every time,
    for about 1.4 times the fit's time."""
    decisions = group(samples, int(MAP_EXPLORER_SETTINGS["n_slots"]), scale)
    with torch.random.fork_rng(devices=[]):  # the caller's torch generator is left as it was
        torch.manual_seed(seed)
        team = decisions.crops.shape[1] == crop_shape(team=True)[0]  # teammates' channels
        model = new_scorer(decisions.features.shape[-1], reg.scorer_width, reg.scorer_members, team)
    valid = decisions.features[decisions.mask]
    model.feature_mean.copy_(valid.mean(0))
    model.feature_std.copy_(valid.std(0).clamp(min=1e-3))
    weights = family_weights(samples, reg.balance) if reg.balance else None
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        fit(
            model,
            decisions,
            reg.fit_epochs,
            reg.fit_batch,
            reg.fit_rate,
            seed,
            loss=loss,
            weights=weights,
            schedule=reg.fit_schedule,
        )
    finally:
        torch.set_num_threads(threads)
    model.eval()
    return model


class Validation:
    """``validation(model)``: the scorer against frontier-rule on validation episodes."""

    def __init__(self, names: list[str], episodes: int) -> None:
        self.families = [family(name) for name in names]
        self.episodes = episodes
        self.worlds = [variant_configs(fam, None, 1) for fam in self.families]
        rule = heuristic("frontier-rule")
        pairs = zip(self.families, self.worlds, strict=True)
        self.rule = [self._t99(fam, rule, worlds) for fam, worlds in pairs]

    def _t99(self, fam: Any, contender: Contender, worlds: list[EnvConfig]) -> list[float | None]:
        result = run_family(fam, contender, worlds, self.episodes, split="validation")
        return [e.cells_to_coverage.get(level_key(0.99)) for e in result.episodes]

    def __call__(self, model: Any, rule_weight: float = 0.0) -> dict[str, Any]:
        def make() -> MapExplorer:
            return MapExplorer(model, "explorer", rule_weight)

        learner = Contender("explorer", False, make, scorer_config)
        by_family, differences = {}, []
        for fam, worlds, rule in zip(self.families, self.worlds, self.rule, strict=True):
            t99 = self._t99(fam, learner, worlds)
            diffs = [
                FAILURE if a is None or b is None else a / b - 1.0
                for a, b in zip(t99, rule, strict=True)
            ]
            by_family[fam.name] = float(np.mean(diffs))
            differences += diffs
        mean = float(np.mean(differences))
        return {
            "score": -mean,
            "vs_frontier_rule": mean,
            "by_family": by_family,
            "episodes": self.episodes,
            "split": "validation",
        }

    @staticmethod
    def print_results(prefix: str, results: dict[str, dict[str, Any]]) -> None:
        """One line per rule weight of ``results`` (this class's results by rule weight),
        each starting with ``prefix``."""
        for weight, result in results.items():
            families = ", ".join(f"{n} {v:+.1%}" for n, v in result["by_family"].items())
            print(
                f"{prefix}, rule weight {weight}: T99 vs frontier-rule "
                f"{result['vs_frontier_rule']:+.1%} ({families})",
                flush=True,
            )
