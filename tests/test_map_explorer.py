"""The map-aware explorer's parts: crops, cost-to-go labels, the scorer, its fit, the command."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

import frontier_marl  # noqa: E402
from frontier_marl.cli.main import main  # noqa: E402
from frontier_marl.config import make_config  # noqa: E402
from frontier_marl.core.grid import FREE, OCCUPIED, UNKNOWN  # noqa: E402
from frontier_marl.evaluation.benchmark import families as map_families  # noqa: E402
from frontier_marl.evaluation.benchmark.contenders import map_model  # noqa: E402
from frontier_marl.experiments.explorer_studies.map_scorer_ablation import (  # noqa: E402
    main as ablation_main,
)
from frontier_marl.experiments.explorer_studies.map_scorer_ensemble import (  # noqa: E402
    Averaged,
)
from frontier_marl.experiments.explorer_studies.map_scorer_ensemble import (  # noqa: E402
    main as ensemble_main,
)
from frontier_marl.experiments.explorer_studies.map_scorer_mix import (  # noqa: E402
    main as mix_main,
)
from frontier_marl.experiments.explorer_studies.map_scorer_mix import (  # noqa: E402
    mixed_labels,
)
from frontier_marl.experiments.explorer_studies.map_scorer_probe import main as probe_main  # noqa: E402
from frontier_marl.experiments.explorer_studies.member_spread import (  # noqa: E402
    SpreadPenalised,
)
from frontier_marl.experiments.explorer_studies.member_spread import (  # noqa: E402
    main as spread_main,
)
from frontier_marl.policies import map_crops  # noqa: E402
from frontier_marl.policies.frontier_rule import FRONTIER_RULE_WEIGHTS  # noqa: E402
from frontier_marl.policies.linear_scorer import feature_names, weight_vector  # noqa: E402
from frontier_marl.policies.lookahead import LinearScorerBase, lookahead_costs  # noqa: E402
from frontier_marl.policies.map_explorer import (  # noqa: E402
    MapExplorer,
    load_scorer,
    new_scorer,
    save_map_explorer,
)
from frontier_marl.policies.models import map_scorer_folder, resolve_model_path  # noqa: E402
from frontier_marl.training import cost_regression  # noqa: E402
from frontier_marl.training.cost_regression import scorer_config  # noqa: E402
from frontier_marl.training.cost_to_go import (  # noqa: E402
    Samples,
    cells_regret,
    decision_candidates,
    first_choice_of,
    label_episode,
    relative_regret,
)
from frontier_marl.training.experiment import load_experiment  # noqa: E402
from frontier_marl.training.regression import (  # noqa: E402
    Decisions,
    batch_loss,
    family_weights,
    fit,
    group,
    members_loss,
    step_size_factor,
    symmetry,
)


def window_mean(plane: np.ndarray, outside: float, target, scale: int, i: int, j: int) -> float:
    """One crop cell by brute force: the mean over its scale x scale map cells."""
    height, width = plane.shape
    half = map_crops.SIDE // 2
    top = target[0] + (i - half) * scale - scale // 2
    left = target[1] + (j - half) * scale - scale // 2
    cells = [
        plane[r, c] if 0 <= r < height and 0 <= c < width else outside
        for r in range(top, top + scale)
        for c in range(left, left + scale)
    ]
    return float(np.mean(cells))


def test_crops_are_window_means_of_the_belief_on_a_non_square_map() -> None:
    rng = np.random.default_rng(0)
    belief = rng.choice([FREE, OCCUPIED, UNKNOWN], size=(9, 14)).astype(np.int8)
    belief[4, 6] = FREE
    frontier = rng.random((9, 14)) < 0.2
    planes = map_crops.map_planes(belief, frontier, (4, 6))
    targets = np.array([[0, 0], [8, 13], [5, 7]])
    clusters = [np.array([[0, 0], [0, 1]]), np.array([[8, 13]]), np.array([[5, 7], [6, 7]])]
    crops = map_crops.candidate_crops(planes, targets, clusters)
    assert crops.shape == (3, *map_crops.crop_shape())
    for m, target in enumerate(targets):
        own = np.zeros(belief.shape)
        own[tuple(clusters[m].T)] = 1.0
        channels = [(planes[0], 0.0), (planes[1], 1.0), (planes[2], 0.0), (own, 0.0)]
        channels.append((planes[3], 1.0))
        for k, scale in enumerate(map_crops.SCALES):
            cell = crops[m].reshape(len(map_crops.SCALES), -1, map_crops.SIDE, map_crops.SIDE)[k]
            for i, j in ((0, 0), (5, 5), (3, 9), (10, 2)):
                expected = [window_mean(p, out, target, scale, i, j) for p, out in channels]
                np.testing.assert_allclose(cell[:, i, j], expected, atol=1e-6)


def test_relative_regret_is_the_cost_over_the_cheapest_of_its_decision() -> None:
    regret = relative_regret(np.array([10.0, 15.0, 40.0, 0.0, 3.0]), np.array([0, 0, 0, 1, 1]))
    np.testing.assert_allclose(regret, [0.0, 0.5, 1.0, 0.0, 1.0])  # capped at 1; 0 cells: 1


def test_cells_regret_is_the_extra_cost_over_the_map_side() -> None:
    cost, decision = np.array([10.0, 15.0, 40.0, 7.0, 3.0]), np.array([0, 0, 0, 1, 1])
    regret = cells_regret(cost, decision, np.array([10.0, 10.0, 10.0, 2.0, 2.0]))
    np.testing.assert_allclose(regret, [0.0, 0.5, 1.5, 1.5, 0.0])  # 3.0 and 2.0 capped at 1.5


def test_grouped_decisions_keep_each_candidates_extra_cells() -> None:
    samples = Samples(
        crops=np.zeros((5, *map_crops.crop_shape()), np.uint8),
        features=np.arange(5, dtype=np.float32)[:, None],
        cost=np.array([7.0, 3.0, 10.0, 15.0, 40.0]),
        decision=np.array([1, 1, 0, 0, 0]),
        family=np.full(5, "random-20"),
    )
    samples.crops[:, 0, 0, 0] = np.arange(5)  # each candidate's crops carry its number
    grouped = group(samples, 4)
    assert grouped.features[..., 0].tolist() == [[2, 3, 4, 0], [0, 1, 0, 0]]
    assert len(grouped.crops) == 5  # once per candidate, no padding
    assert (grouped.valid_crops()[:, 0, 0, 0] * 255).tolist() == [2, 3, 4, 0, 1]
    assert (grouped.subset([1]).valid_crops()[:, 0, 0, 0] * 255).tolist() == [0, 1]
    assert grouped.extra.tolist() == [[0, 5, 30, 0], [4, 0, 0, 0]]
    np.testing.assert_allclose(grouped.regret[0, :3], [0.0, 0.5, 1.0])


def test_a_quarter_turn_turns_the_crops_and_the_offsets_alike() -> None:
    half = map_crops.SIDE // 2
    for k in range(8):
        crops = torch.zeros(1, 1, 1, map_crops.SIDE, map_crops.SIDE)
        crops[0, 0, 0, half - 2, half + 3] = 1.0  # the robot: target minus (2, -3)
        features = torch.zeros(1, 1, 14)
        features[..., 2], features[..., 3] = 2.0, -3.0
        turned, offsets = symmetry(crops, features, k)
        row, col = (turned[0, 0, 0] == 1).nonzero()[0].tolist()
        assert (half - row, half - col) == (offsets[0, 0, 2].item(), offsets[0, 0, 3].item())


def test_the_scorer_is_permutation_equivariant_and_masks_padding() -> None:
    torch.manual_seed(0)
    model = new_scorer(14, width=8)
    crops = torch.rand(1, 5, *map_crops.crop_shape())
    features = torch.rand(1, 5, 14)
    mask = torch.tensor([[True, True, True, False, False]])
    scores = model(crops[mask], features, mask)
    assert torch.isinf(scores[0, 3:]).all() and torch.isfinite(scores[0, :3]).all()
    order = torch.tensor([2, 0, 1, 3, 4])
    shuffled = model(crops[:, order][mask[:, order]], features[:, order], mask[:, order])
    torch.testing.assert_close(shuffled[0, :3], scores[0, order[:3]])
    padded = crops.clone()
    padded[0, 3:] = torch.rand(2, *map_crops.crop_shape())  # the padding's crops are not read
    torch.testing.assert_close(model(padded[mask], features, mask), scores)
    with pytest.raises(ValueError, match="5 crops for 3 valid candidates"):
        model(crops[0], features, mask)


def test_a_scorer_of_several_members_is_the_mean_of_them_run_alone() -> None:
    """Member k of a batched scorer is a one-member scorer holding its slice of the weights."""
    torch.manual_seed(1)
    members, width = 3, 8
    batched = new_scorer(14, width, members).eval()
    crops, features = torch.rand(5, *map_crops.crop_shape()), torch.rand(2, 3, 14)
    mask = torch.tensor([[True, True, False], [True, True, True]])
    alone = []
    for k in range(members):
        single = new_scorer(14, width)
        state = {}
        for key, value in batched.state_dict().items():
            size = len(value) // members
            state[key] = value if key.startswith("feature_") else value[k * size : (k + 1) * size]
        single.load_state_dict(state)
        alone.append(single.eval()(crops, features, mask))
    with torch.no_grad():
        each = batched.member_regrets(crops, features, mask)
        torch.testing.assert_close(each[mask], torch.stack(alone, -1)[mask])
        torch.testing.assert_close(batched(crops, features, mask), torch.stack(alone).mean(0))
    with pytest.raises(ValueError, match="members >= 1"):
        new_scorer(14, width, 0)


def test_a_scorer_of_several_members_survives_saving(tmp_path: Path) -> None:
    torch.manual_seed(2)
    model = new_scorer(14, 8, members=2).eval()
    save_map_explorer(model, tmp_path / "scorer", {"rule_weight": 1.0})
    again, metadata = load_scorer(tmp_path / "scorer")
    assert metadata["scorer"] == {"n_features": 14, "width": 8, "members": 2, "team": False}
    crops, features = torch.rand(3, *map_crops.crop_shape()), torch.rand(1, 3, 14)
    mask = torch.ones((1, 3), dtype=torch.bool)
    with torch.no_grad():
        assert torch.equal(again(crops, features, mask), model(crops, features, mask))


def test_the_members_spread_is_added_to_their_mean(tmp_path: Path, capsys) -> None:
    torch.manual_seed(3)
    model = new_scorer(14, 8, members=3).eval()
    crops, features = torch.rand(5, *map_crops.crop_shape()), torch.rand(2, 3, 14)
    mask = torch.tensor([[True, True, False], [True, True, True]])
    with torch.no_grad():
        each = model.member_regrets(crops, features, mask)
        penalised = SpreadPenalised(model, 2.0)(crops, features, mask)
        assert torch.equal(
            SpreadPenalised(model, 0.0)(crops, features, mask), model(crops, features, mask)
        )
    torch.testing.assert_close(penalised[mask], (each.mean(-1) + 2 * each.std(-1))[mask])
    assert torch.isinf(penalised[0, 2])
    with pytest.raises(ValueError, match="two or more members, the scorer has 1"):
        SpreadPenalised(new_scorer(14, 8), 1.0)
    scorer_config_names = feature_names(scorer_config(make_config("thesis-20x20")))
    save_map_explorer(new_scorer(len(scorer_config_names), 8, 2), tmp_path / "two", {})
    report = tmp_path / "spread.json"
    args = ["--spreads", "0,1", "--weights", "1", "--families", "random-20", "--episodes", "1"]
    assert spread_main([str(tmp_path / "two"), *args, "--json", str(report)]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert [line.split(":")[0] for line in printed] == [
        "spread 0.0, rule weight 1.0",
        "spread 1.0, rule weight 1.0",
    ]
    assert all("T99 vs frontier-rule" in line and "(random-20 " in line for line in printed)
    spreads = json.loads(report.read_text())["spreads"]
    assert list(spreads) == ["0.0", "1.0"] and set(spreads["1.0"]["1.0"]["by_family"]) == {
        "random-20"
    }
    save_map_explorer(new_scorer(len(scorer_config_names), 8), tmp_path / "one", {})
    with pytest.raises(SystemExit):
        spread_main([str(tmp_path / "one"), *args])
    assert "two or more members" in capsys.readouterr().err


def test_each_member_is_fitted_on_its_own_loss() -> None:
    regret = torch.tensor([[0.0, 0.5, 9.0]])
    batch = Decisions(
        torch.zeros((2, 1, 1, 1)),
        torch.zeros((1, 3), dtype=torch.long),
        torch.zeros((1, 3, 1)),
        regret,
        torch.tensor([[True, True, False]]),
        torch.zeros((1, 3)),
    )
    first = torch.tensor([[0.0, 0.0, float("inf")]])  # loss 0.125
    second = torch.tensor([[0.0, 0.5, float("inf")]])  # loss 0
    both = torch.stack([first, second], -1)
    assert members_loss("regret", both, batch).item() == pytest.approx(0.0625)
    for kind in ("ranking", "argmax"):
        alone = [batch_loss(kind, p, regret, batch.mask).item() for p in (first, second)]
        assert members_loss(kind, both, batch).item() == pytest.approx(np.mean(alone))


@pytest.fixture(scope="module")
def labelled() -> Samples:
    fam = map_families.family("random-20")
    (world,) = map_families.variant_configs(fam, None, 1)
    nearest = first_choice_of(lambda obs, candidates: candidates.features[:, 0])
    return label_episode(scorer_config(world), fam.train[0], nearest, family="random-20")


def test_labels_finished_by_frontier_rule_cost_what_its_rollouts_walk() -> None:
    fam = map_families.family("rooms-32")
    (world,) = map_families.variant_configs(fam, None, 1)
    cfg = scorer_config(world)
    settings = {"scorer_width": 8, "rule_share": 0.5}
    rule = cost_regression.RegressionSettings(**settings, finisher="frontier-rule")
    nearest = cost_regression.RegressionSettings(**settings)
    by_rule = cost_regression._label(("rooms-32", int(fam.train[0]), None, rule, 0))
    by_nearest = cost_regression._label(("rooms-32", int(fam.train[0]), None, nearest, 0))
    np.testing.assert_array_equal(by_rule.decision, by_nearest.decision)  # same behaviour
    assert not np.array_equal(by_rule.cost, by_nearest.cost)  # other finishers, other costs
    env = frontier_marl.parallel_env(config=cfg)
    observations, _ = env.reset(seed=int(fam.train[0]))
    candidates = decision_candidates(env, observations["robot_0"])
    while len(candidates.slots) < 2:
        observations, *_ = env.step({"robot_0": int(candidates.slots[0])})
        candidates = decision_candidates(env, observations["robot_0"])
    targets = env.mdp.slot_tables()[0].target[candidates.slots]
    world_now = env.world
    rule = weight_vector(FRONTIER_RULE_WEIGHTS, feature_names(cfg), "frontier-rule")
    costs = lookahead_costs(
        world_now.batch,
        world_now.index,
        targets,
        cfg.reward.explore_threshold,
        4 * cfg.height * cfg.width,
        LinearScorerBase(cfg, rule),
    )
    np.testing.assert_array_equal(by_rule.cost[by_rule.decision == 0], costs)


def test_labels_give_every_candidate_of_a_decision_its_cost_to_go(labelled: Samples) -> None:
    decisions = int(labelled.decision.max()) + 1
    assert decisions > 10 and len(labelled) > 2 * decisions  # real choices, several each
    assert labelled.crops.dtype == np.uint8 and labelled.features.shape[1] == 14
    assert (labelled.cost > 0).all() and set(labelled.family) == {"random-20"}
    grouped = group(labelled, 12)
    assert len(grouped) == decisions
    assert (grouped.regret[grouped.mask] >= 0).all()
    assert (grouped.regret.masked_fill(~grouped.mask, 9).min(dim=1).values == 0).all()


def test_one_decision_in_three_labelled_is_every_third_of_the_full_labels(
    labelled: Samples,
) -> None:
    fam = map_families.family("random-20")
    (world,) = map_families.variant_configs(fam, None, 1)
    nearest = first_choice_of(lambda obs, candidates: candidates.features[:, 0])
    cfg = scorer_config(world)
    thinned = label_episode(cfg, fam.train[0], nearest, family="random-20", every=3)
    kept = labelled.decision % 3 == 0  # the same episode: the behaviour does not read labels
    np.testing.assert_array_equal(thinned.decision, labelled.decision[kept] // 3)
    np.testing.assert_array_equal(thinned.cost, labelled.cost[kept])
    np.testing.assert_array_equal(thinned.crops, labelled.crops[kept])
    with pytest.raises(ValueError, match="every must be an integer >= 1, got 0"):
        label_episode(cfg, fam.train[0], nearest, every=0)


def test_samples_survive_a_round_trip_and_a_join(labelled: Samples, tmp_path: Path) -> None:
    labelled.save(tmp_path / "labels.npz")
    again = Samples.load(tmp_path / "labels.npz")
    assert np.array_equal(again.crops, labelled.crops) and np.array_equal(again.cost, labelled.cost)
    joined = Samples.join([labelled, again])
    assert len(joined) == 2 * len(labelled)
    assert joined.decision.max() + 1 == 2 * (labelled.decision.max() + 1)


def test_a_fit_depends_on_its_seed_alone(labelled: Samples) -> None:
    reg = cost_regression.RegressionSettings(fit_epochs=1, scorer_width=8)
    first = cost_regression.fitted(labelled, reg, seed=3).state_dict()
    torch.rand(7)  # the global generator moves on: the fit must not read it
    again = cost_regression.fitted(labelled, reg, seed=3).state_dict()
    other = cost_regression.fitted(labelled, reg, seed=4).state_dict()
    assert all(torch.equal(first[key], again[key]) for key in first)
    assert not all(torch.equal(first[key], other[key]) for key in first)


def test_a_fit_runs_on_one_torch_thread_and_gives_the_threads_back(
    labelled: Samples, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On two threads the same fit gave other weights from one process to the next."""
    seen = []
    real_fit = cost_regression.fit

    def recording_fit(*args: object, **kwargs: object) -> list[float]:
        seen.append(torch.get_num_threads())
        return real_fit(*args, **kwargs)

    monkeypatch.setattr(cost_regression, "fit", recording_fit)
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        cost_regression.fitted(labelled, cost_regression.RegressionSettings(fit_epochs=1), 0)
        assert seen == [1] and torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)


