"""Several training runs in worker processes (frontier_marl.training.workers).

Budgets are tiny (a 10 x 10 map, a few thousand steps); nothing here checks learning quality.
"""

from __future__ import annotations

import json
import os
import signal
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("supersuit")

from frontier_marl.training.checkpoints import list_checkpoints  # noqa: E402
from frontier_marl.training.experiment import experiment_from_dict  # noqa: E402
from frontier_marl.training.run_folder import RunFolderError  # noqa: E402
from frontier_marl.training.workers import TrainJob, train_runs  # noqa: E402

pytestmark = pytest.mark.slow  # trains in worker processes


def tiny(seed: int, steps: int = 1500) -> object:
    return experiment_from_dict(
        {
            "name": "tiny",
            "env": {"preset": "thesis-20x20", "height": 10, "width": 10, "perception_range": 2},
            "dqn": {"learning_starts": 100},
            "train": {
                "seed": seed,
                "total_timesteps": steps,
                "checkpoint_every": 0,
                "eval_episodes": 2,
                "log_interval": 2,
            },
        }
    )


def _jobs(root: Path, seeds: list[int], steps: int = 1500) -> list[TrainJob]:
    return [TrainJob(tiny(s, steps), root / f"seed{s}", label=f"seed {s}") for s in seeds]


def _trace(run_dir: Path) -> tuple[list, list]:
    """What a run produced: its logged metrics (wall times left out) and evaluation rewards."""
    rows = [json.loads(line) for line in (run_dir / "metrics.jsonl").read_text().splitlines()]
    rows = [{k: v for k, v in r.items() if not k.startswith("time/")} for r in rows]
    rewards = json.loads((run_dir / "evaluation.json").read_text())["model"]["rewards"]
    return rows, rewards


def test_runs_in_workers_equal_runs_trained_alone(tmp_path: Path) -> None:
    parallel = train_runs(_jobs(tmp_path / "parallel", [0, 1]), workers=2, progress=False)
    alone = train_runs(_jobs(tmp_path / "alone", [0, 1]), workers=1, progress=False)
    assert not parallel.interrupted and not alone.interrupted
    for seed, p, a in zip([0, 1], parallel.results, alone.results, strict=True):
        assert p.num_timesteps == a.num_timesteps == 1500
        assert p.run_dir == tmp_path / "parallel" / f"seed{seed}"
        assert p.evaluation["model"]["rewards"] == a.evaluation["model"]["rewards"]
        assert _trace(p.run_dir) == _trace(a.run_dir)
    # the seeds differ from each other (each worker really trained its own job)
    assert _trace(parallel.results[0].run_dir) != _trace(parallel.results[1].run_dir)


@pytest.fixture
def python_sigint_handler():
    """Python's own SIGINT handler (KeyboardInterrupt) for one test, whatever was installed."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


@pytest.mark.usefixtures("python_sigint_handler")
def test_ctrl_c_stops_every_worker_with_a_checkpoint(tmp_path: Path) -> None:
    """SIGINT in the parent: the running runs end like Ctrl-C (checkpoint, model, no
    evaluation) and the job still waiting for a worker is skipped."""
    jobs = _jobs(tmp_path, [0, 1, 2], steps=100_000)  # a failure ends in minutes, not hangs

    def interrupt_once_training() -> None:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if all((job.run_dir / "metrics.jsonl").is_file() for job in jobs[:2]):
                time.sleep(2.0)
                os.kill(os.getpid(), signal.SIGINT)
                return
            time.sleep(0.2)

    trigger = threading.Thread(target=interrupt_once_training, daemon=True)
    trigger.start()
    outcome = train_runs(jobs, workers=2, progress=False)
    trigger.join()
    assert outcome.interrupted
    first, second, third = outcome.results
    assert third is None and not jobs[2].run_dir.exists()
    for result in (first, second):
        assert result.interrupted and result.evaluation is None
        assert 0 < result.num_timesteps < 100_000
        assert (result.run_dir / "model.zip").is_file()
        [checkpoint] = list_checkpoints(result.run_dir)
        assert checkpoint.step == result.num_timesteps


def test_workers_must_be_positive(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="workers"):
        train_runs(_jobs(tmp_path, [0]), workers=0)


def test_a_failing_run_stops_the_others_and_raises_its_error(tmp_path: Path) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    healthy = TrainJob(tiny(0, steps=100_000), tmp_path / "seed0", label="seed 0")
    broken = TrainJob(tiny(1), blocker / "seed1", label="seed 1")  # its folder cannot exist
    with pytest.raises(RunFolderError, match="cannot write the run folder .*seed1"):
        train_runs([healthy, broken], workers=2, progress=False)
    if not healthy.run_dir.exists():
        # On a loaded machine the broken run can fail before the healthy one starts: the
        # healthy one then never starts (no folder); otherwise it saves a checkpoint.
        return
    [checkpoint] = list_checkpoints(healthy.run_dir)  # stopped early, with a checkpoint
    assert 0 < checkpoint.step < 100_000
    assert (healthy.run_dir / "model.zip").is_file()
