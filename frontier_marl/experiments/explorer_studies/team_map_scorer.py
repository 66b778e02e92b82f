"""A map-aware team scorer fitted to each candidate's makespan to go on the true map.

Team episodes of the training seeds are labelled (:func:`~frontier_marl.training.
team_cost_to_go.label_team_episode`: the team oracle's choice or the claiming base's, each
candidate's makespan to go on the true map or, with ``--completions K``, its mean over K
completions of the belief), in ``--workers`` processes; one scorer of the team's crops
(:data:`~frontier_marl.policies.map_crops.TEAM_CHANNELS`) is fitted to their relative regret
(:func:`~frontier_marl.training.cost_regression.fitted`, the families balanced) and saved as a
folder that ``frontier-marl benchmark --agents K --policies FOLDER`` plays as a
:class:`~frontier_marl.policies.team_map_explorer.TeamMapExplorer`::

    python benchmarks/team_map_scorer.py --families random-30,rooms-64 --agents 4 \\
        --episodes 48 --save runs/team-map

The new labels are kept in ``FOLDER/labels.npz``. ``--labels FILE ...`` adds stored labels to
the fit (``--episodes 0``: fit them alone). A DAgger round labels the learner's own states:
``--learner FOLDER`` (a fitted team scorer) takes the decisions the oracle does not, and
``--round R`` labels the R-th ``--episodes`` of the families' shuffled training seeds.
``--learner team-explorer`` labels the states of the shipped ``team-explorer`` in the team
protocol instead (:mod:`~frontier_marl.experiments.explorer_studies.team_anchor`), and
``--every N`` labels every N-th decision only (for costly labels, ``--completions 16``)::

    python benchmarks/team_map_scorer.py --episodes 48 --round 1 --learner runs/team-map \
        --labels runs/team-map/labels.npz --save runs/team-map-r1
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from frontier_marl.evaluation.benchmark.contenders import own_world
from frontier_marl.evaluation.benchmark.families import check_families, family, variant_configs
from frontier_marl.evaluation.model_refs import ScorerMaker
from frontier_marl.experiments.explorer_studies.team_anchor import ANCHOR, AnchoredTeamExplorer
from frontier_marl.policies.map_explorer import (
    TEAM_MAP_EXPLORER_SETTINGS,
    load_scorer,
    save_map_explorer,
    team_scorer_folder,
)
from frontier_marl.policies.models import map_scorer_folder
from frontier_marl.policies.team_decider import SequentialTeamDecider
from frontier_marl.training.cost_regression import fitted
from frontier_marl.training.cost_to_go import Samples
from frontier_marl.training.regression import LOSSES, chosen_regret, group, predict
from frontier_marl.training.settings import RegressionSettings
from frontier_marl.training.team_cost_to_go import label_team_episode
from frontier_marl.utils.parallel import map_tasks

PATH_COLUMN = 0  # the ``path`` slot feature: the known-free path length to the target

#: family, reset seed, robots, the oracle's share, the learner (a folder, ``team-explorer``
#: or None), completions, every
LabelTask = tuple[str, int, int, float, str | None, int, int]


def label_task(task: LabelTask) -> Samples:
    """The labels of one team episode of a family's world in the team scorer's env."""
    name, seed, agents, share, learner, completions, every = task
    (world,) = variant_configs(family(name), None, agents)
    cfg = own_world(TEAM_MAP_EXPLORER_SETTINGS, world)
    policy: SequentialTeamDecider | None = None
    if learner == ANCHOR:
        policy = AnchoredTeamExplorer()
    elif learner is not None:
        policy = ScorerMaker(learner, "learner")()
    return label_team_episode(cfg, seed, name, share, every, policy, completions)


def label_jobs(
    names: list[str], episodes: int, round_: int, task: tuple[int, float, str | None, int, int],
    seed: int,
) -> list[LabelTask]:  # fmt: skip
    """The ``round_``-th ``episodes`` training seeds per family, shuffled by ``seed``, each
    with ``task``'s robots, oracle share, learner, completions and every."""
    rng = np.random.default_rng(seed)
    window = slice(round_ * episodes, (round_ + 1) * episodes)
    return [
        (name, int(ep), *task)
        for name in names
        for ep in rng.permutation(np.asarray(family(name).train))[window]
    ]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", default="random-30,rooms-64")
    parser.add_argument("--agents", type=int, default=4, help="robots per team (2 or more)")
    parser.add_argument("--episodes", type=int, default=48, help="labelled episodes per family")
    parser.add_argument("--round", type=int, default=0, help="which episodes: the R-th batch")
    parser.add_argument(
        "--learner", default=None, help=f"a team scorer's folder, or {ANCHOR} (its Q-values)"
    )
    parser.add_argument("--oracle-share", type=float, default=0.5)
    parser.add_argument(
        "--completions", type=int, default=0, help="K: mean costs over K completions (0: true map)"
    )
    parser.add_argument("--every", type=int, default=1, help="label every N-th decision")
    parser.add_argument("--workers", type=int, default=2, help="labelling processes")
    parser.add_argument("--epochs", type=int, default=10)
    parser.add_argument("--loss", choices=LOSSES, default="regret", help="the fit's loss")
    parser.add_argument("--width", type=int, default=32)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--labels", type=Path, nargs="+", default=[], help="stored labels too")
    parser.add_argument("--save", type=Path, required=True, help="the scorer's folder")
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    names = args.families.split(",")
    try:
        check_families(names, "--families")
    except ValueError as exc:
        parser.error(str(exc))
    if args.agents < 2:
        parser.error(f"--agents must be 2 or more, got {args.agents}")
    if args.episodes < 0 or (args.episodes == 0 and not args.labels):
        parser.error(f"--episodes must be 1 or more (0 with --labels), got {args.episodes}")
    if args.round < 0 or (args.round + 1) * args.episodes > min(
        len(family(name).train) for name in names
    ):
        parser.error(f"--round {args.round} of {args.episodes} episodes: not enough seeds")
    if args.completions < 0:
        parser.error(f"--completions must be 0 or more, got {args.completions}")
    if not 0.0 <= args.oracle_share <= 1.0:
        parser.error(f"--oracle-share must be in [0, 1], got {args.oracle_share}")
    missing = [str(path) for path in args.labels if not path.is_file()]
    if missing:
        parser.error(f"--labels: no such file {', '.join(missing)}")
    if args.every < 1:
        parser.error(f"--every must be 1 or more, got {args.every}")
    learner = args.learner
    if learner is not None and learner != ANCHOR:
        if team_scorer_folder(learner) is None:
            parser.error(f"--learner {learner}: no saved team scorer there (nor {ANCHOR})")
        learner = str(Path(learner).resolve())
    started = time.perf_counter()
    parts = [Samples.load(path) for path in args.labels]
    if args.episodes:
        task = (args.agents, args.oracle_share, learner, args.completions, args.every)
        jobs = label_jobs(names, args.episodes, args.round, task, args.seed)
        new = Samples.join(
            map_tasks(label_task, jobs, args.workers, progress=not args.no_progress,
                      desc="team labels", unit="episode")
        )  # fmt: skip
        args.save.mkdir(parents=True, exist_ok=True)
        new.save(args.save / "labels.npz")
        parts.append(new)
    samples = Samples.join(parts)
    labelled = time.perf_counter()
    reg = RegressionSettings(fit_epochs=args.epochs, scorer_width=args.width, balance_families=True)
    model = fitted(samples, reg, args.seed, loss=args.loss)
    options = {k: _plain(v) for k, v in vars(args).items()}
    record = {
        "trained_by": "team-cost-regression",
        "study": options,
        "labels": len(samples),
        "decisions": int(len(np.unique(samples.decision))),
        "label_s": round(labelled - started, 1),
        "fit_s": round(time.perf_counter() - labelled, 1),
    }
    save_map_explorer(model, args.save, record)
    print(json.dumps(record))
    return 0


