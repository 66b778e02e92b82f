"""Nothing lost, nothing silent: a run folder belongs to one session, a crash loses no record,
a damaged checkpoint is skipped by name, and a model is what it claims (issue 32)."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from frontier_marl.cli.main import main  # noqa: E402
from frontier_marl.policies.model_files import (  # noqa: E402
    CHECKSUMS_FILE,
    find_checkpoint,
    list_checkpoints,
)
from frontier_marl.training.run_folder import LOCK_FILE, RunFolderError, own_run_folder  # noqa: E402

TINY = """
name = "tiny-folder"
description = "a 10 x 10 run for the run-folder tests"

[env]
preset = "thesis-20x20"
height = 10
width = 10
perception_range = 2

[dqn]
learning_starts = 100
buffer_size = 5000

[train]
total_timesteps = 600
checkpoint_every = 200
keep_checkpoints = 3
eval_episodes = 1
log_interval = 1
"""


@pytest.fixture
def config(tmp_path: Path) -> Path:
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    return path


def command(config: Path, out: Path, *extra: str) -> list[str]:
    return ["train", str(config), "--out", str(out), "--no-progress", *extra]


def cli(*args: str) -> subprocess.Popen[str]:
    """``frontier-marl ARGS`` in a process of its own."""
    code = "import sys; from frontier_marl.cli.main import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.Popen(
        [sys.executable, "-c", code, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_for(path: Path, process: subprocess.Popen[str], seconds: float = 120) -> None:
    end = time.monotonic() + seconds
    while not path.exists():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < end, f"{path} did not appear"
        time.sleep(0.05)


# ----------------------------------------------------------------- one owner per folder


@pytest.mark.slow
def test_a_second_process_into_a_folder_in_use_is_refused_and_the_first_finishes(
    config: Path, tmp_path: Path
) -> None:
    out = tmp_path / "run"
    first = cli(*command(config, out, "--steps", "3000"))
    wait_for(out / LOCK_FILE, first)
    second = cli(*command(config, out))
    _, error = second.communicate(timeout=120)
    assert second.returncode == 2
    assert f"is in use by process {first.pid} on {socket.gethostname()}" in error
    assert first.wait(timeout=300) == 0, first.communicate()
    assert (out / "metrics.jsonl").stat().st_size > 0
    sessions = json.loads((out / "run.json").read_text())["sessions"]
    assert [s["status"] for s in sessions] == ["finished"]
    assert not (out / LOCK_FILE).exists()


def test_a_stale_lock_of_a_dead_process_is_taken_over_and_a_foreign_one_is_not(
    tmp_path: Path,
) -> None:
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    lock = run_dir / LOCK_FILE
    lock.write_text(json.dumps({"pid": dead.pid, "host": socket.gethostname()}))
    stale = pytest.warns(UserWarning, match=f"stale lock of process {dead.pid}")
    with stale, own_run_folder(run_dir, fresh=True):
        assert json.loads(lock.read_text())["pid"] == os.getpid()
    assert not lock.exists()
    lock.write_text(json.dumps({"pid": 1, "host": "elsewhere", "started_at": "noon"}))
    busy = pytest.raises(RunFolderError, match=f"in use by process 1 on elsewhere.*delete {lock}")
    with busy, own_run_folder(run_dir, fresh=True):
        pass
    assert lock.exists()  # never taken over


def test_a_fresh_run_never_overwrites_files_already_in_the_folder(
    config: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / "evaluation.json").write_text('{"mine": true}')
    (out / "metrics.jsonl").write_text("mine\n")
    assert main(command(config, out)) == 2
    error = capsys.readouterr().err
    assert "already holds a run (evaluation.json, metrics.jsonl)" in error and "--resume" in error
    assert (out / "evaluation.json").read_text() == '{"mine": true}'
    assert (out / "metrics.jsonl").read_text() == "mine\n"
    assert not (out / LOCK_FILE).exists()


def test_an_unwritable_run_folder_is_a_clear_error(
    config: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    def refuse(self: Path, *args: object, **kwargs: object) -> None:
        raise PermissionError(13, "Permission denied", str(self))

    monkeypatch.setattr(Path, "mkdir", refuse)
    assert main(command(config, tmp_path / "locked")) == 2
    error = capsys.readouterr().err
    assert "cannot write the run folder" in error and "permission denied" in error
    assert "Traceback" not in error
    monkeypatch.undo()
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    assert main(command(config, blocker / "run")) == 2
    assert "cannot write the run folder" in capsys.readouterr().err


# ----------------------------------------------------------------- crashes lose nothing


@pytest.mark.slow
def test_a_killed_session_stays_on_record_and_resume_continues_from_its_checkpoint(
    config: Path, tmp_path: Path
) -> None:
    out = tmp_path / "run"
    process = cli(*command(config, out, "--steps", "200000", "--set", "train.eval_episodes=0"))
    wait_for(out / "checkpoints" / "step_000000400", process)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert (out / LOCK_FILE).exists()  # left behind by the killed process
    resumed = cli("train", "--resume", str(out), "--steps", "1000", "--no-progress")
    output, error = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, error
    assert f"stale lock of process {process.pid}" in error
    sessions = json.loads((out / "run.json").read_text())["sessions"]
    assert [s["status"] for s in sessions] == ["killed", "finished"]
    assert sessions[0]["start_step"] == 0 and "end_step" not in sessions[0]
    assert sessions[1]["start_step"] >= 400 and sessions[1]["end_step"] == 1000


def test_a_damaged_newest_checkpoint_is_named_and_the_previous_one_resumed(
    config: Path, tmp_path: Path, capsys
) -> None:
    out = tmp_path / "run"
    assert main(command(config, out)) == 0
    steps = [c.step for c in list_checkpoints(out)]
    assert steps == [200, 400, 600]
    assert all((c.path / CHECKSUMS_FILE).is_file() for c in list_checkpoints(out))
    newest = list_checkpoints(out)[-1]
    buffer = newest.replay_buffer.read_bytes()
    newest.replay_buffer.write_bytes(buffer[: len(buffer) // 2])  # a crash mid-write
    with pytest.warns(UserWarning, match=f"checkpoint {newest.path} is damaged"):
        assert find_checkpoint(out).step == 400
    with pytest.raises(ValueError, match="replay_buffer.pkl does not match its checksum"):
        find_checkpoint(newest.path)
    with pytest.warns(UserWarning, match="replay_buffer.pkl does not match"):
        assert main(["train", "--resume", str(out), "--steps", "800", "--no-progress"]) == 0
    assert "resuming at step 400" in capsys.readouterr().out
    sessions = json.loads((out / "run.json").read_text())["sessions"]
    assert [(s["start_step"], s["end_step"]) for s in sessions] == [(0, 600), (400, 800)]


# ----------------------------------------------------------------- models are what they claim


@pytest.fixture(scope="module")
def model_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("model")
    (root / "tiny.toml").write_text(TINY.replace("eval_episodes = 1", "eval_episodes = 0"))
    out = root / "run"
    assert main(command(root / "tiny.toml", out, "--steps", "200")) == 0
    return out


def copy_model(model_run: Path, folder: Path, metadata: bool = True) -> Path:
    folder.mkdir()
    (folder / "model.zip").write_bytes((model_run / "model.zip").read_bytes())
    if metadata:
        (folder / "model.json").write_text((model_run / "model.json").read_text())
    return folder / "model.zip"


def test_a_model_without_metadata_needs_its_env_named_and_its_bounds_checked(
    model_run: Path, tmp_path: Path, capsys
) -> None:
    bare = copy_model(model_run, tmp_path / "bare", metadata=False)
    assert main(["evaluate", str(bare), "--episodes", "1", "--no-progress"]) == 2
    assert "has no model.json" in capsys.readouterr().err
    argv = ["evaluate", str(bare), "--episodes", "1", "--no-progress", "--preset", "thesis-20x20"]
    sizes = ["--set", "height=10", "--set", "width=10", "--set", "perception_range=2"]
    assert main([*argv, *sizes, "--set", "normalize=true"]) == 2
    assert "bounds differ" in capsys.readouterr().err  # trained on raw observations
    assert main([*argv, *sizes]) == 0  # the env it was trained on, named


def test_a_damaged_model_file_is_named_by_every_command(
    model_run: Path, tmp_path: Path, capsys
) -> None:
    cut = copy_model(model_run, tmp_path / "cut")
    data = cut.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    assert main(["evaluate", str(cut), "--episodes", "1", "--no-progress"]) == 2
    error = capsys.readouterr().err
    assert f"cannot load model {cut}: the file is damaged" in error and "Traceback" not in error
    argv = ["benchmark", "--families", "random-20", "--episodes", "1", "--no-progress"]
    assert main([*argv, "--policies", str(cut)]) == 2
    assert f"cannot load model {cut}" in capsys.readouterr().err
    short = copy_model(model_run, tmp_path / "short")
    meta = short.with_name("model.json")
    meta.write_text(meta.read_text()[:50])
    assert main(["evaluate", str(short), "--episodes", "1", "--no-progress"]) == 2
    assert f"model metadata {meta} is not valid JSON" in capsys.readouterr().err
