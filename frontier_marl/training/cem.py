"""The cross-entropy method on a linear slot scorer (``train.algorithm = "cem"``).

The policy scores every valid slot by the dot product of its features with one weight vector
(:class:`~frontier_marl.policies.networks.slot_dqn.LinearSlotScorer`) and takes the best slot. CEM
searches the weights directly on the benchmark's metric, T99, with no value function to
learn: each generation draws ``population`` weight vectors around the current mean (the mean
itself first), plays each on the same fresh episodes of every training family (``episodes``
per family, seeds drawn from the family's training range), scores each by its mean
per-episode T99 relative to the path-only scorer (nearest-path among the slots) on those same
episodes (an episode that misses 99 % counts as +100 %), and moves the mean and the spread to
the ``elite`` best. The ``path`` weight keeps its initial value: multiplying every weight by
a positive number changes no choice, so one weight fixes the scale.

Episodes are played on the batched vector env with ``skip_forced_steps``: only real decisions
reach the scorer. After each generation the mean is validated like a DQN policy
(:class:`~frontier_marl.training.family_validation.FamilyValidator`, validation seeds) and the
best one is kept in ``RUN/best/``; ``RUN/model.zip`` is the last mean. Both are SB3 models
(``MaskedDQN`` with the linear scorer), usable wherever a model is.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import torch

from frontier_marl.config import EnvConfig
from frontier_marl.envs.vector import FrontierVectorEnv
from frontier_marl.evaluation.benchmark.families import family
from frontier_marl.policies.linear_scorer import feature_names, weight_vector
from frontier_marl.policies.metadata import build_metadata, save_metadata
from frontier_marl.policies.networks.slot_dqn import MaskedDQN, SlotDQNPolicy
from frontier_marl.sim.rewards import THRESHOLD
from frontier_marl.training.batched_vec_env import make_batched_vec_env
from frontier_marl.training.family_validation import FAILURE, FamilyValidator
from frontier_marl.training.plots import plot_family_validation
from frontier_marl.training.results import TrainResult
from frontier_marl.training.settings import CEMSettings
from frontier_marl.training.validation import BestPolicyKeeper, read_validation_log
from frontier_marl.utils.progress import progress_bar as make_bar

if TYPE_CHECKING:
    from frontier_marl.envs.vector import FrontierVectorEnv
    from frontier_marl.training.experiment import Experiment

LOG_FILE = "cem.jsonl"


def initial_weights(settings: CEMSettings, names: list[str]) -> np.ndarray:
    return weight_vector(settings.init, names, "cem.init")


def play_t99(cfg: EnvConfig, seeds: list[int], weights: np.ndarray) -> tuple[np.ndarray, int]:
    """One robot's T99 on the episodes reset with ``seeds`` (NaN where 99 % was not reached)
    when it takes the valid slot of highest ``features @ weights``; also the decisions made."""
    return play_scorer(
        cfg, seeds, lambda observations, env: observations["slots"].astype(np.float64) @ weights
    )


def play_scorer(
    cfg: EnvConfig,
    seeds: list[int],
    score: Callable[[dict[str, np.ndarray], FrontierVectorEnv], np.ndarray],
) -> tuple[np.ndarray, int]:
    """:func:`play_t99` with any slot scorer: ``score(observations, env)`` gives the (N,
    n_slots) scores of the N episodes' slots (``env`` for scorers that read more than the
    observation, e.g. the belief maps); the valid slot of highest score is taken."""
    if cfg.n_agents != 1:
        raise ValueError("the cross-entropy method trains one robot (train.agents = [1])")
    env = FrontierVectorEnv(
        num_envs=len(seeds), config=cfg, skip_forced_steps=True, obs_layout="flat"
    )
    observations, _ = env.reset(seed=list(seeds))
    t99 = np.full(len(seeds), np.nan)
    ended = np.zeros(len(seeds), dtype=bool)
    decisions = 0
    while not ended.all():
        scores = np.asarray(score(observations, env), dtype=np.float64)
        scores = np.where(observations["action_mask"] > 0, scores, -np.inf)
        observations, _, terminated, truncated, info = env.step(scores.argmax(axis=1))
        decisions += int((~ended).sum())
        new = (terminated | truncated) & ~ended
        reached = new & (info["end_reason"] == THRESHOLD)
        t99[reached] = info["travelled"][reached]
        ended |= new
    env.close()
    return t99, decisions


def relative_t99(t99: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Per-episode T99 relative to the reference's (:data:`FAILURE` where either missed)."""
    both = ~np.isnan(t99) & ~np.isnan(reference)
    return np.where(both, t99 / np.where(both, reference, 1.0) - 1.0, FAILURE)