def _plain(value: object) -> object:
    """An option as JSON holds it (paths as strings)."""
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def probe(folder: Path, samples: Samples, decisions: int = 3000) -> list[dict[str, object]]:
    """Per family, over its first ``decisions`` labelled decisions: the mean relative regret
    of the candidate the scorer saved in ``folder`` takes, and of the nearest candidate (the
    least ``path`` feature)."""
    model, _ = load_scorer(folder)
    rows = []
    for name in np.unique(samples.family):
        first = np.unique(samples.decision[samples.family == name])[:decisions]
        keep = (samples.family == name) & np.isin(samples.decision, first)
        part = Samples(*(getattr(samples, f)[keep] for f in Samples.__dataclass_fields__))
        grouped = group(part, int(TEAM_MAP_EXPLORER_SETTINGS["n_slots"]))
        path = grouped.features[..., PATH_COLUMN].masked_fill(~grouped.mask, float("inf"))
        rows.append(
            {
                "family": str(name),
                "decisions": len(grouped),
                "scorer": chosen_regret(predict(model, grouped), grouped),
                "nearest": chosen_regret(path, grouped),
            }
        )
    return rows


def probe_main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="A team scorer's regret on labelled decisions")
    parser.add_argument("folder", type=Path, help="a saved team scorer")
    parser.add_argument("labels", type=Path, help="labels.npz of the study")
    parser.add_argument("--decisions", type=int, default=3000, help="per family")
    args = parser.parse_args(argv)
    if map_scorer_folder(args.folder) is None:
        parser.error(f"{args.folder}: no saved scorer there")
    torch.set_num_threads(1)
    for row in probe(args.folder, Samples.load(args.labels), args.decisions):
        print(json.dumps(row))
    return 0
