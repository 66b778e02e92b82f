"""Can the explorer's observation imitate the lookahead oracle? (docs/beyond-the-thesis.md)

    python benchmarks/imitation_probe.py                     # 4 rounds, ~6 minutes
    python benchmarks/imitation_probe.py --json probe.json --rounds 6

DAgger with :mod:`frontier_marl.training.imitation` on the explorer config's observation and
network (``frontier_marl/assets/configs/explorer-dqn.toml``), training seeds only. Round 0 follows
the oracle; round ``r`` follows it with probability ``0.5 ** r`` and the student otherwise.
Every decision is labelled with the oracle's cost of each valid slot. After each round, the
student is fitted on all rounds so far and scored two ways:

* **decision regret** on the *next* round's decisions (states the fitted student has not been
  trained on): the mean extra cells (oracle cost of the chosen slot minus the cheapest) of the
  student's choice and of nearest-path's (the smallest path feature) on the same decisions;
* **validation T99** against nearest-path, 8 validation episodes per family (seeds 800,000+),
  as ``frontier-marl train`` validates.

The student beats nearest-path only if its regret is the lower one.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch as th

from frontier_marl.config import EnvConfig
from frontier_marl.evaluation.benchmark.families import family
from frontier_marl.policies.networks.slot_dqn import MaskedDQN, SlotDQNPolicy
from frontier_marl.training.batched_vec_env import make_batched_vec_env
from frontier_marl.training.experiment import load_experiment
from frontier_marl.training.family_validation import FamilyValidator
from frontier_marl.training.imitation import Dataset, collect, fit

EPISODES = {"random-20": 12, "random-30": 8, "rooms-32": 12, "rooms-64": 3}  # per round


def regrets(data: Dataset, choose: np.ndarray) -> float:
    """Mean extra oracle cost (cells) of the slots ``choose`` (N,) on ``data``'s decisions."""
    costs = np.stack(data.costs)
    extra = costs - np.nanmin(costs, axis=1, keepdims=True)
    return float(np.mean(extra[np.arange(len(costs)), choose]))


def oracle_choices(data: Dataset) -> np.ndarray:
    """The oracle's slot: the cheapest."""
    return np.nanargmin(np.stack(data.costs), axis=1)


def path_rank(data: Dataset, choose: np.ndarray) -> np.ndarray:
    """How many valid slots have a shorter path than the chosen one (0: the nearest)."""
    slots, masks = np.stack(data.slots), np.stack(data.masks).astype(bool)
    path = np.where(masks, slots[:, :, 0], np.inf)
    return (path < path[np.arange(len(path)), choose][:, None]).sum(axis=1)


def nearest_path_choices(data: Dataset) -> np.ndarray:
    """Nearest-path's slot: the smallest path feature, ties by the centroid distance."""
    slots, masks = np.stack(data.slots), np.stack(data.masks).astype(bool)
    key = np.where(masks, slots[:, :, 0] * 1e6 + slots[:, :, 1], np.inf)
    return key.argmin(axis=1)


def _parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--epochs", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", default=None, help="write the records here")
    return parser.parse_args(argv)


@dataclass
class _Probe:
    """The student, its validator, and the random streams of the rounds."""

    configs: list[EnvConfig]
    names: tuple[str, ...]
    model: Any
    validator: FamilyValidator
    rng: np.random.Generator
    seeds: list[Iterator[Any]]  # per family: its training seeds, shuffled
    generator: th.Generator  # the fits' batches

    @classmethod
    def start(cls, seed: int) -> _Probe:
        th.set_num_threads(1)
        th.manual_seed(seed)
        experiment = load_experiment("explorer-dqn")
        configs = experiment.env_configs()
        names = experiment.train.families
        vec_env = make_batched_vec_env({"config": configs[0]}, 1, seed)
        dqn = {**experiment.dqn, "buffer_size": 1, "learning_starts": 0}
        model = MaskedDQN(SlotDQNPolicy, vec_env, seed=seed, **dqn)
        validator = FamilyValidator(names, 8, configs[0])
        rng = np.random.default_rng(seed)
        seeds = [iter(rng.permutation(family(name).train)[:10_000]) for name in names]
        generator = th.Generator().manual_seed(seed)
        return cls(configs, names, model, validator, rng, seeds, generator)

    def student(self, obs: dict[str, np.ndarray]) -> int:
        return int(self.model.policy.predict(obs, deterministic=True)[0])

    def episodes(self) -> list[list[int]]:
        """The next round's episode seeds, :data:`EPISODES` per family."""
        return [
            [int(next(it)) for _ in range(EPISODES[n])]
            for it, n in zip(self.seeds, self.names, strict=True)
        ]


def _regret_record(model: Any, new: Dataset) -> dict[str, Any]:
    """The student's and nearest-path's regret on a round's decisions, and how the oracle's
    choice relates to nearest-path's."""
    with th.no_grad():
        obs = {
            "slots": th.as_tensor(np.stack(new.slots)),
            "action_mask": th.as_tensor(np.stack(new.masks)),
        }
        chosen = model.policy.q_net(obs).argmax(dim=1).numpy()
    oracle, nearest = oracle_choices(new), nearest_path_choices(new)
    differ = oracle != nearest
    return {
        "regret_student": regrets(new, chosen),
        "regret_nearest_path": regrets(new, nearest_path_choices(new)),
        "regret_decisions": len(new),
        "oracle_differs": float(differ.mean()),
        "oracle_second_nearest": float(np.mean(path_rank(new, oracle)[differ] == 1)),
    }


def _fit_record(
    probe: _Probe, data: Dataset, round_: int, epochs: int, started: float
) -> dict[str, Any]:
    """Fit the student on ``data`` and validate it; the round's record."""
    model = probe.model
    losses = fit(model.policy.q_net, data, epochs, 256, 1e-3, probe.generator)
    model.policy.q_net_target.load_state_dict(model.policy.q_net.state_dict())
    validation = probe.validator(model)
    return {
        "round": round_,
        "decisions": len(data),
        "loss": losses[-1],
        "t99_vs_nearest_path": validation["t99_vs_nearest_path"],
        "by_family": validation["by_family"],
        "seconds": time.perf_counter() - started,
    }


def main(argv: list[str] | None = None) -> int:
    args = _parse_args(argv)
    probe = _Probe.start(args.seed)
    data, records = Dataset(), []
    for round_ in range(args.rounds + 1):
        started = time.perf_counter()
        new = Dataset()
        student = probe.student if round_ else None
        collect(probe.configs, probe.episodes(), new, student, 0.5**round_, probe.rng)
        if round_:  # the student fitted on rounds < round_, scored on this round's decisions
            records[-1].update(_regret_record(probe.model, new))
            print(json.dumps(records[-1]), flush=True)
        if round_ == args.rounds:
            break
        data.extend(new)
        records.append(_fit_record(probe, data, round_, args.epochs, started))
    if args.json:
        with open(args.json, "w") as handle:
            json.dump({"episodes_per_round": EPISODES, "records": records}, handle, indent=1)
    return 0