def paired_change(t99: np.ndarray, reference: np.ndarray) -> dict[str, float]:
    """The mean of :func:`relative_t99` over two or more episodes (``change``) and its
    standard error (``stderr``)."""
    change = relative_t99(t99, reference)
    return {
        "change": float(change.mean()),
        "stderr": float(change.std(ddof=1) / np.sqrt(change.size)),
    }


def changes_text(changes: Mapping[str, Mapping[str, float]]) -> str:
    """``label change±stderr`` in percent for each labelled :func:`paired_change`."""
    return "  ".join(
        f"{label} {100 * c['change']:+.2f}±{100 * c['stderr']:.2f}" for label, c in changes.items()
    )


def candidate_score(
    configs: list[EnvConfig],
    seeds: list[list[int]],
    reference: list[np.ndarray],
    weights: np.ndarray,
) -> tuple[float, int]:
    """The mean over families (each weighing alike) of the mean relative T99 of ``weights``
    against ``reference`` on each family's ``seeds``; also the decisions played."""
    differences, played = [], 0
    for cfg, family_seeds, base in zip(configs, seeds, reference, strict=True):
        t99, decisions = play_t99(cfg, family_seeds, weights)
        differences.append(relative_t99(t99, base).mean())
        played += decisions
    return float(np.mean(differences)), played


def linear_model(cfg: EnvConfig, weights: np.ndarray, device: str = "cpu") -> Any:
    """A ``MaskedDQN`` whose linear slot scorer holds ``weights`` (for saving and validation)."""
    env = make_batched_vec_env({"config": cfg}, 1)
    model = MaskedDQN(
        SlotDQNPolicy,
        env,
        buffer_size=1,
        learning_starts=0,
        device=device,
        policy_kwargs={"scorer": "linear"},
    )
    set_weights(model, weights)
    env.close()
    return model


def linear_metadata(
    model: Any, cfg: EnvConfig, experiment: Experiment, **extra: Any
) -> dict[str, Any]:
    """The ``model.json`` of a linear slot scorer: the usual metadata, its weights by feature
    name, and ``extra`` (e.g. ``trained_by``)."""
    current = model.policy.q_net.q_net.weight.detach().cpu().numpy()
    weights = {name: float(w) for name, w in zip(feature_names(cfg), current, strict=True)}
    return build_metadata(
        cfg,
        model.observation_space,
        model.action_space,
        policy="SlotPolicy",
        num_timesteps=model.num_timesteps,
        experiment=experiment.to_dict(),
        extra={**extra, "weights": weights},
    )


def save_hand_set(weights: Mapping[str, float], folder: Path, experiment: Experiment) -> None:
    """Save a linear slot scorer with hand-set ``weights`` (by feature name, the others 0) on
    ``experiment``'s observation as a model folder (``model.zip`` and ``model.json``)."""
    cfg = experiment.env_config()
    model = linear_model(cfg, weight_vector(weights, feature_names(cfg), "hand-set weights"))
    folder.mkdir(parents=True, exist_ok=True)
    model.save(folder / "model.zip")
    save_metadata(
        linear_metadata(model, cfg, experiment, trained_by="hand-set"), folder / "model.json"
    )


def set_weights(model: Any, weights: np.ndarray) -> None:
    value = torch.as_tensor(weights, dtype=torch.float32)
    with torch.no_grad():
        for network in (model.policy.q_net, model.policy.q_net_target):
            network.q_net.weight.copy_(value)


@dataclass
class _CEMSearch:
    """The search distribution: the weights' mean and spread (none on the fixed path weight)."""

    mean: np.ndarray
    sigma: np.ndarray
    fixed: int
    reference_weights: np.ndarray  # the path-only scorer every candidate is compared with

    @classmethod
    def start(cls, cem: CEMSettings, names: list[str]) -> _CEMSearch:
        mean = initial_weights(cem, names)
        sigma = np.full(len(names), float(cem.sigma))
        fixed = names.index("path")
        sigma[fixed] = 0.0
        reference_weights = np.zeros(len(names))
        reference_weights[fixed] = mean[fixed]
        return cls(mean, sigma, fixed, reference_weights)

    def generation(
        self,
        cem: CEMSettings,
        rng: np.random.Generator,
        configs: list[EnvConfig],
        ranges: list[Any],
        model: Any,
    ) -> list[float]:
        """Score ``population`` candidates on fresh episodes and move to the elite; the
        candidates' scores (the mean's first). Adds the decisions played to ``model``'s."""
        seeds = [[int(s) for s in rng.choice(r, cem.episodes, replace=False)] for r in ranges]
        reference = [
            play_t99(c, s, self.reference_weights)[0] for c, s in zip(configs, seeds, strict=True)
        ]
        size = len(self.mean)
        candidates = [self.mean] + [
            self.mean + self.sigma * rng.standard_normal(size) for _ in range(cem.population - 1)
        ]
        scores = []
        for weights in candidates:
            score, decisions = candidate_score(configs, seeds, reference, weights)
            scores.append(score)
            model.num_timesteps += decisions
        elite = np.array([candidates[i] for i in np.argsort(scores)[: cem.elite]])
        self.mean = elite.mean(axis=0)
        self.sigma = np.maximum(elite.std(axis=0), cem.min_sigma)
        self.sigma[self.fixed] = 0.0
        return scores