@pytest.mark.slow
def test_train_explorer_writes_a_scorer_that_the_benchmark_runs(tmp_path: Path, capsys) -> None:
    out = tmp_path / "run"
    tiny = {
        "train.families": '["random-20"]',
        "train.validation_episodes": 1,
        "regression.rounds": 2,
        "regression.label_episodes": 1,
        "regression.label_workers": 1,
        "regression.fit_epochs": 1,
        "regression.completions": 2,
    }
    sets = [arg for key, value in tiny.items() for arg in ("--set", f"{key}={value}")]
    assert main(["train", "explorer", "--out", str(out), "--no-progress", *sets]) == 0
    started = capsys.readouterr().out
    assert "1 labelled training episodes per family (rollouts" in started  # no other family's
    records = [json.loads(line) for line in (out / "validation.jsonl").read_text().splitlines()]
    assert [r["round"] for r in records] == [0, 1] and records[1]["labels"] > records[0]["labels"]
    tried = records[0]["by_rule_weight_and_family"]
    assert set(tried) == {"0.5", "1.0"} and set(tried["0.5"]) == {"random-20"}
    assert map_scorer_folder(out / "best") == out / "best"
    model, meta = load_scorer(out / "best")
    assert meta["format"] == "map-scorer" and meta["env_settings"]["n_slots"] == 12
    report = tmp_path / "bench.json"
    argv = ["benchmark", "--families", "rooms-32", "--episodes", "1", "--split", "validation"]
    assert main([*argv, "--policies", f"frontier-rule,{out / 'best'}", "--json", str(report)]) == 0
    rows = json.loads(report.read_text())["rows"]
    assert [r["policy"] for r in rows] == ["frontier-rule", "best"] and rows[1]["success"] == 1
    assert rows[1]["config"]["n_slots"] == 12  # frontier-rule's slots
    probe_json = tmp_path / "probe.json"
    probe_args = ["--weights", "0,1", "--families", "random-20", "--episodes", "1"]
    probe_args += ["--label-episodes", "1", "--no-progress", "--json", str(probe_json)]
    assert probe_main([str(out / "best"), *probe_args]) == 0
    probe = json.loads(probe_json.read_text())
    choosers = probe["decisions"]["random-20"]["choosers"]
    assert {"scorer (rule weight 0)", "scorer (rule weight 1)", "frontier-rule"} <= set(choosers)
    assert all(0 <= c["cheapest"] <= 1 and c["regret"] >= 0 for c in choosers.values())
    assert [r["policy"] for r in probe["rows"]] == ["frontier-rule", "scorer-w0", "scorer-w1"]
    ablation_json = tmp_path / "ablation.json"
    ablation_args = ["--variants", "full,no-map,cells", "--weights", "0", "--episodes", "1"]
    ablation_args += ["--epochs", "1", "--train-rounds", "1", "--json", str(ablation_json)]
    assert ablation_main([str(out), *ablation_args]) == 0
    ablation = json.loads(ablation_json.read_text())
    assert ablation["train_rounds"] == 1 and ablation["train_labels"] == records[0]["labels"]
    variants = ablation["variants"]
    assert list(variants) == ["full", "no-map", "cells"]
    for variant in variants.values():
        (held_out,) = variant["held_out_decisions"].values()  # round 1's random-20 decisions
        assert held_out["decisions"] > 0 and "frontier-rule" in held_out["choosers"]
        assert set(variant["validation"]["0.0"]["by_family"]) == {"random-20"}
    ablation_args[ablation_args.index("--train-rounds") + 1] = "2"  # every round
    ablation_args[ablation_args.index("--variants") + 1] = "no-map"
    assert ablation_main([str(out), *ablation_args]) == 0
    ablation = json.loads(ablation_json.read_text())
    assert ablation["train_labels"] == records[1]["labels"]
    assert ablation["variants"]["no-map"]["held_out_decisions"] == {}
    ensemble_json = tmp_path / "ensemble.json"
    ensemble_args = ["--sizes", "1,2", "--weights", "0,1", "--episodes", "1", "--epochs", "1"]
    ensemble_args += ["--with", str(out), "--set", "balance_families=true"]
    ensemble_args += ["--set", 'fit_schedule="cosine"', "--json", str(ensemble_json)]
    assert ensemble_main([str(out), *ensemble_args, "--save", str(tmp_path / "kept")]) == 0
    kept, kept_meta = load_scorer(tmp_path / "kept")
    assert kept_meta["rule_weight"] == 0.0 and kept_meta["regression"]["balance_families"]
    ensemble = json.loads(ensemble_json.read_text())
    assert ensemble["labels"] == 2 * records[1]["labels"]  # the run's labels and --with's
    assert list(ensemble["sizes"]) == ["1", "2"]
    assert set(ensemble["sizes"]["2"]["1.0"]["by_family"]) == {"random-20"}
    true_run = tmp_path / "true-map"  # round 0 again, on the true map: the same decisions
    tiny["regression.completions"], tiny["regression.rounds"] = 0, 1
    sets = [arg for key, value in tiny.items() for arg in ("--set", f"{key}={value}")]
    assert main(["train", "explorer", "--out", str(true_run), "--no-progress", *sets]) == 0
    mix_json = tmp_path / "mix.json"
    mix_args = ["--alphas", "0,1", "--weights", "0", "--episodes", "1", "--epochs", "1"]
    assert mix_main([str(out), str(true_run), *mix_args, "--json", str(mix_json)]) == 0
    mix = json.loads(mix_json.read_text())
    assert mix["labels"] == records[0]["labels"] and list(mix["alphas"]) == ["0.0", "1.0"]
    with pytest.raises(SystemExit):  # a folder without labels
        mix_main([str(out), str(tmp_path / "kept"), *mix_args])


