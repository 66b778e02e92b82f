"""The map-aware team chooser: the teammates' crop channels, the team labels, the scorer's
folder and the benchmark playing it (policies/team_map_explorer.py, training/team_cost_to_go.py,
experiments/explorer_studies/team_map_scorer.py)."""

from __future__ import annotations

import json
from functools import partial
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")

from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN  # noqa: E402
from frontier_marl.evaluation.benchmark.contenders import Contender, own_world  # noqa: E402
from frontier_marl.evaluation.benchmark.families import family, variant_configs  # noqa: E402
from frontier_marl.evaluation.benchmark.run import run_family  # noqa: E402
from frontier_marl.policies import map_crops  # noqa: E402
from frontier_marl.policies.map_explorer import (  # noqa: E402
    TEAM_MAP_EXPLORER_SETTINGS,
    load_scorer,
    new_scorer,
)
from frontier_marl.policies.team_lookahead import TeamLookaheadOracle  # noqa: E402
from frontier_marl.policies.team_map_explorer import TeamMapExplorer  # noqa: E402
from frontier_marl.training.team_cost_to_go import _Labeller, label_team_episode  # noqa: E402
from tests.test_map_explorer import window_mean  # noqa: E402


def test_teammate_planes_mark_their_cells_targets_and_the_nearest_ones_path() -> None:
    belief = np.full((5, 7), FREE, dtype=np.int8)
    belief[2, 2] = UNKNOWN
    belief[3, 4] = OCCUPIED
    cells = np.array([[0, 0], [4, 6]])
    targets = np.array([[2, 3], [-1, -1]])
    planes = map_crops.teammate_planes(belief, cells, targets)
    assert planes.shape == (3, 5, 7)
    assert np.argwhere(planes[0]).tolist() == [[0, 0], [4, 6]]
    assert np.argwhere(planes[1]).tolist() == [[2, 3]]
    # 4-connected paths on the free cells; around the unknown cell and the obstacle
    assert planes[2, 0, 3] == 3 / 64  # from (0, 0)
    assert planes[2, 4, 3] == 3 / 64  # from (4, 6), below the obstacle
    assert planes[2, 2, 3] == 5 / 64  # (0, 0) round the unknown cell: 2 + 3; (4, 6): 5 too
    assert planes[2, 2, 2] == 1.0 and planes[2, 3, 4] == 1.0  # not free: unreachable
    alone = map_crops.teammate_planes(belief, np.zeros((0, 2), int), np.zeros((0, 2), int))
    assert not alone[:2].any() and (alone[2] == 1.0).all()


def test_team_crops_add_the_teammates_channels_as_window_means() -> None:
    rng = np.random.default_rng(1)
    belief = rng.choice([FREE, OCCUPIED, UNKNOWN], size=(9, 14), p=[0.6, 0.2, 0.2])
    belief = belief.astype(np.int8)
    belief[4, 6] = belief[1, 1] = FREE
    frontier = rng.random((9, 14)) < 0.2
    planes = np.concatenate(
        [
            map_crops.map_planes(belief, frontier, (4, 6)),
            map_crops.teammate_planes(belief, np.array([[1, 1]]), np.array([[8, 13]])),
        ]
    )
    targets = np.array([[0, 0], [8, 13]])
    clusters = [np.array([[0, 0]]), np.array([[8, 13]])]
    crops = map_crops.candidate_crops(planes, targets, clusters)
    assert crops.shape == (2, *map_crops.crop_shape(team=True))
    assert map_crops.crop_shape(team=True)[0] == 8 * len(map_crops.SCALES)
    for m, target in enumerate(targets):
        mates = [(planes[4], 0.0), (planes[5], 0.0), (planes[6], 1.0)]
        for k, scale in enumerate(map_crops.SCALES):
            cell = crops[m].reshape(len(map_crops.SCALES), -1, map_crops.SIDE, map_crops.SIDE)[k]
            for i, j in ((0, 0), (5, 5), (10, 2)):
                expected = [window_mean(p, out, target, scale, i, j) for p, out in mates]
                np.testing.assert_allclose(cell[5:, i, j], expected, atol=1e-6)


def _team_world(agents: int = 2):
    (world,) = variant_configs(family("random-20"), None, agents)
    return own_world(TEAM_MAP_EXPLORER_SETTINGS, world)


