"""Experiment configs: one TOML file per thesis experiment, overridable from the command line.

A config file has four parts (every one optional except ``name``)::

    name = "config01"
    description = "absolute centroids + agent position, unsorted, Reward 2"

    [env]            # flat keywords of frontier_marl.make_config (preset, centroid, reward, ...)
    preset = "thesis-20x20"
    reward = "reward2"

    [dqn]            # keyword arguments of stable_baselines3.DQN (thesis values by default)
    learning_rate = 5e-5

    [train]          # budget, seed, vector copies, checkpoints, evaluation
    total_timesteps = 1_000_000
    seed = 0

and, with ``train.algorithm = "cem"``, a ``[cem]`` section instead of ``[dqn]``
(:class:`~frontier_marl.training.settings.CEMSettings`); with ``"ppo"`` or ``"maskable-ppo"``, a
``[ppo]`` section (keyword arguments of SB3's ``PPO`` or sb3-contrib's ``MaskablePPO``, their
defaults where unset) and no ``[dqn]``.

Overrides use ``section.key=value`` (``env.reward=reward1``, ``dqn.learning_rate=1e-4``,
``train.n_envs=2``); a bare ``key=value`` goes to the one section that knows the key (a
keyword that DQN and PPO share goes to ``[dqn]``: write ``ppo.key=value``). Values
are parsed as TOML (``1e-4``, ``true``, ``[64, 64]``), else kept as strings.
"""

from __future__ import annotations

import dataclasses
import tomllib
from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig, config_keys, make_config
from frontier_marl.core.example_maps import EXAMPLE_MAPS, example_map_path
from frontier_marl.evaluation.benchmark.families import family, variant_configs
from frontier_marl.policies.models import renamed_hint
from frontier_marl.training.algorithms import SB3_ALGORITHMS
from frontier_marl.training.dqn import DQN, THESIS_DQN
from frontier_marl.training.ppo import PPO, with_prior_vector
from frontier_marl.training.settings import (
    CEM_KEYS,
    REGRESSION_KEYS,
    TRAIN_KEYS,
    CEMSettings,
    RegressionSettings,
    TrainSettings,
)

__all__ = ["Experiment", "TrainSettings", "experiment_from_dict", "load_experiment"]

SECTIONS = ("env", "dqn", "ppo", "train", "cem", "regression")


@dataclass(frozen=True)
class Experiment:
    """One training experiment: env keywords, the algorithm's keywords, and run settings."""

    name: str
    description: str = ""
    env: dict[str, Any] = field(default_factory=dict)
    dqn: dict[str, Any] = field(default_factory=lambda: dict(THESIS_DQN))
    train: TrainSettings = field(default_factory=TrainSettings)
    cem: dict[str, Any] = field(default_factory=dict)
    regression: dict[str, Any] = field(default_factory=dict)
    ppo: dict[str, Any] = field(default_factory=dict)
    source: str | None = None

    def hyperparameters(self) -> dict[str, Any]:
        """The keyword arguments of ``train.algorithm``'s SB3 class (``[dqn]`` or ``[ppo]``);
        a ``policy_kwargs.prior`` given by feature name becomes the vector over the
        observation's slot features (ValueError for a name that is not one)."""
        if not self._uses_ppo():
            return self.dqn
        return with_prior_vector(self.ppo, self.env_config())

    def env_config(self) -> EnvConfig:
        """The validated env config (raises ``ValueError`` naming a bad env key); with
        ``train.families``, the first family's."""
        return self.env_configs()[0]

    def env_configs(self) -> list[EnvConfig]:
        """One env config per training family and team size (``[env]`` on each family's world
        with ``train.agents`` robots, families first), or the ``[env]`` config alone."""
        if self.train.families:
            return [
                variant_configs(family(name), self.env, agents)[0]
                for name in self.train.families
                for agents in self.train.agents
            ]
        kwargs = dict(self.env)
        preset = kwargs.pop("preset", "thesis-20x20")
        return [make_config(preset, **kwargs)]

    def to_dict(self) -> dict[str, Any]:
        """A JSON/TOML-able dictionary that :func:`experiment_from_dict` reads back."""
        return {
            "name": self.name,
            "description": self.description,
            "env": dict(self.env),
            **({"ppo": dict(self.ppo)} if self._uses_ppo() else {"dqn": dict(self.dqn)}),
            "train": {
                **dataclasses.asdict(self.train),
                "families": list(self.train.families),
                "agents": list(self.train.agents),
            },
            **({"cem": dict(self.cem)} if self.cem else {}),
            **({"regression": dict(self.regression)} if self.regression else {}),
        }

    def _uses_ppo(self) -> bool:
        return section_of(self.train.algorithm) == "ppo"


