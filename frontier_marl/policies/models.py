"""Trained models shipped with the package, usable by name wherever a model path is accepted::

    frontier-marl evaluate thesis-config01

Each model lives in ``frontier_marl/assets/models/<name>/`` as ``model.zip`` (SB3 DQN) with
its ``model.json`` metadata (env config, observation layout, training run), or, for the
map-aware ``explorer``, as ``model.pt`` (torch weights, :mod:`frontier_marl.policies.
map_explorer`) with its ``model.json``. How each was trained is in docs/results.md
(``thesis-config01``) and docs/beyond-the-thesis.md (``explorer``, ``team-explorer``). The
research models of the explorer studies (``explorer-dqn``, ``explorer-ppo``) are not in the
package: they lie in the repository's ``training/models/`` and load by path.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from importlib import import_module, resources
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig
from frontier_marl.envs.layout import ObservationLayout
from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.policies.metadata import (
    check_compatible,
    describe_space,
    env_config_from_metadata,
    load_metadata,
)
from frontier_marl.policies.model_files import MODEL_FILE, newest_good_checkpoint

#: name -> one-line description
PRETRAINED: dict[str, str] = {
    "explorer": "the learned frontier selector (docs/experiments/2026-12-04-map-aware-"
    "explorer.md): a small CNN over the belief map around each of frontier-rule's 12 slots, "
    "fitted to each candidate's mean cost-to-go over 16 completions of the belief on six "
    "families by `frontier-marl train explorer` (seed 0, the same weights every run; 104 "
    "minutes here beside another job); it overrules frontier-rule where it predicts a "
    "clear gain (the rule's margin weighed 1); torch only",
    "team-explorer": "the learned team selector (docs/beyond-the-thesis.md): a slot scorer "
    "on frontier-rule's slot features with three teammate features per slot, one "
    "parameter-shared model for teams of 2 to 8, trained on random-30 and rooms-64 by "
    "`frontier-marl train team-explorer` (seed 0); the best-validated policy (step 1,600,032)",
    "thesis-config01": "configuration 1 (absolute centroids + agent position, unsorted, "
    "Reward 2, normalized): the best-validated policy of seed 2 (step 340,000) of a default "
    "frontier-marl reproduce run, the seed whose protocol score is the median of the three",
}


#: Shipped models and configs renamed: old name -> new name (named in the error for the old).
RENAMED: dict[str, str] = {"explorer-map": "explorer"}


def pretrained_names() -> list[str]:
    return list(PRETRAINED)


def renamed_hint(name: str) -> str:
    """`` (NAME is now called NEW)`` for a renamed shipped model, else the empty string."""
    new = RENAMED.get(str(name))
    return f" ({name!r} is now called {new!r})" if new else ""


def pretrained_model_dir(name: str) -> Path:
    """The folder of shipped model ``name``; ``ValueError`` if unknown or missing."""
    if name not in PRETRAINED:
        raise ValueError(
            f"pretrained model must be one of {pretrained_names()}, got {name!r}"
            + renamed_hint(name)
        )
    folder = resources.files("frontier_marl").joinpath("assets", "models", name)
    files = ("model.zip", MAP_SCORER_FILE)
    if not isinstance(folder, Path) or not any((folder / f).is_file() for f in files):
        raise ValueError(f"pretrained model {name!r} is missing from the installed package")
    return folder


#: A map-aware scorer's folder: ``model.pt`` (torch weights) and ``model.json`` with this
#: ``format`` (:mod:`frontier_marl.policies.map_explorer`).
MAP_SCORER_FORMAT = "map-scorer"
MAP_SCORER_FILE = "model.pt"


def map_scorer_folder(name: str | Path) -> Path | None:
    """The folder of a saved map-aware scorer named by ``name`` (a shipped model's name, its
    folder, or its ``model.pt``), or None if ``name`` is no such model."""
    folder = pretrained_model_dir(str(name)) if str(name) in PRETRAINED else Path(name)
    if folder.is_file() and folder.name == MAP_SCORER_FILE:
        folder = folder.parent
    metadata = folder / "model.json"
    if not (folder / MAP_SCORER_FILE).is_file() or not metadata.is_file():
        return None
    try:
        return (
            folder if json.loads(metadata.read_text()).get("format") == MAP_SCORER_FORMAT else None
        )
    except ValueError:
        return None


#: The algorithm recorded in a model's metadata -> the class that loads it (module, name).
LOADERS: dict[str, tuple[str, str]] = {
    "DQN": ("stable_baselines3", "DQN"),
    "PPO": ("stable_baselines3", "PPO"),
    "MaskablePPO": ("sb3_contrib", "MaskablePPO"),
}

#: Where models saved before the package's layout of 0.2 find their policy classes: an SB3 zip
#: names its policy class by module, and these modules moved.
LEGACY_MODULES: dict[str, str] = {
    "frontier_marl.training.slot_policy": "frontier_marl.policies.networks.slot_dqn",
    "frontier_marl.training.slot_actor_critic": "frontier_marl.policies.networks.slot_actor_critic",
}


class MissingExtraError(ValueError):
    """Loading a model needs an optional extra that is not installed."""


#: The extra that provides each loader's module.
EXTRAS: dict[str, str] = {"stable_baselines3": "train", "sb3_contrib": "train"}


@dataclass
class LoadedModel:
    """An SB3 model with the metadata saved beside it (``None`` for a bare SB3 file)."""

    model: Any
    path: Path
    metadata: dict[str, Any] | None

    def env_config(self, **overrides: Any) -> EnvConfig | None:
        """The training env config with overrides, or ``None`` without metadata."""
        if self.metadata is None:
            return None
        return env_config_from_metadata(self.metadata, **overrides)


def resolve_model_path(path: str | Path) -> Path:
    """``model.zip``, a run folder (its final ``model.zip``), a checkpoint folder, or the name
    of a model shipped with the package (:data:`PRETRAINED`)."""
    if str(path) in PRETRAINED and not Path(path).exists():
        path = pretrained_model_dir(str(path))
    path = Path(path)
    if path.is_dir():
        if (path / MODEL_FILE).is_file():
            return path / MODEL_FILE
        checkpoint = newest_good_checkpoint(path)
        if checkpoint is not None:
            return checkpoint.model
        if map_scorer_folder(path) is not None:
            raise ValueError(
                f"{str(path)!r} is a map-aware scorer ({MAP_SCORER_FILE}), not an SB3 model: "
                "play it with `frontier-marl evaluate`, `benchmark --policies` or `gif`"
            )
        raise ValueError(f"no {MODEL_FILE} in folder {str(path)!r}")
    if not path.is_file() and path.with_suffix(".zip").is_file():
        path = path.with_suffix(".zip")
    if not path.is_file():
        raise ValueError(f"model file {str(path)!r} not found" + renamed_hint(str(path)))
    return path


def loader(label: str | None) -> Any:
    """The SB3 class that loads a model whose metadata records ``label`` as its algorithm
    (``None``, a model without metadata: DQN, as every model was before PPO)."""
    if label is not None and label not in LOADERS:
        raise ValueError(
            f"the model's metadata names algorithm {label!r}; known: {sorted(LOADERS)}"
        )
    module, name = LOADERS[label or "DQN"]
    try:
        return getattr(import_module(module), name)
    except ModuleNotFoundError as exc:
        extra = EXTRAS.get(module, "train")
        raise MissingExtraError(
            f"a {label or 'DQN'} model needs the {extra!r} extra ({exc.name} is not installed): "
            f"pip install 'frontier-marl[{extra}]'"
        ) from exc


@contextmanager
def legacy_module_names() -> Iterator[None]:
    """Let the policy classes of older model files resolve under their old module names."""
    added = [old for old in LEGACY_MODULES if old not in sys.modules]
    for old in added:
        sys.modules[old] = import_module(LEGACY_MODULES[old])
    try:
        yield
    finally:
        for old in added:
            sys.modules.pop(old, None)


def load_model(path: str | Path, device: str = "cpu") -> LoadedModel:
    """Load an SB3 model (DQN, PPO or MaskablePPO, by its metadata) and its metadata;
    :class:`MissingExtraError` naming the extra to install if SB3 is missing."""
    model_path = resolve_model_path(path)
    metadata = load_metadata(model_path)
    try:
        algorithm = loader(None if metadata is None else metadata.get("algorithm"))
    except MissingExtraError as exc:
        raise MissingExtraError(f"model {str(path)!r}: {exc}") from None
    try:
        with legacy_module_names():
            model = algorithm.load(model_path, device=device)
    except Exception as error:  # SB3 raises whatever its zip, pickle or torch readers raise
        raise ValueError(
            f"cannot load model {model_path}: the file is damaged or not a saved "
            f"{algorithm.__name__} model ({type(error).__name__}: {error})"
        ) from error
    return LoadedModel(model=model, path=model_path, metadata=metadata)


def check_model_env(loaded: LoadedModel, cfg: EnvConfig) -> None:
    """Raise ``ModelEnvMismatchError`` if the model cannot act in an env built from ``cfg``
    (in the flat layout the project's models are trained on, or a model trained on the classic
    layout in that one)."""
    env = FrontierParallelEnv(config=cfg, obs_layout="flat")
    agent = env.possible_agents[0]
    space = env.observation_space(agent)
    classic = ObservationLayout(space, "classic").space
    if describe_space(loaded.model.observation_space) == describe_space(classic):
        space = classic
    check_compatible(
        cfg,
        space,
        env.action_space(agent),
        loaded.model.observation_space,
        loaded.model.action_space,
        loaded.metadata,
    )