@dataclass
class _CEMRun:
    """One CEM training run: its settings, model, log and start times."""

    experiment: Experiment
    run_dir: Path
    cem: CEMSettings
    configs: list[EnvConfig]
    model: Any
    started: float = 0.0
    cpu_started: float = 0.0

    @property
    def log(self) -> Path:
        return self.run_dir / LOG_FILE

    def metadata(self) -> dict[str, Any]:
        seed = self.experiment.train.seed
        return linear_metadata(
            self.model, self.configs[0], self.experiment, seed=seed, trained_by="cem"
        )

    def start(self) -> BestPolicyKeeper:
        """Create the run folder and an empty log, start the clocks; the keeper of the best
        validated mean."""
        settings = self.experiment.train
        self.run_dir.mkdir(parents=True, exist_ok=True)
        cfg = self.configs[0]
        validator = FamilyValidator(settings.families, settings.validation_episodes, cfg)
        keeper = BestPolicyKeeper(self.run_dir, cfg, settings, self.metadata, 0, validator)
        self.log.write_text("")
        self.started, self.cpu_started = time.perf_counter(), time.process_time()
        return keeper

    def record(self, generation: int, scores: list[float], score: float) -> None:
        """Append one generation's record to the log."""
        record = {
            "generation": generation,
            "decisions": self.model.num_timesteps,
            "mean_vs_path_scorer": scores[0],
            "best_vs_path_scorer": min(scores),
            "validation_vs_nearest_path": -score,
            "weights": self.metadata()["weights"],
            "wall_s": time.perf_counter() - self.started,
        }
        with self.log.open("a") as handle:
            handle.write(json.dumps(record) + "\n")


def _finish(run: _CEMRun, best: float) -> TrainResult:
    """Save the last mean and its metadata, the summary (``best``: the best validation score)
    and the validation plot."""
    model, run_dir, cem = run.model, run.run_dir, run.cem
    wall = time.perf_counter() - run.started
    model.save(run_dir / "model.zip")
    meta = run.metadata()
    meta["training"] = {"wall_time_s": wall, "generations": cem.generations}
    save_metadata(meta, run_dir / "model.json")
    summary = {
        "run_dir": str(run_dir),
        "generations": cem.generations,
        "decisions": model.num_timesteps,
        "wall_time_s": wall,
        "best_validation": None if math.isinf(best) else -best,
        "weights": meta["weights"],
    }
    (run_dir / "cem.json").write_text(json.dumps(summary, indent=2) + "\n")
    plot_family_validation(
        read_validation_log(run_dir),
        run_dir / "validation_t99.png",
        title=f"{run.experiment.name} (seed {run.experiment.train.seed}, "
        f"{cem.generations} generations)",
        xlabel="decisions played in training (CEM)",
    )
    model_path = run_dir / "model.zip"
    return TrainResult(
        run_dir=run_dir,
        model_path=model_path,
        num_timesteps=model.num_timesteps,
        steps_this_session=model.num_timesteps,
        wall_time_s=wall,
        cpu_time_s=time.process_time() - run.cpu_started,
        interrupted=False,
        files={"model": model_path, "metadata": run_dir / "model.json", "log": run.log},
    )


def train_cem(experiment: Experiment, run_dir: Path, progress_bar: bool = True) -> TrainResult:
    """Run CEM for ``experiment`` into ``run_dir`` (summary in ``RUN/cem.json``, one record
    per generation in ``RUN/cem.jsonl``)."""
    settings, cem = experiment.train, CEMSettings(**experiment.cem)
    configs = experiment.env_configs()
    search = _CEMSearch.start(cem, feature_names(configs[0]))
    rng = np.random.default_rng(settings.seed)
    ranges = [family(name).train for name in settings.families]
    model = linear_model(configs[0], search.mean, settings.device)
    model.num_timesteps = 0
    run = _CEMRun(experiment, run_dir, cem, configs, model)
    keeper = run.start()
    bar = make_bar(cem.generations, disable=not progress_bar, desc="cem", unit="gen")
    for generation in range(cem.generations):
        scores = search.generation(cem, rng, configs, ranges, model)
        set_weights(model, search.mean)
        score = keeper(model)
        run.record(generation, scores, score)
        bar.update(1)
        bar.set_postfix(validation=f"{-score:+.1%}")
    bar.close()
    return _finish(run, keeper.best_score)
