"""map_tasks: task order, errors that name the task, dead workers, and the same benchmark and
evaluation results in one process, in worker processes and on a Ray instance."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from frontier_marl.cli.main import main
from frontier_marl.utils import parallel
from frontier_marl.utils.parallel import WorkerDied, check_jobs, map_tasks

BENCH = ["benchmark", "--families", "random-20,rooms-32", "--policies", "nearest-path,cost-utility"]
BENCH += ["--episodes", "3", "--no-progress"]


def square(x: int) -> int:
    return x * x


def fails_on_three(x: int) -> int:
    if x == 3:
        raise ZeroDivisionError(f"task {x} divides by zero")
    return x


def dies_on_two(x: int) -> int:
    if x == 2:
        os._exit(1)  # a worker killed from outside looks the same
    return x


def rows_of(path: Path) -> list[dict]:
    rows = json.loads(path.read_text())["rows"]
    for row in rows:
        row.pop("wall_seconds")  # the only field that depends on the machine
    return rows


# ----------------------------------------------------------------- map_tasks


@pytest.mark.parametrize("jobs", [1, 2])
def test_results_come_back_in_task_order(jobs: int) -> None:
    seen: list[int] = []
    tasks = list(range(7))
    out = map_tasks(square, tasks, jobs, on_done=lambda i, r: seen.append(i), progress=True)
    assert out == [x * x for x in tasks] and sorted(seen) == tasks
    assert map_tasks(square, [], jobs) == []


def test_forkserver_workers_give_the_same_results(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(parallel, "start_method", lambda: "forkserver")  # as with torch loaded
    assert map_tasks(square, range(5), 2) == [0, 1, 4, 9, 16]


@pytest.mark.parametrize("jobs", [0, -1, 1.5, True, "2"])
def test_jobs_below_one_are_refused_by_name(jobs: object) -> None:
    with pytest.raises(ValueError, match="jobs must be an integer >= 1"):
        map_tasks(square, [1], jobs)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="--jobs must"):
        check_jobs(jobs, "--jobs")  # type: ignore[arg-type]
    assert check_jobs(None) == parallel.default_jobs() >= 1


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_failing_task_raises_its_error_naming_the_task(jobs: int) -> None:
    with pytest.raises(ZeroDivisionError, match="task 3 divides") as info:
        map_tasks(fails_on_three, range(6), jobs, label=lambda x: f"task number {x}")
    assert any("task number 3" in note for note in info.value.__notes__)


def test_a_dead_worker_raises_instead_of_hanging() -> None:
    with pytest.raises(WorkerDied, match="worker process died.*first unfinished task was"):
        map_tasks(dies_on_two, range(4), 2)


def test_what_cannot_be_pickled_is_named() -> None:
    def name(task: object) -> str:
        return "the lambda" if callable(task) else f"task {task}"

    with pytest.raises(ValueError, match="the lambda cannot be sent to worker processes"):
        map_tasks(square, [1, lambda: 2], 2, label=name)


# ----------------------------------------------------------------- the commands


def test_benchmark_rows_are_the_same_with_any_number_of_jobs(tmp_path: Path) -> None:
    for jobs in ("1", "2"):
        assert main([*BENCH, "--jobs", jobs, "--json", str(tmp_path / f"{jobs}.json")]) == 0
    one, two = rows_of(tmp_path / "1.json"), rows_of(tmp_path / "2.json")
    assert one == two
    assert [(r["family"], r["policy"]) for r in two] == [
        ("random-20", "nearest-path"), ("random-20", "cost-utility"),
        ("rooms-32", "nearest-path"), ("rooms-32", "cost-utility"),
    ]  # fmt: skip
    assert [e["seed"] for e in two[3]["per_episode"]] == [900_000, 900_001, 900_002]


def test_evaluate_gives_the_same_result_with_any_number_of_jobs(tmp_path: Path) -> None:
    pytest.importorskip("stable_baselines3")
    argv = ["evaluate", "thesis-config01", "--episodes", "3", "--no-progress"]
    argv += ["--heuristics", "random"]
    for jobs in ("1", "2"):
        assert main([*argv, "--jobs", jobs, "--json", str(tmp_path / f"{jobs}.json")]) == 0
    one = json.loads((tmp_path / "1.json").read_text())
    assert one == json.loads((tmp_path / "2.json").read_text())
    assert [row["policy"] for row in one["rows"]] == ["model", "random"]


@pytest.mark.parametrize("command", [["benchmark"], ["evaluate", "thesis-config01"]])
@pytest.mark.parametrize("jobs", ["0", "-2"])
def test_cli_jobs_must_be_positive(command, jobs, capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main([*command, "--jobs", jobs])
    assert exc.value.code == 2
    assert "argument --jobs: expected an integer >= 1" in capsys.readouterr().err


def test_ray_address_without_ray_names_the_extra(monkeypatch, capsys) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray now fails
    assert main([*BENCH, "--ray-address", "auto"]) == 2
    assert 'pip install "frontier-marl[ray]"' in capsys.readouterr().err
    with pytest.raises(ImportError, match="frontier-marl"):
        map_tasks(square, [1], ray_address="auto")


# ----------------------------------------------------------------- Ray


@pytest.fixture(scope="module")
def ray_address():
    """A local Ray instance for this module's tests: its address."""
    ray = pytest.importorskip("ray")
    context = ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield context.address_info["address"]
    ray.shutdown()


