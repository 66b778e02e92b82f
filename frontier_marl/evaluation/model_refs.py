"""Saved models as picklable references, loaded once per process.

An episode that runs in a worker process or on a Ray node (:mod:`frontier_marl.utils.parallel`)
names its model by path; the process loads it on first use and keeps it
(:func:`cached_model`, :func:`cached_scorer`; a file changed on disk is loaded again). A
:class:`ModelRef` also carries a model already in memory, used as it is in this process and
left behind when the reference is pickled.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

from frontier_marl.policies.models import (
    MAP_SCORER_FILE,
    LoadedModel,
    load_model,
    resolve_model_path,
)

#: Models kept per process (the oldest is dropped first).
CACHE_SIZE = 8
_LOADED: dict[tuple[str, str, int], Any] = {}


def _cached(kind: str, path: Path, load: Callable[[], Any]) -> Any:
    """``load()``, once per process for ``path`` as it is now on disk."""
    key = (kind, str(path), path.stat().st_mtime_ns)
    if key not in _LOADED:
        if len(_LOADED) >= CACHE_SIZE:
            del _LOADED[next(iter(_LOADED))]
        _LOADED[key] = load()
    return _LOADED[key]


def cached_model(source: str) -> LoadedModel:
    """:func:`~frontier_marl.policies.models.load_model` of ``source``, once per process."""
    return _cached("sb3", resolve_model_path(source), partial(load_model, source))


def cached_scorer(folder: str) -> tuple[Any, dict[str, Any]]:
    """The map scorer saved in ``folder`` and its metadata, once per process (ValueError
    naming the extra when torch is missing)."""
    try:  # torch is the train extra's
        from frontier_marl.policies.map_explorer import load_scorer
    except ModuleNotFoundError as exc:
        raise ValueError(
            f"model {folder}: a map scorer needs torch ({exc.name} is not installed): "
            "pip install 'frontier-marl[train]'"
        ) from None
    path = Path(folder)
    return _cached("scorer", path / MAP_SCORER_FILE, lambda: load_scorer(path))


def source_of(name: str | Path) -> str:
    """A model's name as any process can find it: an existing path made absolute."""
    return str(Path(name).resolve()) if Path(name).exists() else str(name)


@dataclass
class ModelRef:
    """A saved SB3 model by ``source`` (path or shipped name), with the ``loaded`` object
    when this process has it; :meth:`get` returns that object, else the cached load."""

    source: str
    loaded: LoadedModel | None = None

    def __getstate__(self) -> dict[str, Any]:
        return {"source": self.source, "loaded": None}  # the path travels, not the model

    def get(self) -> LoadedModel:
        return self.loaded if self.loaded is not None else cached_model(self.source)


@dataclass(frozen=True)
class ScorerMaker:
    """A picklable factory of the map scorer saved in ``folder``: a
    :class:`~frontier_marl.policies.map_explorer.MapExplorer` labelled ``label``, with the
    weight of frontier-rule's margin its training chose (``rule_weight`` in its metadata), or
    for a team's scorer a :class:`~frontier_marl.policies.team_map_explorer.TeamMapExplorer`."""

    folder: str
    label: str

    def __call__(self) -> Any:
        from frontier_marl.policies.map_explorer import MapExplorer  # torch: cached_scorer's
        from frontier_marl.policies.team_map_explorer import TeamMapExplorer

        model, metadata = cached_scorer(self.folder)
        if metadata["scorer"].get("team", False):
            return TeamMapExplorer(model, self.label)
        return MapExplorer(model, self.label, float(metadata.get("rule_weight", 0.0)))
