"""Smoke tests of ``frontier-marl gif``."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest

import frontier_marl
from frontier_marl.cli.commands.gif import record_episode, render_frame
from frontier_marl.cli.main import main

SMALL = {"height": 8, "width": 9, "perception_range": 2, "explore_threshold": 0.8}
SMALL_ARGS = [arg for key, value in SMALL.items() for arg in ("--set", f"{key}={value}")]


def test_gif_command_writes_an_animation(tmp_path, capsys):
    out = tmp_path / "episode.gif"
    code = main(
        [
            "gif",
            "--policy",
            "greedy-gain",
            "--seed",
            "1",
            "--out",
            str(out),
            "--cell-px",
            "4",
            "--fps",
            "8",
            *SMALL_ARGS,
        ]
    )
    assert code == 0
    assert out.read_bytes()[:6] in (b"GIF87a", b"GIF89a")
    frames = iio.imread(out, index=None)
    assert frames.shape[1:3] == (8 * 4, (2 * 9 + 1) * 4)
    assert len(frames) >= 2
    printed = capsys.readouterr().out
    assert str(out) in printed and "reward" in printed and "steps" in printed


def test_recorded_episode_has_one_frame_per_step_plus_reset():
    frames, reward, steps, reason = record_episode(SMALL, "cost-utility", seed=0, cell_px=3)
    assert len(frames) == steps + 1
    assert reason == "threshold" and reward > 0
    frames, _, steps, reason = record_episode(
        {**SMALL, "n_agents": 2}, "random", seed=0, cell_px=3, max_steps=2
    )
    assert steps <= 2 and len(frames) == steps + 1


def test_frame_matches_env_render_at_default_size():
    env = frontier_marl.parallel_env(render_mode="rgb_array", **SMALL)
    _, infos = env.reset(seed=4)
    _, _, _, _, infos = env.step({"robot_0": 0})
    np.testing.assert_array_equal(render_frame(env, 12), env.render())


@pytest.mark.parametrize("argv", [["--fps", "0"], ["--set", "sensor=sonar"]])
def test_gif_invalid_values_exit_2(tmp_path, argv, capsys):
    assert main(["gif", "--out", str(tmp_path / "x.gif"), *argv]) == 2
    assert "error" in capsys.readouterr().err
    assert not (tmp_path / "x.gif").exists()


def test_gif_beside_draws_two_policies_on_the_same_episode(tmp_path, capsys):
    out = tmp_path / "side.gif"
    argv = ["gif", "--policy", "greedy-gain", "--beside", "nearest-path", "--out", str(out)]
    assert main([*argv, "--cell-px", "4", "--seed", "2", *SMALL_ARGS]) == 0
    frames = iio.imread(out, index=None)
    single = (2 * 9 + 1) * 4
    assert frames.shape[2] == 2 * single + 8
    # both halves start from the same reset: the same map and start
    np.testing.assert_array_equal(frames[0][:, :single], frames[0][:, single + 8 :])
    printed = capsys.readouterr().out
    assert "greedy-gain" in printed and "nearest-path" in printed


def test_gif_refuses_an_unknown_policy(tmp_path, capsys):
    assert main(["gif", "--policy", "nosuch", "--out", str(tmp_path / "x.gif")]) == 2
    assert "unknown policy 'nosuch'" in capsys.readouterr().err
