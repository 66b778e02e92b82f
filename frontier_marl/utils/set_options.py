"""``--set KEY=VALUE`` options: the text of each value parsed into an int, float, bool, None or
string (the commands' ``--set`` and the baselines' scripts' ``--set`` and ``--option``)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any


def parse_value(text: str) -> Any:
    """A ``--set`` value: int, float, bool (true/false), None (none), else the string
    (e.g. ``full``, ``raycast``)."""
    lowered = text.strip().lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    if lowered in ("none", "null"):
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text.strip()


def parse_set_options(items: Sequence[str] | None) -> dict[str, Any]:
    """``["key=value", ...]`` -> ``{key: parsed value}``; ValueError on a malformed item."""
    out: dict[str, Any] = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        key = key.strip().replace("-", "_")
        if not sep or not key:
            raise ValueError(f"--set expects key=value, got {item!r}")
        out[key] = parse_value(value)
    return out
