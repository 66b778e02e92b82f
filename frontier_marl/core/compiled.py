"""The core's one compiler: numba's ``njit`` with an on-disk cache.

Every hot loop of the simulator (frontier cells, splitting, cluster statistics, targets, slots,
shortest paths, ray casting, the walk) has exactly one implementation, a numba-compiled
function next to the operation it implements; docs/performance.md says why. The functions
compile once per machine (about 10 s, then cached beside the module or in numba's user cache).
For debugging, numba's own ``NUMBA_DISABLE_JIT=1`` runs the same functions as plain Python.

Numba checks a cached function against its own file only: after editing a compiled function,
a caller in another file keeps the old callee compiled into it until that file changes too.
When developing, clear the caches after such an edit
(``find frontier_marl -name '*.nb[ic]' -delete``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

import numba

F = TypeVar("F", bound=Callable[..., Any])


def compiled(function: F) -> F:
    """``numba.njit`` with an on-disk cache; without one if no cache folder is writable."""
    try:
        return numba.njit(cache=True, nogil=True)(function)  # type: ignore[no-any-return]
    except RuntimeError:  # numba found no writable cache location: compile in every process
        return numba.njit(nogil=True)(function)  # type: ignore[no-any-return]
