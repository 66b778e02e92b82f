"""team-explorer's Q-values in the team protocol, alone or with the team map scorer as a
correction (experiments/explorer_studies/team_anchor.py), and labels of its states."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import torch  # noqa: E402

from frontier_marl.envs.parallel import FrontierParallelEnv  # noqa: E402
from frontier_marl.evaluation.benchmark.contenders import (  # noqa: E402
    Contender,
    ModelWorld,
    loaded_model,
    own_world,
)
from frontier_marl.evaluation.benchmark.families import family, variant_configs  # noqa: E402
from frontier_marl.evaluation.benchmark.run import run_family  # noqa: E402
from frontier_marl.evaluation.model_refs import ScorerMaker  # noqa: E402
from frontier_marl.experiments.explorer_studies.team_anchor import (  # noqa: E402
    AnchoredTeamExplorer,
    anchored,
    main,
)
from frontier_marl.policies.linear_scorer import explorer_slots  # noqa: E402
from frontier_marl.policies.map_explorer import (  # noqa: E402
    TEAM_MAP_EXPLORER_SETTINGS,
    new_scorer,
    save_map_explorer,
)

FAMILY = "random-20"


def _team_scorer(folder: Path) -> Path:
    torch.manual_seed(0)
    save_map_explorer(new_scorer(17, 8, team=True), folder, {})
    return folder


def _episodes(contender: Contender, agents: int = 2, episodes: int = 2) -> list[tuple]:
    fam = family(FAMILY)
    result = run_family(
        fam, contender, variant_configs(fam, None, agents), episodes, split="validation"
    )
    return [(e.cells_to_coverage, e.makespan_to_coverage) for e in result.episodes]


def test_the_q_values_are_team_explorers_on_its_own_observation() -> None:
    """The team scorer's env holds team-explorer's slot features among its own: picked by
    name, they give the Q-values team-explorer computes in its own env on the same world."""
    (world,) = variant_configs(family(FAMILY), None, 3)
    ours = FrontierParallelEnv(config=own_world(TEAM_MAP_EXPLORER_SETTINGS, world))
    theirs = FrontierParallelEnv(config=ModelWorld("team-explorer")(world))
    policy = AnchoredTeamExplorer()
    policy.attach(ours)
    seed = int(family(FAMILY).validation[0])
    observations, _ = ours.reset(seed=seed)
    own_observations, _ = theirs.reset(seed=seed)
    q_network = loaded_model("team-explorer").model.q_net
    for agent, obs in observations.items():
        slots, mask = explorer_slots(own_observations[agent])
        own = {"slots": torch.as_tensor(slots)[None], "action_mask": torch.as_tensor(mask)[None]}
        with torch.no_grad():
            expected = q_network(own)[0].numpy()
        live = obs["action_mask"] > 0
        assert live.sum() >= 2
        np.testing.assert_allclose(policy.q_values(obs)[live], expected[live], rtol=1e-6)


def test_a_large_weight_plays_the_q_alone_and_weight_zero_the_scorer_alone(tmp_path: Path):
    folder = str(_team_scorer(tmp_path / "team"))
    q_alone = _episodes(anchored(None, 0.0))
    assert _episodes(anchored(folder, 1e9)) == q_alone
    scorer = Contender("scorer", False, ScorerMaker(folder, "scorer"), anchored(None, 0).config)
    assert _episodes(anchored(folder, 0.0)) == _episodes(scorer)
    with pytest.raises(ValueError, match="weight must be a number >= 0"):
        AnchoredTeamExplorer(folder, -1.0)


def test_the_study_plays_the_weights_beside_the_baselines(tmp_path: Path, capsys) -> None:
    folder = _team_scorer(tmp_path / "team")
    report = tmp_path / "rows.json"
    argv = ["--families", FAMILY, "--agents", "2", "--episodes", "1", "--jobs", "1"]
    scored = ["--scorer", str(folder), "--weights", "0,1"]
    assert main([*argv, *scored, "--json", str(report), "--no-progress"]) == 0
    rows = json.loads(report.read_text())["rows"]
    assert [row["policy"] for row in rows] == [
        "utility-discount",
        "coordinated-assignment",
        "team-explorer",
        "team-explorer-q",
        "anchored-w0",
        "anchored-w1",
    ]
    assert "anchored-w1" in capsys.readouterr().out
    single = tmp_path / "single"
    save_map_explorer(new_scorer(14, 8), single, {})
    bad_options = (
        ["--agents", "1"],
        ["--scorer", str(single)],
        ["--scorer", str(folder), "--weights", "1,1"],
        ["--scorer", str(folder), "--weights", "-1"],
        ["--scorer", str(folder), "--weights", "x"],
    )
    for bad in bad_options:
        with pytest.raises(SystemExit):
            main([*argv, *bad])


def test_labels_of_team_explorers_states_every_other_decision(tmp_path: Path) -> None:
    from frontier_marl.experiments.explorer_studies.team_map_scorer import main as study

    argv = ["--families", FAMILY, "--agents", "2", "--episodes", "1", "--epochs", "1"]
    folder = tmp_path / "labelled"
    options = ["--learner", "team-explorer", "--every", "2", "--workers", "1", "--no-progress"]
    assert study([*argv, *options, "--save", str(folder)]) == 0
    record = json.loads((folder / "model.json").read_text())
    assert record["study"]["learner"] == "team-explorer" and record["study"]["every"] == 2
    assert record["decisions"] > 0
    with pytest.raises(SystemExit):
        study([*argv, "--every", "0", "--save", str(folder)])
