"""How low can the env's share of DQN training go? A lower bound (docs/performance.md).

    python benchmarks/bench_step_floor.py                 # ~3 minutes on 2 cores
    python benchmarks/bench_step_floor.py --steps 30000 --chunks 15 --json floor.json

Not a test and not an env to use: ``MinimalStep`` is the thesis's configuration-1 decision step
(one robot, Reward 2, absolute centroids + agent position, unsorted, the calibrated defaults of
``thesis-20x20``) written as the smallest Python we could put around the compiled kernels and
the ``scipy.ndimage.label`` call the design requires: no adapters, no dataclasses, one robot
only, a minimal info. Before timing anything the script checks that it
plays exactly the episodes of ``FrontierExploreEnv`` (observations, rewards, episode ends,
action masks, slot targets, paths). Then the thesis's DQN trains, interleaved in chunks as in
``bench_env.py``, on a null env, on the real env, on ``MinimalStep``, and on ``MinimalStep``
with the labelling skipped after each episode's first (wrong clusters: a cost measurement only),
and the script reports each one's share of training time (and the two steps' cost outside
training).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from scipy import ndimage

import frontier_marl
from frontier_marl.core.frontiers import clusters_from_labels, frontier_cells
from frontier_marl.core.slots import _robot_slots
from frontier_marl.core.world import count_known
from frontier_marl.envs.infos import StepInfo
from frontier_marl.training.experiment import load_experiment

sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench_env.py lies beside this script
from bench_env import NullEnv, train_interleaved  # noqa: E402


class MinimalStep(gym.Env):
    """Configuration 1's step with the least glue possible (see the module docstring)."""

    relabel = True  # False: reuse the episode's first labelling (cost bound only)

    def __init__(self) -> None:
        cfg = load_experiment("config01").env_config()
        self._real = frontier_marl.FrontierExploreEnv(preset=None, config=cfg)
        obs = cfg.observation
        if not (obs.centroid == "absolute" and obs.agent_position and not obs.info_gain):
            raise ValueError("MinimalStep implements configuration 1's observation only")
        if obs.sort_by_distance or obs.action_mask or cfg.n_agents != 1:
            raise ValueError("MinimalStep implements configuration 1 only")
        self.cfg = cfg
        # Positions divided by the grid size with ``normalize`` (in float64, then float32).
        self.scale = np.array([cfg.height, cfg.width], float) if obs.normalize else np.ones(2)
        self.reward = cfg.reward
        self.n_slots = cfg.n_slots
        self.structure = ndimage.generate_binary_structure(2, 2 if cfg.connectivity == 8 else 1)
        self.observation_space = self._real.observation_space
        self.action_space = self._real.action_space

    def reset(self, *, seed: int | None = None, options: Any = None) -> Any:
        observation, info = self._real.reset(seed=seed)
        self.world = self._real.world
        self._labelled_version = -1
        self._first_labelling: tuple[np.ndarray, int] | None = None
        self.steps = 0
        self.without_progress = 0
        self.history: tuple[tuple[int, int] | None, ...] = ()
        self._refresh()
        return observation, info

    def _label(self, mask: np.ndarray) -> tuple[np.ndarray, int]:
        if self.relabel or self._first_labelling is None:
            image, count = ndimage.label(mask, structure=self.structure)
            self._first_labelling = (image, count)
            return image, count
        image = self._first_labelling[0].copy()
        image[mask] = 1
        return image, 1

    def _refresh(self) -> None:
        world = self.world
        if world._version != self._labelled_version:
            mask, rows, cols = frontier_cells(world._belief)
            if len(rows):
                image, count = self._label(mask)
                cluster, sizes, centroids = clusters_from_labels(
                    image, rows, cols, count, self.cfg.max_cluster_cells
                )
            else:
                cluster = sizes = rows
                centroids = np.zeros((0, 2))
            self._clusters = (rows, cols, cluster, centroids, sizes, sizes.astype(float))
            self._labelled_version = world._version
        rows, cols, cluster, centroids, sizes, gains = self._clusters
        position = world._positions[0]
        self.slots = _robot_slots(
            world._belief,
            position[0],
            position[1],
            rows,
            cols,
            cluster,
            centroids,
            sizes,
            gains,
            self.n_slots,
            False,
        )
        self.live = int(self.slots[9])

    def step(self, action: Any) -> Any:
        slot = int(action)
        if not 0 <= slot < self.n_slots:
            raise ValueError(f"action must be in [0, {self.n_slots - 1}], got {action!r}")
        world, reward_cfg = self.world, self.reward
        goals = world._goals
        if slot < self.live:
            row, col = self.slots[3][slot].tolist()
            target: tuple[int, int] | None = (row, col)
            goals[0] = target
            padding = False
        else:
            target = None
            goals[0] = -1
            padding = self.live > 0
        history = self.history
        oscillation = (
            target is not None
            and bool(history)
            and history[-1] is not None
            and target != history[-1]
            and target in history[:-1]
        )
        self.history = (*history, target)[-(reward_cfg.oscillation_window + 1) :]
        world._walk()
        new = int(world._new_cells[0])
        self.steps += 1
        self.without_progress = 0 if new else self.without_progress + 1
        self._refresh()
        known = count_known(world._belief, world._start_region)
        fraction = known / max(world._start_region_size, 1)
        reward = reward_cfg.cell_reward * new
        if new == 0:
            reward += reward_cfg.no_new_cell_penalty
        if padding:
            reward += reward_cfg.padding
        if oscillation:
            reward += reward_cfg.oscillation_penalty
        terminated = truncated = False
        if fraction >= reward_cfg.explore_threshold:
            reward += reward_cfg.goal_bonus
            terminated = True
        elif not self.live:
            terminated = True
        else:
            if self.without_progress >= reward_cfg.no_progress_limit:
                reward += reward_cfg.no_progress_penalty
                truncated = True
            if self.steps >= reward_cfg.max_steps:
                reward += reward_cfg.step_limit_penalty
                truncated = True
        _, _, centroid, target_cells, _, _, _, _, mask, _ = self.slots
        live = self.live
        features = np.zeros((self.n_slots, 2))
        features[:live] = centroid[:live]
        observation = {
            "clusters": (features / self.scale).astype(np.float32).ravel(),
            "agent_position": (world._positions[0] / self.scale).astype(np.float32),
        }
        info = StepInfo(
            explored_fraction=fraction,
            new_cells=new,
            action_mask=mask,
            target=target_cells[:live],  # the live slots' targets, checked against the env's
            path=world._walked[0, : world._walked_len[0]].copy(),
        )
        return observation, float(reward), terminated, truncated, info


