"""Validation during training: score the greedy policy on held-out episodes, keep the best.

With ``train.validate_every = N`` a run scores its greedy (epsilon = 0) policy every N steps on
``validation_episodes`` episodes of the training env (reset seeds ``validation_seed`` ..,
disjoint from the evaluation's), appends each score to ``RUN/validation.jsonl``, and keeps the
best-scoring policy in ``RUN/best/`` (``model.zip`` + ``model.json``, whose ``validation`` entry
says at which step and with which score). This is SB3's ``EvalCallback(best_model_save_path=...)``
practice; the thesis protocol's episodes are never used to choose. A run on benchmark families
(``train.families``) is scored by :class:`~frontier_marl.training.family_validation.FamilyValidator`
instead: T99 against nearest-path on the families' validation episodes.
"""

from __future__ import annotations

import json
import math
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig
from frontier_marl.evaluation import evaluate
from frontier_marl.policies import ModelPolicy
from frontier_marl.policies.metadata import load_metadata, save_metadata
from frontier_marl.policies.model_files import MODEL_FILE
from frontier_marl.training.settings import TrainSettings

BEST_DIR = "best"
LOG_FILE = "validation.jsonl"


class BestPolicyKeeper:
    """``keeper(model)`` validates ``model`` and saves it to ``RUN/best/`` if it is the best so
    far; returns the validation score (the mean reward, unless ``scorer`` is given: a function
    of the model returning a record with a ``score``, higher is better)."""

    def __init__(
        self,
        run_dir: Path,
        cfg: EnvConfig,
        settings: TrainSettings,
        metadata: Callable[[], dict[str, Any]],
        start_step: int = 0,
        scorer: Callable[[Any], dict[str, Any]] | None = None,
    ) -> None:
        self.run_dir = run_dir
        self.cfg = cfg
        self.episodes = settings.validation_episodes
        self.seed = settings.validation_seed
        self.metadata = metadata
        self.scorer = scorer or self._mean_reward
        self.best_score = -math.inf
        self._forget_after(start_step)

    @property
    def best_dir(self) -> Path:
        return self.run_dir / BEST_DIR

    @property
    def log_path(self) -> Path:
        return self.run_dir / LOG_FILE

    def _forget_after(self, step: int) -> None:
        """On a fresh run, clear old records; on a resumed one, drop those past its step (and
        a best policy saved past it: its session was not continued)."""
        records = [r for r in read_validation_log(self.run_dir) if r["step"] <= step]
        self.log_path.write_text("".join(json.dumps(r) + "\n" for r in records))
        best = load_metadata(self.best_dir / MODEL_FILE)
        if best is not None and best.get("validation", {}).get("step", math.inf) <= step:
            record = best["validation"]
            self.best_score = float(record.get("score", record.get("mean_reward")))
        elif self.best_dir.exists():
            shutil.rmtree(self.best_dir)

    def _mean_reward(self, model: Any) -> dict[str, Any]:
        result = evaluate(
            {"config": self.cfg},
            ModelPolicy(model, name="validation", deterministic=True),
            episodes=self.episodes,
            seed=self.seed,
        )
        return {
            "score": result.mean_reward,
            "mean_reward": result.mean_reward,
            "std_reward": result.std_reward,
            "terminations": result.terminations,
            "episodes": self.episodes,
            "seed": self.seed,
            "map_mode": self.cfg.map_mode,
        }

    def __call__(self, model: Any) -> float:
        record = {"step": int(model.num_timesteps), **self.scorer(model)}
        with self.log_path.open("a") as handle:
            handle.write(json.dumps(record) + "\n")
        if record["score"] > self.best_score:
            self.best_score = record["score"]
            self.best_dir.mkdir(exist_ok=True)
            model.save(self.best_dir / MODEL_FILE)
            meta = self.metadata()
            meta["validation"] = record
            save_metadata(meta, self.best_dir / "model.json")
        return float(record["score"])


def read_validation_log(run_dir: str | Path) -> list[dict[str, Any]]:
    """The records of ``RUN/validation.jsonl`` (empty if there is none)."""
    path = Path(run_dir) / LOG_FILE
    if not path.is_file():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