def test_labels_with_the_oracles_share_one_play_the_team_oracles_episodes() -> None:
    """The labeller takes the cheapest candidate by the exact costs, the oracle by pruned
    ones: the same choices, so the same episodes."""
    fam = family("random-20")
    worlds = variant_configs(fam, None, 2)
    config = partial(own_world, TEAM_MAP_EXPLORER_SETTINGS)
    runs = {}
    for name, make in (
        ("oracle", TeamLookaheadOracle),
        ("labeller", lambda: _Labeller(1.0, np.random.default_rng(0), 1)),
    ):
        result = run_family(
            fam, Contender(name, False, make, config), worlds, 2, split="validation"
        )
        runs[name] = [(e.cells_to_coverage, e.makespan_to_coverage) for e in result.episodes]
    assert runs["labeller"] == runs["oracle"]


def test_team_labels_hold_every_candidate_of_every_decision() -> None:
    cfg = _team_world()
    samples = label_team_episode(cfg, int(family("random-20").train[0]), "random-20", 0.5)
    decisions, counts = np.unique(samples.decision, return_counts=True)
    assert len(decisions) > 5 and (counts >= 2).all() and counts.max() <= 12
    assert samples.crops.shape[1:] == map_crops.crop_shape(team=True)
    assert samples.crops.dtype == np.uint8
    assert samples.features.shape[1] == 17  # frontier-rule's 14 and three of the teammates
    assert (samples.cost >= 0).all() and (samples.cost < 4 * 20 * 20).all()
    assert (samples.family == "random-20").all()
    half = label_team_episode(cfg, int(family("random-20").train[0]), "random-20", 0.5, every=2)
    assert len(np.unique(half.decision)) == -(-len(decisions) // 2)
    with pytest.raises(ValueError, match="commit"):
        label_team_episode(own_world({"commit": "until-reached"}, cfg), 0)
    with pytest.raises(ValueError, match="oracle_share"):
        label_team_episode(cfg, 0, oracle_share=1.5)


def test_a_team_scorer_is_saved_fitted_and_played_by_the_benchmark(tmp_path: Path, capsys):
    from frontier_marl.cli.main import main as cli
    from frontier_marl.experiments.explorer_studies.team_map_scorer import main, probe_main

    folder = tmp_path / "team-map"
    argv = ["--families", "random-20", "--agents", "2", "--episodes", "1", "--epochs", "1"]
    assert main([*argv, "--workers", "1", "--save", str(folder), "--no-progress"]) == 0
    metadata = json.loads((folder / "model.json").read_text())
    assert metadata["scorer"]["team"] is True
    assert metadata["env_settings"]["teammates"] == "positions+targets"
    assert metadata["labels"] > 0
    model, _ = load_scorer(folder)
    refit = tmp_path / "refit"
    stored = ["--labels", str(folder / "labels.npz")]
    assert main([*argv[:4], "--episodes", "0", *stored, "--epochs", "1", "--save", str(refit)]) == 0
    again, _ = load_scorer(refit)
    for name, value in model.state_dict().items():  # the fit depends on its seed alone
        assert (again.state_dict()[name] == value).all(), name
    dagger = tmp_path / "round1"  # the learner's own states, the stored labels kept
    round1 = ["--round", "1", "--learner", str(folder), *stored, "--save", str(dagger)]
    assert main([*argv, "--workers", "1", *round1, "--no-progress"]) == 0
    record = json.loads((dagger / "model.json").read_text())
    assert record["labels"] > metadata["labels"]
    capsys.readouterr()
    assert probe_main([str(folder), str(folder / "labels.npz")]) == 0
    (row,) = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert row["family"] == "random-20" and row["decisions"] > 0
    assert 0 <= row["scorer"] <= 1 and 0 <= row["nearest"] <= 1
    bench = ["benchmark", "--agents", "2", "--families", "random-20", "--episodes", "1"]
    assert cli([*bench, "--policies", f"coordinated-assignment,{folder}", "--no-progress"]) == 0
    assert "team-map" in capsys.readouterr().out
    bad_options = (
        ["--agents", "1"],
        ["--learner", str(tmp_path)],
        ["--oracle-share", "2"],
        ["--labels", str(tmp_path / "none.npz")],
    )
    for bad in bad_options:
        with pytest.raises(SystemExit):
            main([*argv, *bad, "--save", str(folder)])


def test_a_team_scorer_refuses_an_env_with_other_slot_features() -> None:
    import frontier_marl
    from frontier_marl.policies.map_explorer import MAP_EXPLORER_SETTINGS

    policy = TeamMapExplorer(new_scorer(17, 8, team=True))
    single = {**MAP_EXPLORER_SETTINGS, "n_agents": 2}  # no teammate features
    with pytest.raises(ValueError, match="reads 17 slot features; the env gives 14"):
        policy.attach(frontier_marl.parallel_env(preset="thesis-20x20", **single))
    with pytest.raises(RuntimeError, match="attach"):
        TeamMapExplorer(new_scorer(17, 8, team=True)).act_team({}, {})