def section_of(algorithm: str) -> str | None:
    """The config section of ``algorithm``'s keywords (None for ``cem``)."""
    sb3 = SB3_ALGORITHMS.get(algorithm)
    return None if sb3 is None else sb3.section


def dqn_keys() -> set[str]:
    """Keyword arguments of ``stable_baselines3.DQN`` that a config may set."""
    return DQN.keyword_names()


def experiment_from_dict(data: Mapping[str, Any], source: str | None = None) -> Experiment:
    """Build and validate an :class:`Experiment` from a parsed config file."""
    where = f" in {source}" if source else ""
    name = _checked_name(data, where)
    env = _env_section(data)
    train_kw = dict(data.get("train", {}))
    for key in ("families", "agents"):
        if isinstance(train_kw.get(key), list):
            train_kw[key] = tuple(train_kw[key])
    _check_keys("train", train_kw, TRAIN_KEYS, where)
    dqn = {**THESIS_DQN, **dict(data.get("dqn", {}))}
    _check_keys("dqn", dqn, dqn_keys(), where, reserved=True)
    DQN.check_ranges(dqn, where)
    settings = TrainSettings(**train_kw)
    ppo = _ppo_section(data, settings, where)
    cem = dict(data.get("cem", {}))
    _check_keys("cem", cem, CEM_KEYS, where)
    CEMSettings(**cem)  # raises naming a bad value
    regression = dict(data.get("regression", {}))
    _check_keys("regression", regression, REGRESSION_KEYS, where)
    RegressionSettings(**regression)
    if isinstance(dqn.get("train_freq"), list):
        dqn["train_freq"] = tuple(dqn["train_freq"])  # SB3 wants (n, "step"|"episode")
    experiment = Experiment(
        name=name,
        description=str(data.get("description", "")),
        env=env,
        dqn=dqn,
        train=settings,
        cem=cem,
        regression=regression,
        ppo=ppo,
        source=source,
    )
    _check_built(experiment, where)
    return experiment


def _checked_name(data: Mapping[str, Any], where: str) -> str:
    """The experiment's name, after checking the top-level keys and that sections are tables."""
    unknown = set(data) - {"name", "description", *SECTIONS}
    if unknown:
        raise ValueError(
            f"unknown top-level key(s) {sorted(unknown)}{where}; "
            "allowed: name, description, [env], [dqn], [ppo], [train], [cem], [regression]"
        )
    name = data.get("name")
    if not isinstance(name, str) or not name:
        raise ValueError(f"an experiment needs a non-empty string 'name'{where}")
    for section in SECTIONS:
        if not isinstance(data.get(section, {}), Mapping):
            raise ValueError(f"[{section}] must be a table{where}")
    return name


def _env_section(data: Mapping[str, Any]) -> dict[str, Any]:
    """The ``[env]`` keywords, a shipped example map named in ``map_path`` made a path."""
    env = dict(data.get("env", {}))
    map_name = env.get("map_path")
    if isinstance(map_name, str) and map_name in EXAMPLE_MAPS:  # e.g. "rooms-64"
        env["map_path"] = str(example_map_path(map_name))  # a shipped example map by name
    return env


def _check_keys(
    section: str, keys: Iterable[str], allowed: Collection[str], where: str, reserved: bool = False
) -> None:
    """Refuse keys of ``[section]`` outside ``allowed`` (``reserved``: seed and device, which
    [train] sets, are not allowed either)."""
    bad = set(keys) - set(allowed)
    if not bad:
        return
    if reserved:
        raise ValueError(
            f"unknown or reserved [{section}] key(s) {sorted(bad)}{where}; "
            f"allowed: {sorted(allowed)} (seed and device are set in [train])"
        )
    raise ValueError(f"unknown [{section}] key(s) {sorted(bad)}{where}; allowed: {sorted(allowed)}")


def _ppo_section(data: Mapping[str, Any], settings: TrainSettings, where: str) -> dict[str, Any]:
    """The ``[ppo]`` keywords, checked against the algorithm (none unless it is a PPO)."""
    ppo = dict(data.get("ppo", {}))
    _check_sections(settings.algorithm, bool(data.get("dqn")), bool(ppo), where)
    if ppo:
        algorithm = SB3_ALGORITHMS[settings.algorithm]
        _check_keys("ppo", ppo, algorithm.keyword_names(), where, reserved=True)
        algorithm.check_ranges(ppo, where)
    return ppo