def check_same_episodes(episodes: int) -> int:
    """Play random-action episodes on the real env and on ``MinimalStep``; they must match."""
    cfg = load_experiment("config01").env_config()
    real = frontier_marl.FrontierExploreEnv(preset=None, config=cfg)
    minimal = MinimalStep()
    steps = 0
    for seed in range(episodes):
        got, expected = minimal.reset(seed=seed), real.reset(seed=seed)
        rng = np.random.default_rng(seed)
        done = False
        while not done:
            action = int(rng.integers(cfg.n_slots))
            got, expected = minimal.step(action), real.step(action)
            for key in ("clusters", "agent_position"):
                np.testing.assert_array_equal(got[0][key], expected[0][key])
            assert got[1:4] == expected[1:4], (seed, steps, got[1:4], expected[1:4])
            assert got[4]["new_cells"] == expected[4]["new_cells"], (seed, steps)
            table = expected[4]["slots"]
            np.testing.assert_array_equal(got[4]["target"], table.target[: table.live])
            for key in ("action_mask", "path"):
                np.testing.assert_array_equal(got[4][key], expected[4][key])
            done = got[2] or got[3]
            steps += 1
    return steps


def warm_us_per_step(env: gym.Env, steps: int) -> float:
    """Microseconds per ``step`` outside training (random actions, resets not timed)."""
    rng = np.random.default_rng(0)
    env.reset(seed=0)
    elapsed, seed = 0.0, 0
    for _ in range(steps):
        action = int(rng.integers(env.action_space.n))
        start = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(action)
        elapsed += time.perf_counter() - start
        if terminated or truncated:
            seed += 1
            env.reset(seed=seed)
    return 1e6 * elapsed / steps


def training_shares(steps: int, chunks: int) -> dict[str, Any]:
    """Train the thesis's DQN on each env, interleaved in chunks; seconds and env shares."""
    cfg = load_experiment("config01").env_config()
    real = frontier_marl.FrontierExploreEnv(preset=None, config=cfg, info="minimal")
    unlabelled = MinimalStep()
    unlabelled.relabel = False
    envs: dict[str, gym.Env] = {
        "null": NullEnv(real),
        "env": real,
        "minimal": MinimalStep(),
        "minimal_without_labelling": unlabelled,
    }
    seconds = {name: sum(chunk) for name, chunk in train_interleaved(envs, steps, chunks).items()}
    return {
        "steps": chunks * -(-steps // chunks),
        "chunks": chunks,
        "seconds": seconds,
        "env_share": {
            name: (seconds[name] - seconds["null"]) / seconds[name]
            for name in envs
            if name != "null"
        },
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=30_000)
    parser.add_argument("--chunks", type=int, default=15)
    parser.add_argument("--check-episodes", type=int, default=30)
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args()
    checked = check_same_episodes(args.check_episodes)
    print(f"MinimalStep plays the real env's episodes exactly ({checked} steps checked)")
    cfg = load_experiment("config01").env_config()
    warm = {
        "env": warm_us_per_step(frontier_marl.FrontierExploreEnv(preset=None, config=cfg), 20_000),
        "minimal": warm_us_per_step(MinimalStep(), 20_000),
    }
    print(f"µs per step outside training: env {warm['env']:.1f}, minimal {warm['minimal']:.1f}")
    report = training_shares(args.steps, args.chunks)
    report["steps_checked"] = checked
    report["warm_us_per_step"] = warm
    for name, second in report["seconds"].items():
        share = report["env_share"].get(name)
        text = "" if share is None else f"  env share {100 * share:.1f} %"
        print(f"{name:>26}: {second:6.1f} s{text}")
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(report, handle, indent=2)


if __name__ == "__main__":
    main()
