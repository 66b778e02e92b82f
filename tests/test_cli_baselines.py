"""End-to-end tests of ``frontier-marl baselines`` (run in-process)."""

from __future__ import annotations

import json

import pytest

from frontier_marl.cli.main import main
from frontier_marl.utils.set_options import parse_set_options, parse_value

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
SMALL = [
    "--set",
    "height=8",
    "--set",
    "width=9",
    "--set",
    "perception_range=2",
    "--set",
    "explore_threshold=0.8",
]


def test_baselines_end_to_end_writes_json_and_png(tmp_path, capsys):
    out_json, out_png = tmp_path / "rows.json", tmp_path / "sub" / "plot.png"
    code = main(
        [
            "baselines",
            "--episodes",
            "2",
            "--seed",
            "3",
            "--no-progress",
            "--json",
            str(out_json),
            "--plot",
            str(out_png),
            *SMALL,
        ]
    )
    assert code == 0
    rows = json.loads(out_json.read_text())
    assert [row["policy"] for row in rows] == [
        "greedy-distance",
        "greedy-gain",
        "cost-utility",
        "random",
    ]
    for row in rows:
        for key in (
            "mean_reward",
            "std_reward",
            "terminations",
            "episodes",
            "action_shares",
            "mean_steps",
            "mean_travelled",
            "cells_to_coverage",
            "config",
        ):
            assert key in row
        assert row["episodes"] == 2 and row["seeds"] == [3, 4]
        assert len(row["action_shares"]) == 4
        assert sum(row["action_shares"]) == pytest.approx(1.0)
        assert row["config"]["height"] == 8 and row["config"]["explore_threshold"] == 0.8
        assert row["thesis_mean"] is None  # the thesis's figures are for 20x20 only
    assert out_png.read_bytes()[:8] == PNG_SIGNATURE
    printed = capsys.readouterr().out
    assert "greedy-distance" in printed and "cost-utility" in printed
    assert f"wrote {out_json}" in printed


def test_thesis_figures_appear_beside_ours(capsys):
    # the default preset, static map: the thesis's figures are printed for two policies
    code = main(
        [
            "baselines",
            "--episodes",
            "1",
            "--no-progress",
            "--policies",
            "greedy-distance,greedy-gain",
            "--set",
            "max_steps=5",
        ]
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert "16.48 ± 1.78" in printed and "15.01 ± 1.12" in printed


def test_the_thesis_protocol_applies_on_the_thesis_presets_only(tmp_path, capsys):
    # thesis-30x30, static, seed 16: plain greedy distance cycles between two clusters (37 %
    # coverage, tests/test_policies.py); the thesis protocol's (commit on-cycle) does not
    out_json = tmp_path / "rows.json"
    argv = ["baselines", "--episodes", "1", "--seed", "16", "--no-progress"]
    thesis = [*argv, "--preset", "thesis-30x30", "--policies", "greedy-distance"]
    assert main([*thesis, "--json", str(out_json)]) == 0
    (row,) = json.loads(out_json.read_text())
    assert row["end_reasons"] == {"threshold": 1}
    assert "36.39 ± 1.27" in capsys.readouterr().out  # the thesis's Table 6.5 figure
    # a loaded map is not the thesis's setting: greedy distance is the plain rule there
    from tests.test_policies import CYCLE_MAP

    path = tmp_path / "cycle.txt"
    path.write_text(CYCLE_MAP)
    loaded = ["baselines", "--episodes", "1", "--seed", "0", "--no-progress", "--map", str(path)]
    assert main([*loaded, "--policies", "greedy-distance", "--json", str(out_json)]) == 0
    (row,) = json.loads(out_json.read_text())
    assert row["end_reasons"] == {"no_progress": 1}


def test_team_and_dynamic_options(tmp_path):
    out_json = tmp_path / "team.json"
    code = main(
        [
            "baselines",
            "--episodes",
            "1",
            "--agents",
            "2",
            "--map-mode",
            "dynamic",
            "--policies",
            "greedy-gain",
            "--no-progress",
            "--json",
            str(out_json),
            *SMALL,
        ]
    )
    assert code == 0
    (row,) = json.loads(out_json.read_text())
    assert row["n_agents"] == 2 and row["map_mode"] == "dynamic" and row["map_seed"] is None


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--policies", "greedy-distance,nearest"], "unknown policy 'nearest'"),
        (["--set", "obstacle_prob=2"], "obstacle_prob"),
        (["--set", "no_such_key=1"], "unexpected keyword argument 'no_such_key'"),
        (["--set", "height"], "key=value"),
        (["--set", "cells_per_step=fast"], "cells_per_step"),
    ],
)
def test_invalid_values_exit_2_with_a_message(argv, message, capsys):
    assert main(["baselines", "--no-progress", *argv]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("argv", [["--episodes", "0"], ["--preset", "tiny"], ["--seed", "x"]])
def test_argparse_errors_exit_2(argv):
    with pytest.raises(SystemExit) as info:
        main(["baselines", *argv])
    assert info.value.code == 2


def test_set_value_parsing():
    assert parse_set_options(["a=3", "b=0.5", "c=true", "d=full", "e=None", "f-g=False"]) == {
        "a": 3,
        "b": 0.5,
        "c": True,
        "d": "full",
        "e": None,
        "f_g": False,
    }
    assert isinstance(parse_value("3"), int) and isinstance(parse_value("3.0"), float)
