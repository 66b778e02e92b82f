"""What a training session returns, whatever the algorithm."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


@dataclass
class TrainResult:
    """What :func:`frontier_marl.training.train.train` produced."""

    run_dir: Path
    model_path: Path
    num_timesteps: int
    steps_this_session: int
    wall_time_s: float
    cpu_time_s: float
    interrupted: bool
    evaluation: dict[str, Any] | None = None
    best_evaluation: dict[str, Any] | None = None  # of RUN/best/ (with train.validate_every)
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def steps_per_second(self) -> float:
        return self.steps_this_session / self.wall_time_s if self.wall_time_s > 0 else 0.0