def test_mixed_labels_weigh_the_true_cost_on_the_same_decisions_only() -> None:
    crops = np.zeros((3, *map_crops.crop_shape()), np.uint8)
    features = np.zeros((3, 14), np.float32)
    decision, family = np.array([0, 0, 1]), np.array(["rooms-32"] * 3)
    soft = Samples(crops, features, np.array([10.0, 20.0, 30.0]), decision, family)
    true = Samples(
        np.zeros((4, *map_crops.crop_shape()), np.uint8), np.zeros((4, 14), np.float32),
        np.array([14.0, 16.0, 38.0, 99.0]), np.array([0, 0, 1, 2]), np.array(["rooms-32"] * 4),
    )  # fmt: skip
    assert mixed_labels(soft, true, 0.25).cost.tolist() == [11.0, 19.0, 32.0]
    moved = Samples(true.crops.copy(), true.features, true.cost, true.decision, true.family)
    moved.crops[1, 0, 0, 0] = 1  # another belief at the same position
    for other, alpha in ((moved, 0.5), (true, 1.5)):
        with pytest.raises(ValueError, match="not the same decisions|alpha must be in"):
            mixed_labels(soft, other, alpha)


def test_an_average_of_one_scorer_is_that_scorer_and_of_two_their_mean() -> None:
    torch.manual_seed(0)
    first, second = new_scorer(14, 8).eval(), new_scorer(14, 8).eval()
    crops, features = torch.rand(5, *map_crops.crop_shape()), torch.rand(2, 3, 14)
    mask = torch.tensor([[True, True, False], [True, True, True]])
    with torch.no_grad():
        one, two = first(crops, features, mask), second(crops, features, mask)
        assert torch.equal(Averaged([first])(crops, features, mask), one)
        assert torch.allclose(Averaged([first, second])(crops, features, mask), (one + two) / 2)


