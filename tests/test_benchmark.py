"""The benchmark: the nearest-path heuristic, the paired difference, same episodes for every
policy, the families, and the ``frontier-marl benchmark`` command."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import frontier_marl
from frontier_marl.cli.main import main
from frontier_marl.core.frontiers import cluster_frontiers
from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN
from frontier_marl.core.slots import robot_slots
from frontier_marl.evaluation.benchmark import families as map_families
from frontier_marl.evaluation.benchmark import run as bench
from frontier_marl.evaluation.benchmark.stats import (
    best_heuristic,
    compare,
    format_table,
    paired_difference,
)
from frontier_marl.policies import GreedyDistance, NearestPath, make_policy

EXPLORE_BENCH = Path(__file__).resolve().parents[2] / "shared" / "maps" / "explore-bench"
_CODES = {"?": UNKNOWN, ".": FREE, "#": OCCUPIED, "R": FREE}

# ----------------------------------------------------------------- nearest-path

# A non-square 6x7 belief. The robot R stands at (1, 1). Cluster A, (0, 3) and (1, 3), is
# behind a wall: its centroid (0.5, 3) is 2.06 away in a straight line but its target (0, 3)
# is 7 cells away by the known-free path (down, right, up). Cluster B, (4, 1), is 3 away both
# ways. Greedy distance takes A; nearest-path takes B.
WALLED = """
# . # . ? ? ?
# R # . ? ? ?
# . # . # # ?
# . . . # # ?
# . # # # # ?
# ? # # # # ?
"""


def walled_info() -> dict:
    rows = [line.split() for line in WALLED.strip().splitlines()]
    belief = np.array([[_CODES[c] for c in row] for row in rows], dtype=np.int8)
    clusters = cluster_frontiers(belief, connectivity=8, max_cells=8)
    table = robot_slots(belief, (1, 1), clusters, clusters.sizes.astype(float), 4, False)
    return {"slots": table, "action_mask": table.mask, "new_cells": 1}


def test_nearest_path_takes_the_shortest_known_free_path_not_the_nearest_centroid():
    info = walled_info()
    table = info["slots"]
    assert table.live == 2
    by_target = {tuple(table.target[s]): s for s in range(table.live)}
    a, b = by_target[(0, 3)], by_target[(4, 1)]
    assert table.path_length[a] == 7 and table.path_length[b] == 3
    assert table.distance[a] < table.distance[b]  # A is the nearer centroid
    assert GreedyDistance().act(None, info) == a
    assert NearestPath().act(None, info) == b
    assert make_policy("nearest-path").act(None, info) == b


def test_nearest_path_ties_go_to_the_nearest_centroid():
    from tests.helpers import info_with, live_slot

    info = info_with([live_slot(1, 4.0, path_length=5), live_slot(1, 3.0, path_length=5)])
    assert NearestPath().act(None, info) == 1


# ----------------------------------------------------------------- statistics


def test_paired_difference_on_hand_computed_numbers():
    # relative differences 0.1, -0.1, 0.2: mean 1/15, sample std sqrt(0.07/3) = 0.152753;
    # t(0.975, 2 dof) = 4.302653 -> half-width 4.302653 * 0.152753 / sqrt(3) = 0.379454
    out = paired_difference([110, 90, 120, None], [100, 100, 100, 100])
    assert out["pairs"] == 3
    assert out["mean"] == pytest.approx(1 / 15)
    half = 4.302653 * math.sqrt(0.07 / 3) / math.sqrt(3)
    assert out["ci_low"] == pytest.approx(1 / 15 - half, abs=1e-5)
    assert out["ci_high"] == pytest.approx(1 / 15 + half, abs=1e-5)
    assert paired_difference([5], [4]) == {
        "pairs": 1,
        "undefined": 0,
        "mean": 0.25,
        "ci_low": None,
        "ci_high": None,
    }
    assert paired_difference([None], [4])["mean"] is None
    with pytest.raises(ValueError, match="pair up"):
        paired_difference([1, 2], [1])


def test_a_baseline_of_zero_leaves_the_difference_undefined_not_a_crash():
    out = paired_difference([0, 3, 0], [0, 2, 0])  # T99 = 0: the map was seen whole at reset
    assert (out["pairs"], out["undefined"], out["mean"]) == (1, 2, 0.5)
    none = paired_difference([0, 0], [0, 0])
    assert (none["pairs"], none["undefined"], none["mean"]) == (0, 2, None)
    with pytest.raises(ValueError, match=">= 0"):
        paired_difference([1], [-1])


def test_a_map_seen_whole_at_reset_is_reported_and_written(tmp_path: Path) -> None:
    seen = tmp_path / "open.txt"
    seen.write_text("....\n....\n....\n")  # r = 3 sees every cell from anywhere
    out = tmp_path / "open.json"
    argv = ["benchmark", "--map", str(seen), "--episodes", "2", "--no-progress"]
    assert main([*argv, "--policies", "nearest-path,cost-utility", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [row["success"] for row in rows] == [2, 2]
    assert all(row["vs_best"]["undefined"] >= 1 for row in rows)
    assert format_table(rows).count("undefined") >= 1


def test_a_failing_comparison_keeps_the_rows(monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(rows):
        raise ArithmeticError("statistics broke")

    monkeypatch.setattr(bench, "compare", broken)
    family = map_families.family("random-20")
    logged: list[str] = []
    rows = bench.run_benchmark([family], bench.contenders(["nearest-path"]), 1, log=logged.append)
    assert len(rows) == 1 and rows[0]["success"] == 1
    assert "statistics broke" in rows[0]["comparison_error"] and "rows kept" in logged[0]


def _row(policy, t99, heuristic=True):
    success = sum(v is not None for v in t99)
    reached = [v for v in t99 if v is not None]
    return {
        "policy": policy,
        "family": "f",
        "agents": 1,
        "episodes": len(t99),
        "heuristic": heuristic,
        "success": success,
        "t99_mean": float(np.mean(reached)) if reached else None,
        "t99_std": float(np.std(reached)) if reached else None,
        "t99_partial": success < len(t99),
        "t90_mean": None,
        "t90_std": None,
        "per_episode": [{"t99": v} for v in t99],
    }


def test_best_heuristic_has_most_successes_then_lowest_t99():
    rows = [
        _row("a", [100, 110]),
        _row("b", [80, None]),  # lower mean, but a failure
        _row("c", [105, 100]),
        _row("model", [50, 50], heuristic=False),  # models are never the reference
    ]
    assert best_heuristic(rows)["policy"] == "c"
    compare(rows)
    assert {r["best_heuristic"] for r in rows} == {"c"}
    assert rows[2]["vs_best"]["mean"] == 0.0
    assert rows[1]["vs_best"]["pairs"] == 1
    assert rows[3]["vs_best"]["mean"] == pytest.approx(((50 - 105) / 105 + (50 - 100) / 100) / 2)
    table = format_table(rows)
    assert "80.0 ± 0.0*" in table and "best" in table


def test_teams_are_also_compared_by_makespan():
    rows = [_row("a", [100, 105]), _row("b", [110, 100]), _row("m", [90, 90], heuristic=False)]
    spans = {"a": [60, 50], "b": [40, 50], "m": [30, 45]}  # b: best makespan, a: best T99
    for row in rows:
        row["agents"] = 2
        row["makespan99_mean"] = float(np.mean(spans[row["policy"]]))
        row.update(makespan99_std=0.0, overlap_mean=0.0, overlap_std=0.0)
        for entry, span in zip(row["per_episode"], spans[row["policy"]], strict=True):
            entry["makespan99"] = span
    compare(rows)
    assert {r["best_heuristic"] for r in rows} == {"a"}
    assert {r["best_heuristic_makespan"] for r in rows} == {"b"}
    assert rows[2]["makespan_vs_best"]["mean"] == pytest.approx((30 / 40 - 1 + 45 / 50 - 1) / 2)
    assert "makespan vs best" in format_table(rows)


# ----------------------------------------------------------------- families and episodes


def test_families_and_seed_ranges():
    assert list(map_families.FAMILIES) == [
        "random-20", "random-30", "rooms-32", "rooms-64", "rooms-96-fine", "floorplan-96"
    ]  # fmt: skip
    for fam in map_families.FAMILIES.values():
        held = set(fam.heldout)
        assert not held & set(fam.train[-1000:]) and not held & set(fam.validation)
        assert fam.train.stop <= fam.validation.start and fam.validation.stop <= fam.heldout.start
        assert fam.seeds(3) == [900_000, 900_001, 900_002]
    shapes = {
        name: (c.height, c.width, c.map_scale, c.perception_range, c.map_generator, c.map_mode)
        for name in map_families.FAMILIES
        for c in map_families.variant_configs(map_families.family(name))
    }
    assert shapes == {
        "random-20": (20, 20, 1, 3, "random", "dynamic"),
        "random-30": (30, 30, 1, 5, "random", "dynamic"),
        "rooms-32": (32, 32, 1, 3, "rooms", "dynamic"),
        "rooms-64": (64, 64, 1, 5, "rooms", "dynamic"),
        "rooms-96-fine": (96, 96, 3, 13, "rooms", "dynamic"),
        "floorplan-96": (96, 96, 2, 13, "floorplan", "dynamic"),
    }
    (cfg,) = map_families.variant_configs(
        map_families.family("rooms-64"), {"perception_range": 4}, agents=2
    )
    assert (cfg.perception_range, cfg.max_cluster_cells, cfg.n_agents) == (4, 10, 2)
    assert cfg.n_slots == map_families.HEURISTIC_SLOTS
    assert (cfg.reward.explore_threshold, cfg.reward.max_steps) == (0.99, 2 * 64 * 64)
    assert (bench.default_commit(1), bench.default_commit(3)) == ("until-progress", "none")
    with pytest.raises(ValueError, match="unknown family"):
        map_families.family("mazes")
    with pytest.raises(ValueError, match="episodes"):
        map_families.family("random-20").seeds(0)


@pytest.mark.parametrize("name", ["random-20", "rooms-32"])
def test_same_maps_and_starts_whatever_the_observation_settings(name):
    """The reset seed alone fixes the true grid and the start cells."""
    (world,) = map_families.variant_configs(map_families.family(name), agents=2)
    variants = [
        {},
        {"n_slots": 4, "centroid": "relative", "sort_by_distance": True},
        {"n_slots": 8, "centroid": "none", "info_gain": True, "agent_position": False},
        {"normalize": True, "teammates": "positions", "action_mask": True, "gain": "unknown"},
    ]
    envs = [frontier_marl.parallel_env(config=world.replace(**v)) for v in variants]
    for seed in map_families.family(name).seeds(3):
        grids, starts = [], []
        for env in envs:
            env.reset(seed=seed)
            grids.append(np.array(env.world.true_grid))
            starts.append(np.array(env.world.positions))
        for grid, start in zip(grids[1:], starts[1:], strict=True):
            np.testing.assert_array_equal(grid, grids[0])
            np.testing.assert_array_equal(start, starts[0])
    assert not np.array_equal(grids[0], np.zeros_like(grids[0]))


def test_loaded_maps_cycle_and_scale_the_sensor(tmp_path):
    small = tmp_path / "small.txt"
    small.write_text("\n".join(["." * 9] * 6) + "\n")
    fam = map_families.map_family([tmp_path])
    assert fam.name == f"map:{tmp_path.name}" and fam.maps == (str(small),)
    (cfg,) = map_families.variant_configs(fam)
    assert (cfg.height, cfg.width, cfg.perception_range, cfg.map_mode) == (6, 9, 3, "static")
    assert map_families.loaded_map_range(250, 250) == 35
    with pytest.raises(ValueError, match="does not exist"):
        map_families.map_family([tmp_path / "nothing.pgm"])


# ----------------------------------------------------------------- the command


def test_cli_smoke_with_a_family_and_a_loaded_map(tmp_path, capsys):
    out_json, out_png = tmp_path / "b.json", tmp_path / "b.png"
    argv = ["benchmark", "--families", "random-20", "--map", "rooms-32", "--episodes", "2"]
    argv += ["--json", str(out_json), "--plot", str(out_png), "--no-progress"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "nearest-path" in text and "map:rooms-32" in text and "best" in text
    data = json.loads(out_json.read_text())
    rows = data["rows"]
    assert len(rows) == 10  # 2 families x 5 heuristics (frontier-rule among them)
    keys = ("policy", "family", "agents", "episodes", "success", "t99_mean", "t99_std")
    for row in rows:
        for key in (*keys, "t90_mean", "makespan99_mean", "per_episode"):
            assert key in row
        assert row["success"] == 2 and row["episodes"] == 2 and row["agents"] == 1
        assert [e["seed"] for e in row["per_episode"]] == [900_000, 900_001]
        assert row["makespan99_mean"] == row["t99_mean"]  # one robot
    by_family = {}
    for row in rows:
        by_family.setdefault(row["family"], []).append(row)
    for family_rows in by_family.values():  # same episodes: same seeds, same first coverage
        starts = {tuple(e["seed"] for e in r["per_episode"]) for r in family_rows}
        assert len(starts) == 1
    assert out_png.stat().st_size > 0


def test_cli_team_adds_makespan_and_overlap(tmp_path, capsys):
    argv = ["benchmark", "--families", "random-20", "--episodes", "2", "--agents", "2"]
    argv += ["--policies", "nearest-path,coordinated-assignment", "--no-progress"]
    argv += ["--json", str(tmp_path / "t.json"), "--set", "perception_range=2"]
    assert main(argv) == 0
    assert "makespan" in capsys.readouterr().out
    rows = json.loads((tmp_path / "t.json").read_text())["rows"]
    for row in rows:
        assert row["agents"] == 2 and row["config"]["perception_range"] == 2
        assert row["makespan99_mean"] < row["t99_mean"]
        assert row["overlap_mean"] >= 0
        assert row["best_heuristic_makespan"] in ("nearest-path", "coordinated-assignment")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--families", "mazes"], "unknown family 'mazes'"),
        (["--policies", "greedy-nowhere"], "unknown policy 'greedy-nowhere'"),
        (["--policies", __file__], "cannot load model"),
        (["--episodes", "100001"], "episodes must be in [1, 100000]"),
        (["--map", "/nonexistent/map.pgm"], "does not exist"),
        (["--set", "n_agents=3"], "n_agents"),
        (["--set", "perception_range=0"], "perception_range"),
        (["--families", ","], "at least one family"),
        (["--policies", "nearest-path,nearest-path"], "share the label 'nearest-path'"),
    ],
)
def test_cli_bad_input(argv, message, capsys):
    assert main(["benchmark", "--no-progress", *argv]) == 2
    assert message in capsys.readouterr().err


def test_a_map_folder_without_maps_names_its_subfolders_that_have_some(tmp_path, capsys):
    (tmp_path / "plans").mkdir()
    (tmp_path / "plans" / "a.txt").write_text("..\n..\n")
    (tmp_path / "empty").mkdir()
    assert main(["benchmark", "--no-progress", "--map", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "holds no .pgm, .png or .txt map (its subfolders plans do: pass one of them)" in err


def test_run_on_seeds_refuses_held_out_seeds():
    with pytest.raises(ValueError, match="held-out seeds overlap"):
        bench.run_on_seeds(["nearest-path"], range(899_999, 900_001), 1)


def test_models_in_folders_of_one_name_are_refused(tmp_path):
    shipped = Path(frontier_marl.__file__).parent / "assets" / "models" / "explorer"
    folders = [tmp_path / run / "best" for run in ("run-a", "run-b")]
    for folder in folders:
        shutil.copytree(shipped, folder)
    with pytest.raises(ValueError, match="share the label 'best'"):
        bench.contenders([str(folder) for folder in folders])


@pytest.mark.parametrize("agents", ["0", "-1"])
def test_cli_agents_must_be_positive(agents, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["benchmark", "--agents", agents])
    assert exc.value.code == 2
    assert "expected an integer >= 1" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.skipif(not EXPLORE_BENCH.is_dir(), reason=f"{EXPLORE_BENCH} is absent")
def test_cli_explore_bench_folder(tmp_path):
    out = tmp_path / "eb.json"
    argv = ["benchmark", "--map", str(EXPLORE_BENCH), "--episodes", "2", "--no-progress"]
    argv += ["--policies", "nearest-path", "--json", str(out)]
    assert main(argv) == 0
    (row,) = json.loads(out.read_text())["rows"]
    assert row["family"] == "map:explore-bench" and len(row["maps"]) == 12
    assert [e["map"] for e in row["per_episode"]] == row["maps"][:2]
    assert row["config"]["perception_range"] == 35 and row["success"] == 2


def test_cli_shipped_model_keeps_its_observation_settings(tmp_path, capsys):
    pytest.importorskip("stable_baselines3")
    out = tmp_path / "m.json"
    argv = ["benchmark", "--families", "random-20,random-30", "--episodes", "1"]
    argv += ["--policies", "nearest-path,thesis-config01", "--json", str(out), "--no-progress"]
    assert main(argv) == 0
    assert "thesis-config01 skipped on random-30" in capsys.readouterr().err  # a 20x20 model
    rows = json.loads(out.read_text())["rows"]
    assert [(r["family"], r["policy"]) for r in rows] == [
        ("random-20", "nearest-path"),
        ("random-20", "thesis-config01"),
        ("random-30", "nearest-path"),
    ]
    heuristic, model = rows[0], rows[1]
    assert (heuristic["n_slots"], model["n_slots"]) == (map_families.HEURISTIC_SLOTS, 4)
    assert model["config"]["normalize"] and not heuristic["config"]["normalize"]
    for key in ("perception_range", "cells_per_step", "max_steps", "explore_threshold"):
        assert model["config"][key] == heuristic["config"][key]
    assert model["best_heuristic"] == "nearest-path" and not model["heuristic"]


def test_the_resolution_sweep_draws_the_layouts_finer_with_the_sensor_scaled(
    tmp_path: Path,
) -> None:
    from frontier_marl.experiments.explorer_studies.resolution_sweep import main as sweep

    out = tmp_path / "sweep.json"
    argv = ["--scales", "1,2", "--episodes", "1", "--policies", "cost-utility,nearest-path"]
    assert sweep([*argv, "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [(row["scale"], row["perception_range"], row["policy"]) for row in rows] == [
        (1, 4, "cost-utility"), (1, 4, "nearest-path"),
        (2, 9, "cost-utility"), (2, 9, "nearest-path"),
    ]  # fmt: skip
    assert all(row["success"] == 1 for row in rows)
    argv = ["--layouts", "floorplan", "--scales", "1", "--episodes", "1", "--first", "800500"]
    assert sweep([*argv, "--policies", "nearest-path", "--json", str(out)]) == 0
    (row,) = json.loads(out.read_text())["rows"]
    assert (row["scale"], row["perception_range"], row["success"]) == (1, 6, 1)
    assert json.loads(out.read_text())["options"]["first_seed"] == 800_500
    for bad in (["--scales", "x"], ["--first", "900000"], ["--layouts", "caves"]):
        with pytest.raises(SystemExit):
            sweep(bad)


def test_the_feature_cost_benchmark_times_every_layout(tmp_path: Path) -> None:
    from frontier_marl.experiments.speed import bench_explorer_features as bench

    out = tmp_path / "cost.json"
    argv = ["--families", "random-20", "--worlds", "2", "--seconds", "0.05", "--json", str(out)]
    assert bench.main(argv) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [row["layout"] for row in rows] == list(bench.LAYOUTS)
    assert all(row["decisions_per_s"] > 0 for row in rows)
    with pytest.raises(SystemExit):
        bench.main(["--worlds", "0"])


def test_a_policy_refusing_inside_an_episode_is_one_line_naming_the_episode(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def refuse(self: NearestPath, observations: object, infos: object) -> dict[str, int]:
        raise ValueError("this policy cannot act here")

    monkeypatch.setattr(NearestPath, "act_team", refuse)
    argv = ["benchmark", "--no-progress", "--families", "random-20", "--episodes", "1"]
    assert main([*argv, "--policies", "nearest-path", "--jobs", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "this policy cannot act here; while running episode 900000 of nearest-path" in err
