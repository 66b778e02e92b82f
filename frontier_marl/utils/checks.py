"""Validation of user-supplied values: each check raises a ``ValueError`` that names the
parameter, its allowed range and the value it got."""

from __future__ import annotations

import math
import numbers
from typing import Any


def check_choice(name: str, value: Any, choices: tuple[str, ...]) -> None:
    if value not in choices:
        raise ValueError(f"{name} must be one of {list(choices)}, got {value!r}")


def check_bool(name: str, value: Any) -> None:
    if not isinstance(value, bool):
        raise ValueError(f"{name} must be True or False, got {value!r}")


def check_int(
    name: str, value: Any, low: int, high: int | None = None, extra_allowed: str = ""
) -> int:
    """``value`` as an int if it is an integer (not a bool) in ``[low, high]``."""
    ok = isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if ok and value >= low and (high is None or value <= high):
        return int(value)
    allowed = f"an integer >= {low}" if high is None else f"an integer in [{low}, {high}]"
    if extra_allowed:
        allowed += f" or {extra_allowed}"
    raise ValueError(f"{name} must be {allowed}, got {value!r}")


def check_finite(name: str, value: Any) -> None:
    if not isinstance(value, numbers.Real) or isinstance(value, bool) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")


def check_range(name: str, value: Any, low: float, high: float, low_open: bool = False) -> None:
    check_finite(name, value)
    if (value <= low if low_open else value < low) or value > high:
        bracket = "(" if low_open else "["
        raise ValueError(f"{name} must be in {bracket}{low}, {high}], got {value!r}")


def check_seed(seed: Any, name: str = "seed") -> int | None:
    """``seed`` as an int, or None; ValueError naming ``name`` unless it is None or an integer
    >= 0 (numpy's generators take no negative seed, and a float or a bool is a mistake)."""
    if seed is None:
        return None
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise ValueError(f"{name} must be None or an integer >= 0, got {seed!r}")
    return int(seed)
