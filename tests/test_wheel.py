"""The package works installed from its wheel, not only from an editable checkout.

A wheel is built from a copy of this checkout (so the build leaves nothing in the repository)
and installed into fresh virtualenvs:

* ``installed``: the wheel without its dependencies, which the venv reads from the environment
  running the tests (a system Python or a virtualenv alike); from a folder outside the
  repository the installed command trains a shipped config and runs the main job with tiny
  budgets, and reads the shipped example maps and model;
* ``core_only``: the wheel with its core dependencies only (no ``train`` extra: no torch, no
  SB3), as ``pip install frontier-marl`` gives: every heuristic, the benchmark and the
  renderer run, and a shipped model that needs the extra says so in one line.
"""

from __future__ import annotations

import json
import os
import shutil
import site
import subprocess
import sys
import venv
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PIP = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q"]

HEURISTICS = (
    "greedy-distance", "greedy-gain", "cost-utility", "nearest-path", "frontier-rule", "random"
)  # fmt: skip

pytestmark = pytest.mark.slow  # builds a wheel and installs it twice (about a minute)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The wheel of this checkout, built from a copy of its source."""
    root = tmp_path_factory.mktemp("wheel")
    source = root / "source"
    shutil.copytree(
        REPO,
        source,
        ignore=shutil.ignore_patterns(
            ".git", "build", "dist", "runs", "*.egg-info", "__pycache__", ".*cache", "*venv*"
        ),
    )
    subprocess.run(
        [*PIP, "wheel", "--no-deps", "--no-build-isolation", "-w", str(root / "dist"), str(source)],
        check=True,
        cwd=root,
    )
    (built,) = (root / "dist").glob("frontier_marl-*.whl")
    return built


@pytest.fixture(scope="module")
def installed(wheel: Path) -> Path:
    """The ``bin`` folder of a virtualenv with the wheel installed and the test environment's
    packages readable (a ``.pth`` file lists its site-packages; their own ``.pth`` files, such
    as an editable install of this checkout, are not run)."""
    root = wheel.parent
    venv.create(root / "venv", with_pip=False)
    bin_dir = root / "venv" / "bin"
    purelib = subprocess.run(
        [str(bin_dir / "python"), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    outer = [*site.getsitepackages(), site.getusersitepackages()]
    Path(purelib, "test_environment.pth").write_text("\n".join(outer) + "\n")
    subprocess.run(
        [*PIP, "--python", str(bin_dir / "python"), "install", "--no-deps", str(wheel)],
        check=True,
        cwd=root,
    )
    return bin_dir


@pytest.fixture(scope="module")
def core_only(wheel: Path) -> Path:
    """The ``bin`` folder of a virtualenv with the wheel and its core dependencies only."""
    root = wheel.parent
    venv.create(root / "core", with_pip=True)
    bin_dir = root / "core" / "bin"
    subprocess.run([str(bin_dir / "python"), *PIP[1:], "install", str(wheel)], check=True, cwd=root)
    return bin_dir


def run(bin_dir: Path, *args: str, cwd: Path, expect: int = 0) -> str:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run(
        args, cwd=cwd, env=env, capture_output=True, text=True, check=False, timeout=600
    )
    assert done.returncode == expect, done.stdout + done.stderr
    return done.stdout + done.stderr


def test_the_installed_package_is_the_wheel(installed: Path, tmp_path: Path) -> None:
    code = (
        "import json, frontier_marl\n"
        "from frontier_marl.core.example_maps import example_map_path\n"
        "from frontier_marl.policies.models import pretrained_model_dir\n"
        "from frontier_marl.training.experiment import shipped_configs\n"
        "print(json.dumps([frontier_marl.__file__, str(example_map_path('rooms-32')),"
        " str(pretrained_model_dir('thesis-config01')), shipped_configs()]))"
    )
    package, room, model, configs = json.loads(
        run(installed, str(installed / "python"), "-c", code, cwd=tmp_path)
    )
    venv_root = installed.parent
    for path in (package, room, model):
        assert Path(path).is_relative_to(venv_root), path  # not the checkout
    assert "config01" in configs and "team_rooms64" in configs


def test_installed_commands_train_and_reproduce(installed: Path, tmp_path: Path) -> None:
    command = str(installed / "frontier-marl")
    out = run(
        installed,
        command,
        "train",
        "config01",
        "--steps",
        "2000",
        "--out",
        "run",
        "--no-progress",
        "--set",
        "train.validate_every=0",
        "--set",
        "train.eval_episodes=2",
        cwd=tmp_path,
    )
    assert (tmp_path / "run" / "model.zip").is_file(), out
    run(
        installed,
        command,
        "reproduce",
        "--steps",
        "600",
        "--seeds",
        "0",
        "--episodes",
        "2",
        "--out",
        "reproduce",
        "--no-progress",
        cwd=tmp_path,
    )
    table = json.loads((tmp_path / "reproduce" / "comparison.json").read_text())
    assert table["training"]["steps"] == 600
    assert (tmp_path / "reproduce" / "comparison.md").is_file()


def test_a_core_only_install_runs_the_heuristics_the_benchmark_and_the_renderer(
    core_only: Path, tmp_path: Path
) -> None:
    python, command = str(core_only / "python"), str(core_only / "frontier-marl")
    for extra in ("torch", "stable_baselines3", "supersuit", "ray"):
        run(core_only, python, "-c", f"import {extra}", cwd=tmp_path, expect=1)
    out = run(
        core_only, command, "baselines", "--preset", "thesis-20x20", "--episodes", "2",
        "--policies", ",".join(HEURISTICS), "--json", "baselines.json", "--no-progress",
        cwd=tmp_path,
    )  # fmt: skip
    rows = json.loads((tmp_path / "baselines.json").read_text())
    assert [row["policy"] for row in rows] == list(HEURISTICS)
    out = run(
        core_only, command, "benchmark", "--families", "random-20", "--episodes", "1",
        "--policies", "nearest-path,cost-utility,coordinated-assignment", "--agents", "2",
        "--json", "bench.json", "--no-progress", cwd=tmp_path,
    )  # fmt: skip
    assert json.loads((tmp_path / "bench.json").read_text())["rows"], out
    run(
        core_only, command, "gif", "--policy", "nearest-path", "--preset", "thesis-20x20",
        "--out", "episode.gif", cwd=tmp_path,
    )  # fmt: skip
    assert (tmp_path / "episode.gif").stat().st_size > 0
    shipped = ("explorer", "team-explorer")  # a map scorer (torch) and an SB3 zip
    for args in (["evaluate", "explorer"], *(["benchmark", "--policies", m] for m in shipped)):
        out = run(core_only, command, *args, "--no-progress", cwd=tmp_path, expect=2)
        message = [line for line in out.splitlines() if line.strip()]
        assert len(message) == 1 and "pip install 'frontier-marl[train]'" in message[0], out
