"""``frontier-marl gif``: run one episode with a heuristic or a model and write it as a GIF.

Examples::

    frontier-marl gif --policy greedy-distance --preset thesis-20x20 --seed 0 --out episode.gif
    frontier-marl gif --policy explorer --beside nearest-path --map rooms-64 --out side.gif

The frames show the true grid beside the robots' belief, the frontier clusters and their
centroids, the robots, their last paths and targets (see :mod:`frontier_marl.render.frames`).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

import frontier_marl
from frontier_marl.cli.arguments import (
    add_env_arguments,
    env_kwargs_from_args,
    fail,
    positive_int,
)
from frontier_marl.config import make_config
from frontier_marl.evaluation.benchmark.run import contenders
from frontier_marl.policies import POLICIES
from frontier_marl.render.renderer import frame
from frontier_marl.render.viewer import write_gif


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--policy",
        default="greedy-distance",
        help=f"heuristic ({', '.join(POLICIES)}) or model (a shipped model's name, a run "
        "folder or a model.zip) driving the robots (default: %(default)s)",
    )
    parser.add_argument(
        "--beside",
        default=None,
        help="a second policy run on the same episode, drawn to the right of the first",
    )
    add_env_arguments(parser)
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("episode.gif"),
        help="GIF file to write (default: %(default)s)",
    )
    parser.add_argument(
        "--fps", type=float, default=4.0, help="frames per second (default: %(default)s)"
    )
    parser.add_argument(
        "--cell-px",
        type=positive_int,
        default=12,
        help="pixels per grid cell (default: %(default)s)",
    )
    parser.add_argument(
        "--max-steps",
        type=positive_int,
        default=None,
        help="stop after this many decisions (default: when the episode ends)",
    )


def render_frame(env: Any, cell_px: int) -> np.ndarray:
    """An RGB frame of ``env``'s current state at ``cell_px`` pixels per cell (the same
    picture as ``env.render()`` in ``rgb_array`` mode, which is fixed at 12 px)."""
    return frame(env.unwrapped.mdp, "rgb_array", cell_px=cell_px)


def record_episode(
    env_kwargs: dict[str, Any],
    policy_name: str,
    seed: int,
    cell_px: int = 12,
    max_steps: int | None = None,
) -> tuple[list[np.ndarray], float, int, str]:
    """Frames (reset included), team-mean return, decision steps and end reason of one
    episode of ``policy_name`` (a heuristic, or a model on its own observation settings)."""
    contender = contenders([policy_name])[0]
    cfg = contender.config(make_config(**env_kwargs))
    env = frontier_marl.parallel_env(render_mode="rgb_array", config=cfg)
    try:
        policy = contender.make()
        policy.attach(env)
        observations, infos = env.reset(seed=seed)
        frames = [render_frame(env, cell_px)]
        returns = dict.fromkeys(env.agents, 0.0)
        steps = 0
        reason = ""
        while env.agents and (max_steps is None or steps < max_steps):
            actions = policy.act_team(observations, infos)
            observations, rewards, _, _, infos = env.step(actions)
            for agent, reward in rewards.items():
                returns[agent] += reward
            steps += 1
            frames.append(render_frame(env, cell_px))
            reason = frontier_marl.reason_name(next(iter(infos.values()))["end_reason"])
        if env.agents:
            reason = "max_steps"
    finally:
        env.close()
    return frames, float(np.mean(list(returns.values()))), steps, reason


def side_by_side(left: list[np.ndarray], right: list[np.ndarray]) -> list[np.ndarray]:
    """Frames of two episodes next to each other (a white gap between); the shorter episode
    holds its last frame."""
    count = max(len(left), len(right))
    height = max(left[0].shape[0], right[0].shape[0])

    def at(frames: list[np.ndarray], i: int) -> np.ndarray:
        frame = frames[min(i, len(frames) - 1)]
        pad = np.full((height - frame.shape[0], *frame.shape[1:]), 255, dtype=frame.dtype)
        return np.concatenate([frame, pad], axis=0)

    gap = np.full((height, 8, 3), 255, dtype=left[0].dtype)
    return [np.concatenate([at(left, i), gap, at(right, i)], axis=1) for i in range(count)]


def run(args: argparse.Namespace) -> int:
    try:
        env_kwargs = env_kwargs_from_args(args)
        if not args.fps > 0:
            raise ValueError(f"--fps must be > 0, got {args.fps}")
    except ValueError as exc:
        return fail("gif", str(exc))

    names = [args.policy] + ([args.beside] if args.beside else [])
    episodes = []
    try:
        for name in names:
            episodes.append(
                record_episode(env_kwargs, name, args.seed, args.cell_px, args.max_steps)
            )
    except ValueError as exc:
        return fail("gif", str(exc))
    frames = episodes[0][0]
    if len(episodes) == 2:
        frames = side_by_side(frames, episodes[1][0])
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_gif(frames, args.out, fps=args.fps)
    print(f"wrote {args.out}" + (f" ({names[0]} left, {names[1]} right)" if args.beside else ""))
    for name, (_, reward, steps, reason) in zip(names, episodes, strict=True):
        print(
            f"policy {name}, seed {args.seed}: reward {reward:.2f}, {steps} steps, "
            f"end: {reason or 'none'}"
        )
    return 0