def test_the_fit_losses_have_their_known_values() -> None:
    regret = torch.tensor([[0.0, 0.5, 9.0]])
    mask = torch.tensor([[True, True, False]])
    predicted = torch.tensor([[0.0, 0.0, float("inf")]])  # the scorer cannot tell them apart
    assert batch_loss("regret", predicted, regret, mask).item() == pytest.approx(0.125)
    half = torch.log(torch.tensor(2.0)).item()  # -log(1/2): either candidate is as likely
    assert batch_loss("argmax", predicted, regret, mask).item() == pytest.approx(half)
    assert batch_loss("ranking", predicted, regret, mask).item() == pytest.approx(half)
    sure = torch.tensor([[0.0, 20.0, float("inf")]])  # the cheapest one, surely
    assert batch_loss("argmax", sure, regret, mask).item() == pytest.approx(0.0, abs=1e-6)
    with pytest.raises(ValueError, match="unknown loss 'hinge'"):
        fit(new_scorer(14, 8), None, 1, loss="hinge")  # type: ignore[arg-type]


def test_family_weights_give_every_family_the_same_total() -> None:
    samples = Samples(
        cost=np.ones(7),
        decision=np.array([5, 5, 2, 9, 9, 9, 7]),  # decisions 2, 5, 7, 9 in group's order
        family=np.array(["b", "b", "a", "b", "b", "b", "a"]),
    )
    weights = family_weights(samples)
    np.testing.assert_allclose(weights.numpy(), [0.5, 0.5, 0.5, 0.5])
    samples.family[2] = "b"  # now "a" has one decision (7), "b" three
    np.testing.assert_allclose(family_weights(samples).numpy(), [1 / 3, 1 / 3, 1.0, 1 / 3])
    halfway = family_weights(samples, 0.5).numpy()  # totals: "b" sqrt(3), "a" 1
    np.testing.assert_allclose(halfway, [3**-0.5, 3**-0.5, 1.0, 3**-0.5])
    np.testing.assert_allclose(family_weights(samples, 0.0).numpy(), [1.0, 1.0, 1.0, 1.0])


