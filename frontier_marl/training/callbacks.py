"""SB3 callbacks and logger outputs of a training run; each does O(1) work per step."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.logger import KVWriter

from frontier_marl.utils.progress import progress_bar


class Periodic(BaseCallback):
    """Calls ``action(model)`` every ``every`` environment steps, counted from step 0 (so a
    resumed run keeps the same steps); with ``log_key``, logs what it returns under that key.
    Runs the periodic checkpoints and validations of a training run."""

    def __init__(
        self, every: int, action: Callable[[Any], Any], log_key: str | None = None
    ) -> None:
        super().__init__()
        if every < 1:
            raise ValueError(f"the interval of a periodic callback must be >= 1, got {every}")
        self.every = every
        self.action = action
        self.log_key = log_key
        self._next = every

    def _on_training_start(self) -> None:
        self._next = (self.model.num_timesteps // self.every + 1) * self.every

    def _on_step(self) -> bool:
        if self.model.num_timesteps >= self._next:
            value = self.action(self.model)
            if self.log_key is not None:
                self.logger.record(self.log_key, value)
            self._next = (self.model.num_timesteps // self.every + 1) * self.every
        return True


class ProgressBar(BaseCallback):
    """A progress bar (:mod:`frontier_marl.utils.progress`) over the session's steps, with the
    rolling episode reward and epsilon. Unlike SB3's ``ProgressBarCallback`` (a rich bar
    redrawn from every step, which cost about a quarter of the training time here) it touches
    the bar every ``every`` steps.
    """

    def __init__(self, every: int = 500) -> None:
        super().__init__()
        self.every = every
        self.pbar: Any = None
        self._shown = 0
        self._next = 0

    def _on_training_start(self) -> None:
        total = int(self.locals["total_timesteps"])
        self._shown = self.model.num_timesteps
        self._next = self._shown + self.every
        self.pbar = progress_bar(total, initial=self._shown, unit="step", smoothing=0.05)

    def _on_step(self) -> bool:
        if self.model.num_timesteps >= self._next:
            self._refresh()
        return True

    def _refresh(self) -> None:
        steps = self.model.num_timesteps
        self.pbar.update(steps - self._shown)
        self._shown = steps
        self._next = steps + self.every
        episodes = self.model.ep_info_buffer
        rate = getattr(self.model, "exploration_rate", None)  # DQN's epsilon; PPO has none
        postfix = {} if rate is None else {"eps": f"{rate:.2f}"}
        if episodes:
            postfix["ep_rew"] = f"{sum(e['r'] for e in episodes) / len(episodes):.2f}"
        self.pbar.set_postfix(postfix, refresh=False)

    def _on_training_end(self) -> None:
        self.close()

    def close(self) -> None:
        if self.pbar is not None:
            self._refresh()
            self.pbar.close()
            self.pbar = None


class JsonLinesWriter(KVWriter):
    """SB3 logger output: one JSON object per dump (``{"step": ..., "rollout/...": ...}``),
    appended to a file, so a resumed run keeps extending the same record."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file = self.path.open("a", buffering=1, encoding="utf-8")

    def write(
        self, key_values: dict[str, Any], key_excluded: dict[str, tuple[str, ...]], step: int = 0
    ) -> None:
        row: dict[str, Any] = {"step": int(step)}
        for key, value in key_values.items():
            number = _as_number(value)
            if number is not None:
                row[key] = number
        self._file.write(json.dumps(row) + "\n")

    def close(self) -> None:
        if not self._file.closed:
            self._file.close()


def _as_number(value: Any) -> float | int | None:
    if isinstance(value, bool):
        return int(value)
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    if not math.isfinite(number):
        return None
    return int(number) if isinstance(value, int) else number


def read_metrics(path: str | Path) -> list[dict[str, Any]]:
    """The rows of a ``metrics.jsonl`` file (empty when it does not exist)."""
    path = Path(path)
    if not path.is_file():
        return []
    rows = []
    for line in path.read_text(encoding="utf-8").splitlines():
        line = line.strip()
        if line:
            try:
                rows.append(json.loads(line))
            except json.JSONDecodeError:
                continue  # a line cut short by a crash
    return rows


def truncate_metrics(path: str | Path, last_step: int) -> None:
    """Drop rows logged after ``last_step`` (used when a run resumes from a checkpoint)."""
    path = Path(path)
    rows = [row for row in read_metrics(path) if row.get("step", 0) <= last_step]
    if path.is_file():
        path.write_text("".join(json.dumps(row) + "\n" for row in rows), encoding="utf-8")
