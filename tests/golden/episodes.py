"""Golden episodes: digests of whole episodes that a refactor must leave unchanged.

Each case plays whole episodes of one env configuration with one heuristic and hashes every
observation, reward, episode flag and info value, one digest per stream, so a change shows
which stream moved. ``python tests/golden/episodes.py`` rewrites ``episodes.json`` (only do
that for a deliberate change of behaviour, and say so in the commit).

Rewritten for the env's v1 (issue 33): the ``target``, ``position`` and ``end_reason`` infos
became fixed-shape numbers (arrays, a code) and the observations with an action mask took the
classic ``{"observation", "action_mask"}`` layout, so those streams' digests changed and no
other did; translated back to v0's forms, v1 replayed every v0 digest.
"""

from __future__ import annotations

import hashlib
import json
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

GOLDEN_FILE = Path(__file__).with_name("episodes.json")

#: Info keys whose values are hashed as they are.
INFO_KEYS = (
    "explored_fraction",
    "coverage",
    "new_cells",
    "action_mask",
    "path",
    "target",
    "position",
    "travelled",
    "padding",
    "oscillation",
    "step",
    "end_reason",
)

POLICIES = (
    "greedy-distance",
    "greedy-gain",
    "cost-utility",
    "random",
    "first-slot",
    "coordinated-assignment",
    "utility-discount",
)

#: name -> env kwargs of the base settings; every policy plays each of them.
SETTINGS: dict[str, dict[str, Any]] = {
    f"{name}-{mode}-{agents}": {**kwargs, "map_mode": mode, "n_agents": agents}
    for name, kwargs in (
        ("thesis-20x20", {"preset": "thesis-20x20"}),
        ("thesis-30x30", {"preset": "thesis-30x30"}),
        (
            "rooms-32",
            {
                "preset": "thesis-20x20",
                "map_generator": "rooms",
                "height": 32,
                "width": 32,
                "max_steps": 1024,
            },
        ),
    )
    for mode in ("static", "dynamic")
    for agents in (1, 4)
}

#: Observation, reward and movement variants, played by two policies each.
VARIANTS: dict[str, dict[str, Any]] = {
    "relative-sorted-reward1": {
        "centroid": "relative",
        "agent_position": False,
        "sort_by_distance": True,
        "reward": "reward1",
    },
    "gain-only-normalized": {
        "centroid": "none",
        "agent_position": False,
        "info_gain": True,
        "normalize": True,
        "gain": "unknown",
    },
    "distance-mask-square": {"centroid": "distance", "action_mask": True, "sensor": "square"},
    "full-path-8-slots": {"cells_per_step": "full", "n_slots": 8, "info_gain": True},
    "two-cells-4-connected": {"cells_per_step": 2, "connectivity": 4, "max_cluster_cells": 4},
    "team-targets-shared-reward": {
        "n_agents": 3,
        "teammates": "positions+targets",
        "team_weight": 0.5,
        "map_mode": "dynamic",
    },
    "team-positions-30x30": {
        "preset": "thesis-30x30",
        "n_agents": 2,
        "teammates": "positions",
        "normalize": True,
    },
}
VARIANT_POLICIES = ("greedy-distance", "random")

SEEDS = (0, 1)


def cases() -> Iterator[tuple[str, dict[str, Any], str]]:
    """(case name, env kwargs, policy name) of every golden case."""
    for name, kwargs in SETTINGS.items():
        for policy in POLICIES:
            yield f"{name}/{policy}", kwargs, policy
    for name, kwargs in VARIANTS.items():
        for policy in VARIANT_POLICIES:
            yield f"{name}/{policy}", kwargs, policy


def _feed(digest: Any, value: Any) -> None:
    """Hash ``value`` exactly: arrays by dtype, shape and bytes; floats by their bits."""
    if isinstance(value, Mapping):
        for key in sorted(value):
            digest.update(f"<{key}>".encode())
            _feed(digest, value[key])
    elif isinstance(value, np.ndarray):
        digest.update(f"{value.dtype}{value.shape}".encode())
        digest.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, (list, tuple)):
        digest.update(f"[{len(value)}".encode())
        for item in value:
            _feed(digest, item)
        digest.update(b"]")
    elif isinstance(value, (bool, np.bool_)):
        digest.update(b"T" if value else b"F")
    elif isinstance(value, (int, np.integer)):
        digest.update(f"i{int(value)}".encode())
    elif isinstance(value, (float, np.floating)):
        digest.update(np.float64(value).tobytes())
    elif value is None:
        digest.update(b"None")
    elif isinstance(value, str):
        digest.update(f"s{value}".encode())
    else:
        raise TypeError(f"cannot hash {type(value).__name__}")


def slot_rows(info: Mapping[str, Any]) -> list[tuple[Any, ...]]:
    """The live slots of one robot's info: (slot, cluster, centroid, target, size, gain,
    distance) each, with centroid and target as (row, col) tuples. (Before the typed step
    these were the info's ``clusters`` dicts; the rows are the same.)"""
    from frontier_marl.envs.infos import slot_table

    table = slot_table(info)
    return [
        (
            slot,
            int(table.cluster[slot]),
            tuple(float(v) for v in table.centroid[slot]),
            tuple(int(v) for v in table.target[slot]),
            int(table.size[slot]),
            float(table.gain[slot]),
            float(table.distance[slot]),
        )
        for slot in range(table.live)
    ]


def play(kwargs: Mapping[str, Any], policy_name: str, seed: int) -> dict[str, Any]:
    """One episode's digests (one per stream) and a few plain figures for readable diffs."""
    import frontier_marl
    from frontier_marl.policies import make_policy

    env = frontier_marl.parallel_env(info="debug", **kwargs)  # debug: with the path
    policy = make_policy(policy_name, seed)
    policy.attach(env)
    streams = {
        name: hashlib.sha256()
        for name in ("observations", "rewards", "done", "slots", *[f"info.{k}" for k in INFO_KEYS])
    }

    def record(observations: Mapping[str, Any], infos: Mapping[str, Any]) -> None:
        for agent in sorted(observations):
            _feed(streams["observations"], observations[agent])
            info = infos[agent]
            _feed(streams["slots"], slot_rows(info))
            for key in INFO_KEYS:
                _feed(streams[f"info.{key}"], info[key])

    observations, infos = env.reset(seed=seed)
    policy.reset(seed)
    record(observations, infos)
    total = 0.0
    steps = 0
    while env.agents:
        actions = policy.act_team(observations, infos)
        observations, rewards, terminations, truncations, infos = env.step(actions)
        record(observations, infos)
        for agent in sorted(rewards):
            _feed(streams["rewards"], float(rewards[agent]))
            _feed(streams["done"], (bool(terminations[agent]), bool(truncations[agent])))
        total += float(np.mean(list(rewards.values())))
        steps += 1
    env.close()
    last = next(iter(infos.values()))
    return {
        "steps": steps,
        "return": round(total, 9),
        "end_reason": frontier_marl.reason_name(last["end_reason"]),
        "digests": {name: h.hexdigest()[:16] for name, h in streams.items()},
    }


def record_all() -> dict[str, Any]:
    return {
        name: {str(seed): play(kwargs, policy, seed) for seed in SEEDS}
        for name, kwargs, policy in cases()
    }


if __name__ == "__main__":
    golden = record_all()
    GOLDEN_FILE.write_text(json.dumps(golden, indent=1, sort_keys=True) + "\n")
    print(f"wrote {len(golden)} cases to {GOLDEN_FILE}", file=sys.stderr)
