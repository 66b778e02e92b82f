"""The adapters' keywords: their own, and the config's, checked before the config is built."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from frontier_marl.config import ALIASES, EnvConfig, config_keys, make_config, reject_unknown

#: The keywords of the single adapters (Parallel, AEC, Gymnasium) beside the config's.
ADAPTER_KEYWORDS = ("preset", "render_mode", "info", "obs_layout")


def adapter_config(
    owner: str, preset: str | None, kwargs: dict[str, Any], own: Iterable[str] = ADAPTER_KEYWORDS
) -> EnvConfig:
    """The config of ``preset`` with ``kwargs``; an unknown keyword raises
    :class:`~frontier_marl.config.UnknownKeywordError` (a ``TypeError``) naming it and every
    keyword ``owner`` takes."""
    reject_unknown(kwargs, {*config_keys(), *ALIASES, *own}, owner)
    return make_config(preset, **kwargs)
