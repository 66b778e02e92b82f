"""The package works installed from its wheel, not only from an editable checkout.

A wheel is built from this checkout and installed (without its dependencies, which this
environment already has) into a fresh virtualenv; from a folder outside the repository the
installed command trains a shipped config and runs the main job with tiny budgets, and reads
the shipped example maps and model.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import venv
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The ``bin`` folder of a virtualenv with the wheel installed."""
    root = tmp_path_factory.mktemp("wheel")
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q"]
    subprocess.run(
        [*pip, "wheel", "--no-deps", "--no-build-isolation", "-w", str(root / "dist"), str(REPO)],
        check=True,
        cwd=root,
    )
    (wheel,) = (root / "dist").glob("frontier_marl-*.whl")
    venv.create(root / "venv", system_site_packages=True, with_pip=False)
    bin_dir = root / "venv" / "bin"
    subprocess.run(
        [*pip, "--python", str(bin_dir / "python"), "install", "--no-deps", str(wheel)],
        check=True,
        cwd=root,
    )
    return bin_dir


def run(bin_dir: Path, *args: str, cwd: Path) -> str:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run(
        args, cwd=cwd, env=env, capture_output=True, text=True, check=False, timeout=600
    )
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


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