@pytest.mark.slow
def test_map_tasks_on_ray(ray_address: str) -> None:
    # functions of an installed module: Ray's workers do not see the tests folder
    assert map_tasks(math.sqrt, [0, 1, 4], ray_address=ray_address) == [0.0, 1.0, 2.0]
    with pytest.raises(ValueError, match="math domain error") as info:
        map_tasks(math.sqrt, [4, -1, 9], ray_address=ray_address, label=lambda x: f"sqrt({x})")
    assert any("raised on Ray by sqrt(-1)" in note for note in info.value.__notes__)


@pytest.mark.slow
def test_benchmark_on_a_ray_cluster_gives_the_same_rows(ray_address: str, tmp_path: Path) -> None:
    """The command in its own process joins the running instance as a cluster client."""
    out = tmp_path / "ray.json"
    argv = [*BENCH, "--ray-address", ray_address, "--json", str(out)]
    command = [sys.executable, "-m", "frontier_marl", *argv]
    subprocess.run(command, check=True, capture_output=True, timeout=300)
    assert main([*BENCH, "--jobs", "1", "--json", str(tmp_path / "one.json")]) == 0
    assert rows_of(out) == rows_of(tmp_path / "one.json")


def test_the_speed_script_reports_both_runs(tmp_path: Path) -> None:
    from frontier_marl.experiments.speed import bench_jobs

    out = tmp_path / "jobs.json"
    argv = ["--repeats", "1", "--episodes", "2", "--families", "random-20"]
    assert bench_jobs.main([*argv, "--policies", "nearest-path", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert [run["jobs"] for run in report["runs"]] == [1, 2] and len(report["speedups"]) == 1
    assert all(run["wall_s"] > 0 for run in report["runs"])


@pytest.mark.slow
def test_cost_regression_labels_are_the_same_in_worker_processes() -> None:
    pytest.importorskip("torch")
    import numpy as np

    from frontier_marl.training.cost_regression import label_round
    from frontier_marl.training.settings import RegressionSettings

    jobs = [("random-20", 1), ("random-20", 2)]
    one, two = (
        label_round(jobs, None, RegressionSettings(label_workers=workers), seed=0)
        for workers in (1, 2)
    )
    assert len(one) == len(two) > 0
    for name in ("crops", "features", "cost", "decision", "family"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name))
