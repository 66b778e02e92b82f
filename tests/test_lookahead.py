"""The lookahead oracle (evaluation/lookahead.py) and the imitation tools built on it
(training/imitation.py)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

import frontier_marl
from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN
from frontier_marl.core.sensing import make_sensor
from frontier_marl.core.world import World, WorldParams
from frontier_marl.policies.lookahead import LookaheadOracle, lookahead_costs


def _corridor() -> World:
    """A 13-cell corridor (columns 1..13 of row 1), the robot at column 4, sensor range 1."""
    grid = np.ones((3, 15), dtype=bool)
    grid[1, 1:14] = False
    return World(grid, np.array([[1, 4]]), WorldParams(make_sensor("square", 1), 1))


def test_lookahead_costs_on_a_corridor_with_known_answers() -> None:
    world = _corridor()
    belief, positions = world.belief.copy(), world.positions.copy()
    # Left first: (1,3), (1,2), (1,1) sees the end wall, then right to (1,12): 3 + 11 cells.
    # Right first: out to (1,13) (9 cells), back to (1,2), where column 1 becomes known: 11.
    costs = lookahead_costs(world.batch, world.index, np.array([[1, 3], [1, 5]]), 0.99, 100)
    assert costs.tolist() == [14, 20]
    # the simulations ran on copies: the world itself has not moved or sensed
    assert np.array_equal(world.belief, belief)
    assert np.array_equal(world.positions, positions)
    assert world.travelled.tolist() == [0]


def test_lookahead_costs_cap_a_simulation_that_cannot_finish() -> None:
    world = _corridor()
    # a coverage above 1 is never reached: every simulation stops at the cap (or earlier,
    # with nothing left to explore, and then costs the cap as well)
    costs = lookahead_costs(world.batch, world.index, np.array([[1, 3]]), 1.5, 30)
    assert costs.tolist() == [30]


def test_lookahead_costs_need_one_robot() -> None:
    grid = np.zeros((6, 6), dtype=bool)
    world = World(grid, np.array([[0, 0], [5, 5]]), WorldParams(make_sensor("square", 1), 1))
    with pytest.raises(ValueError, match="one robot"):
        lookahead_costs(world.batch, world.index, np.array([[0, 2]]), 0.99, 100)


def test_oracle_travels_less_than_nearest_path_on_validation_episodes() -> None:
    from frontier_marl.evaluation.benchmark.families import family, variant_configs
    from frontier_marl.evaluation.benchmark.run import contenders, run_family
    from frontier_marl.evaluation.records import level_key

    fam = family("random-20")
    worlds = variant_configs(fam)
    t99 = {}
    for contender in contenders(["nearest-path", "lookahead-oracle"]):
        result = run_family(fam, contender, worlds, 4, split="validation")
        t99[contender.name] = [e.cells_to_coverage[level_key(0.99)] for e in result.episodes]
    assert None not in t99["lookahead-oracle"]
    assert np.mean(t99["lookahead-oracle"]) < 0.95 * np.mean(t99["nearest-path"])


def test_oracle_is_never_the_best_heuristic_and_refuses_teams() -> None:
    from frontier_marl.cli.main import main
    from frontier_marl.evaluation.benchmark.families import family
    from frontier_marl.evaluation.benchmark.run import contenders, run_benchmark

    rows = run_benchmark(
        [family("random-20")], contenders(["nearest-path", "lookahead-oracle"]), episodes=2
    )
    assert [row["best_heuristic"] for row in rows] == ["nearest-path"] * 2
    assert main(["benchmark", "--policies", "lookahead-oracle", "--agents", "2"]) == 2
    import frontier_marl

    env = frontier_marl.parallel_env(preset="thesis-20x20", n_agents=2)
    with pytest.raises(ValueError, match="one robot"):
        LookaheadOracle().attach(env)


def test_imitation_labels_real_decisions_and_fits_them() -> None:
    from frontier_marl.config import make_config
    from frontier_marl.envs.parallel import FrontierParallelEnv
    from frontier_marl.evaluation.benchmark.families import family, variant_configs
    from frontier_marl.policies.networks.slot_dqn import SlotScorer
    from frontier_marl.training.imitation import Dataset, fit, play

    own = {"features": "explorer", "n_slots": 6, "gain": "unknown", "commit": "until-reached"}
    world = variant_configs(family("random-20"))[0]
    cfg = make_config(config=world, **own)
    data = Dataset()
    env = FrontierParallelEnv(config=cfg, obs_layout="flat")
    travelled = play(env, 5, data, None, 1.0, np.random.default_rng(0))
    assert len(data) > 0 and travelled > 0
    slots, masks, targets, valid = data.tensors()
    assert slots.shape == (len(data), 6, 10) and masks.shape == (len(data), 6)
    assert (valid.sum(dim=1) >= 2).all()  # only decisions with a choice are labelled
    assert torch.equal(valid, masks.bool())
    assert (targets <= 0).all() and (targets.max(dim=1).values == 0).all()  # 0: the cheapest

    class Net(torch.nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.scorer = SlotScorer(6, 10, [16, 16], torch.nn.ReLU)

        def forward(self, obs: dict[str, torch.Tensor]) -> torch.Tensor:
            flat = torch.cat([obs["slots"].flatten(1), obs["action_mask"].float()], dim=1)
            return self.scorer(flat)

    losses = fit(Net(), data, 20, 32, 1e-2, torch.Generator().manual_seed(0))
    assert len(losses) == 20 and losses[-1] < losses[0]


def test_a_linear_rollout_base_takes_the_best_scored_live_slot() -> None:
    from frontier_marl import FrontierParallelEnv
    from frontier_marl.config import make_config
    from frontier_marl.core.slots import SlotArrays
    from frontier_marl.policies.frontier_rule import FRONTIER_RULE_SETTINGS
    from frontier_marl.policies.linear_scorer import feature_names
    from frontier_marl.policies.lookahead import LinearScorerBase

    cfg = make_config("thesis-20x20", map_mode="dynamic", **FRONTIER_RULE_SETTINGS)
    path_only = np.array([-1.0 if name == "path" else 0.0 for name in feature_names(cfg)])
    base = LinearScorerBase(cfg, path_only)  # nearest-path among the 12 slots
    env = FrontierParallelEnv(config=cfg)
    for seed in range(5):
        env.reset(seed=seed)
        sims, index = env.world.batch, np.array([env.world.index])
        slots = SlotArrays.empty(sims.belief.shape[0], 1, base.n_slots)
        sims.slots(slots, index, False)
        goal = base.goals(sims, slots, index)[0]
        lengths = slots.path_length[index[0], 0]
        live = np.flatnonzero(slots.valid[index[0], 0])
        chosen = [s for s in live if (slots.target[index[0], 0, s] == goal).all()]
        assert len(live) > 1 and chosen and lengths[chosen[0]] == lengths[live].min()
        slots.valid[index[0], 0] = False
        assert (base.goals(sims, slots, index)[0] == -1).all()  # nothing left: no goal
    env.close()


@pytest.mark.slow
def test_the_rollout_probe_scores_both_oracles_on_validation_episodes(tmp_path) -> None:
    import json

    from frontier_marl.experiments.explorer_studies.rollout_probe import main as probe

    out = tmp_path / "probe.json"
    assert (
        probe(["--families", "random-20", "--episodes", "2", "--json", str(out), "--no-progress"])
        == 0
    )
    rows = json.loads(out.read_text())["rows"]
    assert [row["policy"] for row in rows] == [
        "nearest-path", "frontier-rule", "lookahead-oracle", "explorer-rollout"
    ]  # fmt: skip
    assert all(row["seeds"] == [800_000, 800_001] and row["success"] == 2 for row in rows)
    with pytest.raises(SystemExit):
        probe(["--families", "rooms-128"])


def test_the_headroom_probe_scores_both_oracles_in_frontier_rules_env(tmp_path: Path) -> None:
    from frontier_marl.experiments.explorer_studies import headroom

    out = tmp_path / "headroom.json"
    argv = ["--families", "random-20", "--episodes", "1", "--no-progress", "--json", str(out)]
    assert headroom.main(argv) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [row["policy"] for row in rows] == ["frontier-rule", "oracle-np-12", "oracle-rule-12"]
    assert {row["config"]["n_slots"] for row in rows} == {12}  # the same slots for all three
    assert all(row["success"] == 1 for row in rows)


def test_completion_costs_keep_the_known_cells_and_average_the_maps() -> None:
    from frontier_marl.policies.lookahead import completion_costs

    world = _corridor()
    targets = np.array([[1, 3], [1, 5]])
    true_grid = world.true_grid.copy()
    # the true map as its own completion: the true-map lookahead's costs
    assert completion_costs(world.batch, 0, targets, 0.99, 100, [true_grid]).tolist() == [14, 20]
    # walls wherever the robot knows nothing: the known cells are the whole region, covered
    # already, so no candidate costs a cell
    walls = np.ones_like(true_grid)
    assert completion_costs(world.batch, 0, targets, 0.99, 100, [walls]).tolist() == [0, 0]
    both = completion_costs(world.batch, 0, targets, 0.99, 100, [true_grid, walls])
    assert both.tolist() == [7, 10]
    assert world.travelled.tolist() == [0]  # simulations on copies


def test_the_completions_study_plays_its_planner_on_validation_episodes(tmp_path: Path) -> None:
    from frontier_marl.experiments.explorer_studies import completions

    out = tmp_path / "completions.json"
    argv = ["--families", "random-20", "--samples", "2", "--episodes", "1", "--no-oracle"]
    assert completions.main([*argv, "--jobs", "1", "--no-progress", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [row["policy"] for row in rows] == ["frontier-rule", "completions-2"]
    assert all(row["seeds"] == [800_000] and row["success"] == 1 for row in rows)
    matched = [*argv, "--match", "2", "--band", "2", "--jobs", "1", "--no-progress"]
    assert completions.main([*matched, "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert rows[1]["policy"] == "completions-2-of-4-b2" and rows[1]["success"] == 1
    for bad in (["--samples", "0"], ["--samples", "x"], ["--match", "0"], ["--band", "0"]):
        with pytest.raises(SystemExit):
            completions.main(bad)
    planner = completions.CompletionLookahead(2)
    env = frontier_marl.FrontierParallelEnv(preset="thesis-20x20", map_mode="static")
    with pytest.raises(ValueError, match="dynamic generated maps"):
        planner.attach(env)


def test_matched_completions_keep_the_draws_whose_walls_continue_the_belief() -> None:
    from frontier_marl.experiments.explorer_studies.completions import (
        best_matching,
        completions_name,
    )

    belief = np.full((3, 4), UNKNOWN, dtype=np.int8)
    belief[:, :2] = FREE
    belief[0, 1] = OCCUPIED  # column 1 borders the unknown: wall, free, free
    blocked = np.zeros((3, 4), dtype=bool)
    blocked[:, 1] = True  # agrees on one of the three
    half = blocked.copy()
    half[1, 1] = False  # two
    walled = np.zeros((3, 4), dtype=bool)
    walled[0, 1] = True  # three
    open_map = np.zeros((3, 4), dtype=bool)  # two
    kept = best_matching([blocked, half, walled, open_map], belief, 2, band=1)
    assert kept[0] is walled and kept[1] is half  # a tie keeps the earlier draw
    assert completions_name(8, 1, 3) == "completions-8"
    assert completions_name(8, 4, 2) == "completions-8-of-32-b2"