def _check_built(experiment: Experiment, where: str) -> None:
    """Refuse an experiment whose env config or hyperparameters cannot be built."""
    try:
        experiment.env_config()
    except ValueError as exc:
        raise ValueError(f"[env]{where}: {exc}") from exc
    try:
        experiment.hyperparameters()
    except ValueError as exc:
        raise ValueError(f"[ppo]{where}: {exc}") from exc


def _check_sections(algorithm: str, has_dqn: bool, has_ppo: bool, where: str) -> None:
    """A ``[dqn]`` or ``[ppo]`` section that ``algorithm`` would not read is an error (it
    would be silently ignored)."""
    section = section_of(algorithm)
    if has_ppo and section != "ppo":
        raise ValueError(
            f"[ppo] settings{where} are read only with train.algorithm = 'ppo' or "
            f"'maskable-ppo' (it is {algorithm!r})"
        )
    if has_dqn and section == "ppo":
        raise ValueError(
            f"[dqn] settings{where} are not read with train.algorithm = {algorithm!r}: "
            "set PPO's keywords in [ppo] (ppo.key=value)"
        )


def parse_override(text: str) -> tuple[str, str, Any]:
    """``'section.key=value'`` or ``'key=value'`` -> (section, key, parsed value)."""
    if "=" not in text:
        raise ValueError(f"override must look like key=value or section.key=value, got {text!r}")
    key, raw = text.split("=", 1)
    key = key.strip()
    value = _parse_value(raw.strip())
    if "." in key:
        section, name = key.split(".", 1)
        if section not in SECTIONS:
            raise ValueError(
                f"override section must be one of {', '.join(SECTIONS)}, got {section!r} in "
                f"{text!r}"
            )
        return section, name, value
    owners = [
        section
        for section, keys in (
            ("train", TRAIN_KEYS),
            ("dqn", dqn_keys()),
            ("ppo", PPO.keyword_names() - dqn_keys()),
            ("cem", CEM_KEYS),
            ("regression", REGRESSION_KEYS),
            ("env", set(config_keys())),
        )
        if key in keys
    ]
    if not owners:
        raise ValueError(
            f"unknown override key {key!r}: not a key of {', '.join(SECTIONS)} "
            "(use section.key=value to be explicit)"
        )
    if len(owners) > 1:
        raise ValueError(f"override key {key!r} is ambiguous ({owners}): write section.{key}")
    return owners[0], key, value


def _parse_value(raw: str) -> Any:
    try:
        return tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        return raw


def apply_overrides(data: Mapping[str, Any], overrides: Iterable[str]) -> dict[str, Any]:
    """A copy of a parsed config with ``key=value`` overrides applied."""
    out: dict[str, Any] = {k: (dict(v) if isinstance(v, Mapping) else v) for k, v in data.items()}
    for text in overrides:
        section, key, value = parse_override(text)
        out.setdefault(section, {})[key] = value
    return out


def shipped_configs() -> list[str]:
    """The names of the experiment configs shipped with the package (``config01`` ...)."""
    folder = resources.files("frontier_marl").joinpath("assets", "configs")
    return sorted(
        entry.name[: -len(".toml")] for entry in folder.iterdir() if entry.name.endswith(".toml")
    )


def _read_config(config: str | Path) -> tuple[str, str]:
    """(TOML text, source) of a config file path, or of a shipped config by name."""
    path = Path(config)
    if path.is_file():
        return path.read_text(encoding="utf-8"), str(path)
    if path.parent != Path("."):
        raise ValueError(f"config file {str(config)!r} not found")
    name = path.name[: -len(".toml")] if path.name.endswith(".toml") else path.name
    if name in shipped_configs():
        resource = resources.files("frontier_marl").joinpath("assets", "configs", f"{name}.toml")
        return resource.read_text(encoding="utf-8"), f"{name} (shipped)"
    raise ValueError(
        f"config {str(config)!r} is neither a file nor a shipped config "
        f"({', '.join(shipped_configs())})" + renamed_hint(name)
    )


def load_experiment(config: str | Path, overrides: Iterable[str] = ()) -> Experiment:
    """Read a TOML experiment (a file path, or a shipped config's name) and apply overrides."""
    text, source = _read_config(config)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"cannot parse {source}: {exc}") from exc
    return experiment_from_dict(apply_overrides(data, overrides), source=source)
