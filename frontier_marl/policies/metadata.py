"""Run metadata saved beside every model: env config, observation layout, spaces, versions.

``model.zip`` is SB3's file; ``model.json`` (same stem) says which env the model belongs to.
:func:`check_compatible` compares a model with an env before any observation reaches the
network, so a mismatch is reported by name instead of as a tensor-shape crash.
"""

from __future__ import annotations

import json
import platform
import time
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces

import frontier_marl
from frontier_marl.config import EnvConfig, config_to_dict, make_config
from frontier_marl.sim.observations import describe_layout

METADATA_FORMAT = 1


class ModelEnvMismatchError(ValueError):
    """A saved model does not fit the env it is asked to act in."""


def metadata_path(model_path: str | Path) -> Path:
    """``run/model.zip`` -> ``run/model.json``."""
    path = Path(model_path)
    return path.with_name(path.name.removesuffix(".zip") + ".json")


def describe_space(space: spaces.Space[Any]) -> dict[str, Any]:
    """A JSON-able summary of a (Box, Dict or Discrete) space: kind, shapes, dtypes."""
    if isinstance(space, spaces.Dict):
        return {"type": "Dict", "spaces": {k: describe_space(v) for k, v in space.spaces.items()}}
    if isinstance(space, spaces.Box):
        return {"type": "Box", "shape": list(space.shape), "dtype": str(space.dtype)}
    if isinstance(space, spaces.Discrete):
        return {"type": "Discrete", "n": int(space.n)}
    return {"type": type(space).__name__, "repr": repr(space)}


def build_metadata(
    cfg: EnvConfig,
    observation_space: spaces.Space[Any],
    action_space: spaces.Space[Any],
    *,
    policy: str,
    num_timesteps: int,
    algorithm: str = "DQN",
    experiment: dict[str, Any] | None = None,
    extra: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Everything needed to rebuild the env a model was trained on and to check a new one."""
    import stable_baselines3
    import supersuit
    import torch

    return {
        "format": METADATA_FORMAT,
        "algorithm": algorithm,
        "policy": policy,
        "num_timesteps": int(num_timesteps),
        "env_config": config_to_dict(cfg),
        "observation_layout": describe_layout(cfg),
        "observation_space": describe_space(observation_space),
        "action_space": describe_space(action_space),
        "experiment": experiment,
        "versions": {
            "frontier_marl": frontier_marl.__version__,
            "stable_baselines3": stable_baselines3.__version__,
            "supersuit": getattr(supersuit, "__version__", "unknown"),
            "torch": torch.__version__,
            "python": platform.python_version(),
        },
        "saved_at": time.strftime("%Y-%m-%dT%H:%M:%S"),
        **(extra or {}),
    }


def save_metadata(meta: dict[str, Any], path: str | Path) -> Path:
    path = Path(path)
    path.write_text(json.dumps(meta, indent=2, sort_keys=False, default=_jsonable) + "\n")
    return path


def load_metadata(model_path: str | Path) -> dict[str, Any] | None:
    """The metadata beside ``model_path``, or ``None`` if the model has none."""
    path = metadata_path(model_path)
    if not path.is_file():
        return None
    try:
        meta = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise ValueError(f"model metadata {path} is not valid JSON ({error})") from None
    if not isinstance(meta, dict):
        raise ValueError(f"model metadata {path} must hold a JSON object")
    return meta


def env_config_from_metadata(meta: dict[str, Any], **overrides: Any) -> EnvConfig:
    """The env config a model was trained on, with flat overrides (e.g. ``map_mode``)."""
    flat = dict(meta["env_config"])
    flat.update(overrides)
    return make_config(None, **flat)


def check_compatible(
    cfg: EnvConfig,
    env_observation_space: spaces.Space[Any],
    env_action_space: spaces.Space[Any],
    model_observation_space: spaces.Space[Any],
    model_action_space: spaces.Space[Any],
    meta: dict[str, Any] | None = None,
) -> None:
    """Raise :class:`ModelEnvMismatchError` naming every difference between model and env.

    Compares the saved observation layout (when there is metadata) field by field, then the
    observation and action spaces themselves. Layout fields that the saved metadata lacks
    (added to the layout after the model was saved) are not compared.
    """
    problems: list[str] = []
    if meta is not None and "observation_layout" in meta:
        saved = meta["observation_layout"]
        current = describe_layout(cfg)
        # a key missing from the saved layout was added to the layout after the model was
        # saved: the model used its default, which the spaces check below still guards
        for key in sorted(set(saved)):
            if saved.get(key) != current.get(key):
                problems.append(
                    f"observation layout '{key}': model has {saved.get(key)!r}, "
                    f"env has {current.get(key)!r}"
                )
    problems += space_differences(
        "observation space", model_observation_space, env_observation_space
    )
    problems += space_differences("action space", model_action_space, env_action_space)
    if problems:
        raise ModelEnvMismatchError(
            "the model does not match the env:\n  - "
            + "\n  - ".join(problems)
            + "\n(evaluate it on the env it was trained on: drop the conflicting overrides, "
            "or use the env config saved in the model's .json metadata)"
        )


def space_differences(
    name: str, model_space: spaces.Space[Any], env_space: spaces.Space[Any]
) -> list[str]:
    """How ``model_space`` differs from ``env_space``: kind, shapes and dtypes, then the bounds
    of every Box (a model trained on normalised observations must not read raw ones)."""
    model_desc, env_desc = describe_space(model_space), describe_space(env_space)
    if model_desc != env_desc:
        return [f"{name}: model expects {model_desc}, env gives {env_desc}"]
    if isinstance(model_space, spaces.Dict) and isinstance(env_space, spaces.Dict):
        return [
            problem
            for key in model_space.spaces
            for problem in space_differences(f"{name} '{key}'", model_space[key], env_space[key])
        ]
    if isinstance(model_space, spaces.Box) and model_space != env_space:
        return [
            f"{name}: {bound} bounds differ: model {_bounds(getattr(model_space, bound))}, "
            f"env {_bounds(getattr(env_space, bound))}"
            for bound in ("low", "high")
            if not np.array_equal(getattr(model_space, bound), getattr(env_space, bound))
        ]
    return []


def _bounds(values: np.ndarray) -> str:
    unique = np.unique(values)
    shown = ", ".join(f"{v:g}" for v in unique[:4])
    return f"{{{shown}{', ...' if len(unique) > 4 else ''}}}"


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not JSON-serialisable: {type(value).__name__}")
