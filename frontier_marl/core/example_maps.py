"""Example maps shipped with the package: rooms-and-corridors layouts made by the generator.

Each map is a ``.txt`` file (``#`` wall, ``.`` free; see :mod:`frontier_marl.core.map_files`)
in ``frontier_marl/assets/maps/``, written by ``baselines/make_example_maps.py`` from
:func:`frontier_marl.core.maps.rooms_map` with the fixed seeds of :data:`EXAMPLE_MAPS`::

    from frontier_marl.core.example_maps import example_map_path
    env = frontier_marl.parallel_env(map_path=example_map_path("rooms-64"), n_agents=4)

The commands accept the names too (``--map rooms-64``).
"""

from __future__ import annotations

import atexit
import contextlib
from importlib import resources
from pathlib import Path

import numpy as np

from frontier_marl.core.maps import rooms_map

#: name -> (height, width, seed of ``rooms_map``)
EXAMPLE_MAPS: dict[str, tuple[int, int, int]] = {
    "rooms-32": (32, 32, 32),
    "rooms-64": (64, 64, 64),
    "rooms-128": (128, 128, 128),
}

_files = contextlib.ExitStack()
atexit.register(_files.close)


def example_map_names() -> list[str]:
    """The names of the shipped example maps."""
    return list(EXAMPLE_MAPS)


def example_map_path(name: str) -> Path:
    """The file of example map ``name`` (e.g. ``"rooms-64"``), usable as ``map_path``."""
    if name not in EXAMPLE_MAPS:
        raise ValueError(f"example map must be one of {example_map_names()}, got {name!r}")
    resource = resources.files("frontier_marl").joinpath("assets", "maps", f"{name}.txt")
    if not resource.is_file():
        raise ValueError(
            f"example map {name!r} is missing from the installed package ({resource}); "
            "regenerate it with baselines/make_example_maps.py"
        )
    if isinstance(resource, Path):
        return resource
    return _files.enter_context(resources.as_file(resource))  # e.g. a zipped install


def generate_example_map(name: str) -> np.ndarray:
    """The layout of example map ``name`` drawn afresh from the generator (True = wall)."""
    if name not in EXAMPLE_MAPS:
        raise ValueError(f"example map must be one of {example_map_names()}, got {name!r}")
    height, width, seed = EXAMPLE_MAPS[name]
    return rooms_map(height, width, np.random.default_rng(seed))


def resolve_map(value: str) -> str:
    """A ``--map`` value: an existing file path as given, else an example map's file."""
    if Path(value).is_file() or value not in EXAMPLE_MAPS:
        return value
    return str(example_map_path(value))