def test_the_step_size_schedules_have_their_known_values() -> None:
    assert [step_size_factor("constant", s, 10) for s in (0, 5, 10)] == [1.0, 1.0, 1.0]
    cosine = [step_size_factor("cosine", s, 10) for s in (0, 5, 10)]
    assert cosine == pytest.approx([1.0, 0.5, 0.0])
    with pytest.raises(ValueError, match="unknown schedule 'linear'"):
        fit(new_scorer(14, 8), None, 1, schedule="linear")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="regression.fit_schedule must be one of constant, cos"):
        load_experiment("explorer", ['regression.fit_schedule="linear"'])


def test_a_weighted_fit_draws_only_decisions_of_positive_weight(labelled: Samples) -> None:
    decisions = group(labelled, 12)
    seen: list[torch.Tensor] = []

    class Recorder(torch.nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.bias = torch.nn.Parameter(torch.zeros(1))

        def member_regrets(self, crops: torch.Tensor, features: torch.Tensor, mask: torch.Tensor):
            seen.append(features[..., 0].sum(1))
            return self.bias.expand((*mask.shape, 1))

    weights = torch.zeros(len(decisions), dtype=torch.float64)
    weights[3] = 1.0
    fit(Recorder(), decisions, 1, batch_size=8, weights=weights)
    drawn = torch.cat(seen)
    assert len(drawn) == len(decisions)  # an epoch draws as many decisions as there are
    assert torch.allclose(drawn, drawn[0].expand_as(drawn))  # all of them decision 3
    with pytest.raises(ValueError, match="one entry per decision"):
        fit(Recorder(), decisions, 1, weights=weights[:-1])


def test_the_benchmark_plays_a_saved_scorer_with_its_saved_rule_weight(tmp_path: Path) -> None:
    model = new_scorer(len(feature_names(scorer_config(make_config("thesis-20x20")))))
    save_map_explorer(model, tmp_path / "scorer", {"rule_weight": 0.5})
    policy = map_model(tmp_path / "scorer", "scorer").make()
    assert isinstance(policy, MapExplorer) and policy.rule_weight == 0.5
    assert MapExplorer.load(tmp_path / "scorer").rule_weight == 0.5
    with pytest.raises(ValueError, match="is a map-aware scorer .* not an SB3 model"):
        resolve_model_path(tmp_path / "scorer")


def test_the_explorer_acts_on_valid_slots_only() -> None:
    import frontier_marl
    from frontier_marl.policies.linear_scorer import explorer_slots

    fam = map_families.family("rooms-32")
    (world,) = map_families.variant_configs(fam, None, 1)
    env = frontier_marl.parallel_env(config=scorer_config(world))
    torch.manual_seed(0)
    explorer = MapExplorer(new_scorer(14, 8))
    explorer.attach(env)
    observations, infos = env.reset(seed=fam.validation[0])
    choices = 0
    for _ in range(150):
        _, mask = explorer_slots(observations["robot_0"])
        action = explorer.act(observations["robot_0"], infos["robot_0"])
        assert mask[action] == 1
        choices += int(mask.sum() > 1)
        observations, _, _, _, infos = env.step({"robot_0": action})
    assert choices > 5  # it chose among several slots, not only forced steps


def test_in_a_team_each_robot_chooses_from_its_own_slots_and_crops() -> None:
    world = make_config("rooms-32", n_agents=2, map_mode="dynamic")
    env = frontier_marl.parallel_env(config=scorer_config(world))
    torch.manual_seed(0)
    explorer = MapExplorer(new_scorer(14, 8))
    explorer.attach(env)
    observations, infos = env.reset(seed=5)
    own_crops_differ = 0
    for _ in range(40):
        actions = explorer.act_team(observations, infos)
        for robot, agent in enumerate(env.agents):
            assert infos[agent]["action_mask"][actions[agent]] == 1
            valid = np.flatnonzero(infos[agent]["action_mask"])
            own, other = (map_crops.slot_crops(env, valid, r) for r in (robot, 1 - robot))
            own_crops_differ += int(not np.array_equal(own, other))
        observations, _, terminated, truncated, infos = env.step(actions)
        if any(terminated.values()) or any(truncated.values()):
            break
    assert own_crops_differ > 10  # the robots' crops (their distance fields) are their own


def test_evaluate_plays_the_shipped_explorer_beside_a_heuristic(tmp_path: Path, capsys) -> None:
    """`frontier-marl evaluate explorer`: the thesis protocol on the world of --preset, in
    frontier-rule's observation, the same episodes for the heuristic; bad input named."""
    out = tmp_path / "eval.json"
    argv = ["evaluate", "explorer", "--episodes", "2", "--preset", "rooms-32", "--jobs", "1"]
    argv += ["--set", "no_progress_limit=1024"]  # the preset's 20 cuts long trips short
    assert main([*argv, "--json", str(out), "--no-progress"]) == 0
    result = json.loads(out.read_text())
    assert result["kind"] == "map-scorer" and result["labels"] > 0
    assert [row["policy"] for row in result["rows"]] == ["model", "greedy-distance"]
    assert result["env_config"]["height"] == 32 and result["env_config"]["n_slots"] == 12
    assert result["env_config"]["map_mode"] == "dynamic"  # as trained
    assert result["model"]["terminations"] == 2
    assert "map scorer, " in capsys.readouterr().out
    assert main(["evaluate", "explorer", "--episodes", "1", "--set", "n_slots=8"]) == 2
    assert "so n_slots cannot be set" in capsys.readouterr().err
    assert main(["evaluate", "explorer-map", "--episodes", "1"]) == 2
    assert "'explorer-map' is now called 'explorer'" in capsys.readouterr().err


def test_labels_over_map_completions_are_other_costs_of_the_same_decisions() -> None:
    fam = map_families.family("random-20")
    episode = ("random-20", int(fam.train[0]), None)
    true_map = cost_regression._label((*episode, cost_regression.RegressionSettings(), 0))
    three = cost_regression.RegressionSettings(completions=3)
    completed = cost_regression._label((*episode, three, 0))
    np.testing.assert_array_equal(completed.decision, true_map.decision)  # same behaviour
    np.testing.assert_array_equal(completed.crops, true_map.crops)
    assert not np.array_equal(completed.cost, true_map.cost)
    again = cost_regression._label((*episode, three, 0))
    assert np.array_equal(again.cost, completed.cost)  # seeded
    assert (completed.cost > 0).all()


def test_a_bad_regression_section_is_named() -> None:
    with pytest.raises(ValueError, match=r"regression.rounds must be an integer >= 1"):
        load_experiment("explorer", ["regression.rounds=0"])
    with pytest.raises(ValueError, match=r"unknown \[regression\] key"):
        load_experiment("explorer", ["regression.epochs=3"])
    with pytest.raises(ValueError, match="regression.finisher must be one of nearest-path, "):
        load_experiment("explorer", ['regression.finisher="greedy-gain"'])
    with pytest.raises(ValueError, match="regression.completions must be an integer >= 0"):
        load_experiment("explorer", ["regression.completions=-1"])
    with pytest.raises(ValueError, match="regression.completions needs regression.finisher"):
        load_experiment(
            "explorer", ["regression.completions=4", 'regression.finisher="frontier-rule"']
        )
    with pytest.raises(ValueError, match="needs train.families and one robot"):
        load_experiment("explorer", ["train.families=[]"])
    with pytest.raises(ValueError, match=r"regression.label_every must be an integer >= 1"):
        load_experiment("explorer", ["regression.label_every=0"])
    with pytest.raises(ValueError, match=r"regression.scorer_members must be an integer >= 1"):
        load_experiment("explorer", ["regression.scorer_members=0"])
    with pytest.raises(ValueError, match="regression.balance_families must be true, false or a"):
        load_experiment("explorer", ["regression.balance_families=1.5"])
    with pytest.raises(ValueError, match="regression.completions needs regression.finisher"):
        load_experiment(
            "explorer",
            [
                "regression.per_family={rooms-32={completions=4}}",
                'regression.finisher="frontier-rule"',
            ],
        )


def test_a_family_may_label_its_own_episodes_and_decisions() -> None:
    own = {"floorplan-96": {"label_episodes": 3, "label_every": 8}}
    reg = cost_regression.RegressionSettings(label_episodes=5, label_every=2, per_family=own)
    assert (reg.label_episodes_of("floorplan-96"), reg.label_every_of("floorplan-96")) == (3, 8)
    assert (reg.label_episodes_of("rooms-32"), reg.label_every_of("rooms-32")) == (5, 2)
    mixed = {"random-20": {"completions": 16}, "rooms-32": {"completions": 0}}
    reg = cost_regression.RegressionSettings(completions=4, per_family=mixed)
    assert [reg.completions_of(f) for f in ("random-20", "rooms-32", "rooms-64")] == [16, 0, 4]
    shipped = cost_regression.RegressionSettings(**load_experiment("explorer").regression)
    assert shipped.label_every_of("floorplan-96") > 1 == shipped.label_every_of("random-20")


def test_a_bad_per_family_entry_is_named() -> None:
    with pytest.raises(ValueError, match=r"regression.per_family: unknown family 'floorplan96'"):
        load_experiment("explorer", ["regression.per_family={floorplan96={label_every=2}}"])
    with pytest.raises(ValueError, match=r"per_family.rooms-32 has unknown keys \['epochs'\]"):
        load_experiment("explorer", ["regression.per_family={rooms-32={epochs=2}}"])
    with pytest.raises(ValueError, match=r"per_family.rooms-32.label_every must be an integer"):
        load_experiment("explorer", ["regression.per_family={rooms-32={label_every=0}}"])
    with pytest.raises(
        ValueError, match=r"per_family.rooms-32.completions must be an integer >= 0"
    ):
        load_experiment("explorer", ["regression.per_family={rooms-32={completions=-1}}"])
    with pytest.raises(ValueError, match=r"regression.per_family.rooms-32 must be a table"):
        load_experiment("explorer", ["regression.per_family={rooms-32=4}"])


def test_the_shipped_explorer_is_the_committed_configs_scorer() -> None:
    model, meta = load_scorer("explorer")
    committed = load_experiment("explorer").to_dict()
    assert meta["format"] == "map-scorer" and meta["experiment"]["name"] == "explorer"
    assert meta["rule_weight"] == 1.0 and 1.0 in committed["regression"]["rule_weights"]
    assert {k: meta["experiment"][k] for k in ("train", "regression")} == {
        k: committed[k] for k in ("train", "regression")
    }
    assert model.feature_mean.numel() == len(feature_names(scorer_config(make_config(None))))


def test_the_team_claims_study_discounts_targets_near_claimed_ones(tmp_path: Path) -> None:
    from frontier_marl.experiments.explorer_studies import team_claims

    shipped = MapExplorer.load(map_scorer_folder("explorer"))
    explorer = team_claims.make_claiming((1.0, 4.0, None))
    assert explorer.name == "claims-d1-r4" and explorer.rule_weight == shipped.rule_weight
    weighted = team_claims.make_claiming((1.0, 4.0, 2.0))
    assert weighted.rule_weight == 2.0 and weighted.name == "claims-d1-r4-w2"
    targets = np.array([[0, 0], [0, 10], [4, 4]])
    crowding = explorer._crowding(targets, [np.array([0, 2]), np.array([0, 0])])
    assert crowding.tolist() == pytest.approx([0.5 + 1.0, 0.0, 0.0])
    assert team_claims.parse_variant("0.3:5:2") == (0.3, 5.0, 2.0)
    for bad in ("1", "a:5", "1:0", "-1:5", "nan:5", "1:inf"):
        with pytest.raises(ValueError, match="variant"):
            team_claims.parse_variant(bad)
    out = tmp_path / "claims.json"
    argv = ["--families", "random-20", "--agents", "2", "--variants", "1:5", "--episodes", "1"]
    assert team_claims.main([*argv, "--jobs", "1", "--no-progress", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [row["policy"] for row in rows] == [*team_claims.BASELINES, "claims-d1-r5"]
    assert all(row["seeds"] == [800_000] and row["success"] == 1 for row in rows)
    for bad in (["--agents", "1"], ["--variants", "1:5,1:5"]):
        with pytest.raises(SystemExit):
            team_claims.main(bad)


def test_claiming_robots_leave_a_target_a_teammate_took() -> None:
    from types import SimpleNamespace

    from frontier_marl.experiments.explorer_studies import team_claims

    targets = np.array([[0, 0], [0, 9], [9, 9]])
    tables = [SimpleNamespace(target=targets, path_length=np.array([1, 2, 3]))] * 3
    env = SimpleNamespace(
        possible_agents=["a0", "a1", "a2"], mdp=SimpleNamespace(slot_tables=lambda: tables)
    )
    scores = {  # robots 0 and 1 both rate slot 0 best; robot 2 has one valid slot, slot 2
        0: (np.array([0, 1, 2]), np.array([0.0, 0.5, 0.9])),
        1: (np.array([0, 1, 2]), np.array([0.0, 0.4, 0.9])),
        2: (np.array([2]), np.zeros(1)),
    }
    observations = {agent: None for agent in env.possible_agents}
    chosen = {}
    for discount in (0.0, 10.0):
        explorer = team_claims.make_claiming((discount, 3.0, None))
        explorer._env = env
        explorer.slot_scores = lambda obs, robot: scores[robot]
        chosen[discount] = explorer.act_team(observations, {})
    assert chosen[0.0] == {"a0": 0, "a1": 0, "a2": 2}  # no discount: both crowd slot 0
    assert chosen[10.0] == {"a0": 0, "a1": 1, "a2": 2}  # robot 0 first (lower index on a tie)
