"""The benchmark's policies (:class:`Contender`): heuristics, the oracles and models.

A contender built here is picklable: its factories are module-level functions, partials or
small dataclasses that name what they load (a model's path, a scorer's folder), so an episode
can be played in a worker process or on a Ray node (:mod:`frontier_marl.utils.parallel`); each
process loads a model once (:mod:`frontier_marl.evaluation.model_refs`). A contender built from
in-memory objects (a lambda over a live model) runs in this process only (``jobs=1``).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig, config_to_dict, make_config
from frontier_marl.evaluation.benchmark.families import OBSERVATION_KEYS, world_settings
from frontier_marl.evaluation.model_refs import ScorerMaker, cached_model, cached_scorer, source_of
from frontier_marl.policies.base import ModelPolicy
from frontier_marl.policies.lookahead import LookaheadOracle
from frontier_marl.policies.models import (
    PRETRAINED,
    LoadedModel,
    check_model_env,
    map_scorer_folder,
    renamed_hint,
)
from frontier_marl.policies.registry import POLICIES, env_settings, make_policy
from frontier_marl.policies.team_lookahead import TeamLookaheadOracle

ORACLE = "lookahead-oracle"
TEAM_ORACLE = "team-lookahead-oracle"


@dataclass
class Contender:
    """A policy of the benchmark: a heuristic (by registry name) or a learned model.

    ``make`` returns a fresh :class:`~frontier_marl.evaluation.Policy`; ``config`` turns a
    family's world config into the config this policy runs with (the same for a heuristic;
    the model's observation settings on the same world for a model).
    """

    name: str
    heuristic: bool
    make: Callable[[], Any]
    config: Callable[[EnvConfig], EnvConfig]


def default_commit(agents: int) -> str:
    """The heuristics' commit rule in the benchmark (see the module docstring)."""
    return "until-progress" if agents == 1 else "none"


def loaded_model(source: str) -> LoadedModel:
    """The SB3 model ``source`` names (loaded once per process); ValueError if it cannot be
    loaded or has no metadata."""
    try:
        loaded = cached_model(source)
    except Exception as exc:  # e.g. a file that is not an SB3 zip
        raise ValueError(f"cannot load model {source}: {exc}") from exc
    if loaded.metadata is None:
        raise ValueError(f"model {source}: no metadata saved beside it (its observation settings)")
    return loaded


def own_world(own: Mapping[str, Any], world: EnvConfig) -> EnvConfig:
    """``world`` with a heuristic's own env settings ``own`` on top (none: ``world``)."""
    return make_config(None, **{**world_settings(world), **own}) if own else world


def same_world(world: EnvConfig) -> EnvConfig:
    return world


@dataclass(frozen=True)
class ModelMaker:
    """``make`` of a saved SB3 model: a :class:`ModelPolicy` labelled ``label``."""

    source: str
    label: str

    def __call__(self) -> ModelPolicy:
        return ModelPolicy(loaded_model(self.source).model, name=self.label)


@dataclass(frozen=True)
class ModelWorld:
    """``config`` of a saved SB3 model: its observation settings on the family's world."""

    source: str

    def __call__(self, world: EnvConfig) -> EnvConfig:
        loaded = loaded_model(self.source)
        saved = config_to_dict(loaded.env_config())
        own = {k: saved[k] for k in OBSERVATION_KEYS}
        cfg = make_config(None, **{**world_settings(world), **own})
        check_model_env(loaded, cfg)
        return cfg


def heuristic(name: str, commit: str = "until-progress") -> Contender:
    """A heuristic of the registry, with ``commit`` where it takes one; one that reads an
    observation layout of its own (``frontier-rule``) runs with it on the family's world."""
    accepted = inspect.signature(POLICIES[name]).parameters
    options = {"commit": commit} if "commit" in accepted else {}
    make = partial(make_policy, name, 0, **options)
    return Contender(name, True, make, partial(own_world, env_settings(name)))


def model(name: str) -> Contender:
    """A saved or shipped SB3 model (``thesis-config01``, a run folder, a model.zip)."""
    source = source_of(name)
    loaded_model(source)  # fails here, not in an episode
    label = Path(name).stem if name.endswith(".zip") else Path(name).name
    return Contender(label, False, ModelMaker(source, label), ModelWorld(source))


def map_model(folder: Path, label: str) -> Contender:
    """A saved map-aware scorer (:mod:`frontier_marl.policies.map_explorer`): it chooses among
    frontier-rule's slots, in frontier-rule's env on each world (a team's scorer: in the env
    settings saved with it). Needs torch."""
    source = str(Path(folder).resolve())
    _, metadata = cached_scorer(source)
    if metadata["scorer"].get("team", False):
        config = partial(own_world, metadata["env_settings"])
    else:
        config = heuristic("frontier-rule").config
    return Contender(label, False, ScorerMaker(source, label), config)


def oracle() -> Contender:
    """``lookahead-oracle`` (:mod:`frontier_marl.policies.lookahead`): it reads the true map,
    so it is reported beside the others but never counts as the best heuristic."""
    return Contender(LookaheadOracle.name, False, LookaheadOracle, same_world)


def team_oracle() -> Contender:
    """``team-lookahead-oracle`` (:mod:`frontier_marl.policies.team_lookahead`): the lookahead
    for every robot of a team; like ``lookahead-oracle`` it reads the true map and never counts
    as the best heuristic."""
    return Contender(TeamLookaheadOracle.name, False, TeamLookaheadOracle, same_world)


def contenders(names: Sequence[str], commit: str = "until-progress") -> list[Contender]:
    """Heuristics by name, the two oracles and models by name or path; ValueError for anything
    else."""
    out = []
    for name in names:
        if name in POLICIES:
            out.append(heuristic(name, commit))
        elif name == ORACLE:
            out.append(oracle())
        elif name == TEAM_ORACLE:
            out.append(team_oracle())
        elif (folder := map_scorer_folder(name)) is not None:
            out.append(map_model(folder, Path(name).name if Path(name).exists() else name))
        elif name in PRETRAINED or Path(name).exists():
            out.append(model(name))
        else:
            raise ValueError(
                f"unknown policy {name!r}: not a heuristic ({', '.join(POLICIES)}), {ORACLE}, "
                f"{TEAM_ORACLE}, "
                f"a shipped model ({', '.join(PRETRAINED)}), nor a model file or run folder"
                + renamed_hint(name)
            )
    labels = [contender.name for contender in out]
    repeated = sorted({label for label in labels if labels.count(label) > 1})
    if repeated:
        raise ValueError(
            f"two policies share the label {', '.join(map(repr, repeated))} (a model is "
            "labelled by its folder): copy one to a folder of another name"
        )
    return out
