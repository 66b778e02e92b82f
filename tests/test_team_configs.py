"""The team training configs and example map names in [env] map_path."""

from __future__ import annotations

import pytest

from frontier_marl.core.example_maps import example_map_path
from frontier_marl.training.experiment import experiment_from_dict, load_experiment


def test_example_map_name_resolves_to_its_file() -> None:
    exp = experiment_from_dict(
        {"name": "x", "env": {"preset": "thesis-30x30", "map_path": "rooms-32"}}
    )
    assert exp.env["map_path"] == str(example_map_path("rooms-32"))
    cfg = exp.env_config()
    assert (cfg.height, cfg.width) == (32, 32)


def test_unknown_map_name_is_still_a_path_error() -> None:
    with pytest.raises(ValueError, match="map_path"):
        experiment_from_dict({"name": "x", "env": {"map_path": "rooms-999"}})


@pytest.mark.parametrize(
    ("config", "shape", "map_file"),
    [("team_30x30", (30, 30), None), ("team_rooms64", (64, 64), "rooms-64.txt")],
)
def test_team_configs(config: str, shape: tuple[int, int], map_file: str | None) -> None:
    exp = load_experiment(config)
    cfg = exp.env_config()
    assert cfg.n_agents == 2
    assert (cfg.height, cfg.width) == shape
    assert (cfg.map_path is None) == (map_file is None)
    if map_file is not None:
        assert cfg.map_path.endswith(map_file)
    assert cfg.perception_range == 5
    assert (cfg.reward.explore_threshold, cfg.reward.max_steps) == (1.0, 5000)
    assert cfg.reward.no_progress_limit == 500
    assert cfg.reward.kind == "reward2"
    obs = cfg.observation
    assert (obs.centroid, obs.agent_position, obs.info_gain, obs.sort_by_distance) == (
        "absolute",
        True,
        False,
        False,
    )
    assert exp.train.total_timesteps == 500_000
    assert exp.train.eval_episodes == 10
    assert exp.dqn["learning_rate"] == 5e-5


def test_multi_robot_comparison_of_a_policy_that_never_reaches_a_level() -> None:
    import copy

    from frontier_marl.experiments import multi_robot, multi_robot_tables
    from frontier_marl.policies import make_policy

    settings_ = {
        "tiny": {
            "map_path": str(example_map_path("rooms-32")),
            "explore_threshold": 1.0,
            "no_progress_limit": 200,
        }
    }
    rows = multi_robot.run_experiment(
        settings_,
        {"greedy-distance": lambda: make_policy("greedy-distance")},
        [2],
        2,
        log=lambda _: None,
    )
    stuck = copy.deepcopy(rows[0])
    stuck["policy"] = "stuck"
    for episode in stuck["per_episode"]:
        episode["makespan_to_coverage"]["0.99"] = None
    entries = multi_robot_tables.comparison([rows[0], stuck])
    assert len(entries) == 1
    assert entries[0]["makespan@0.99"]["episodes"] == 0
    assert entries[0]["makespan@0.99"]["change"] is None
    assert entries[0]["overlap"]["episodes"] == 2
    table = multi_robot_tables.comparison_table(entries)
    assert "no paired episode" in table and "nan" not in table
    endings = multi_robot_tables.endings_table([rows[0]])
    assert "| tiny | 2 | greedy-distance | 1.000 | threshold 2 |" in endings
