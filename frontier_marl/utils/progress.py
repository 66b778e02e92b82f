"""The one progress bar of the project: tqdm on standard error, quiet when not on a terminal.

On a terminal the bar updates in place as usual. Written to a file or a CI log, where every
redraw would become a new line, it prints at most five lines: the start, each quarter of a
known total, and the end (with no total: the start, one line a minute at most, and the end).
"""

from __future__ import annotations

import sys
from typing import Any

from tqdm import tqdm


def progress_bar(total: int | None = None, *, disable: bool = False, **kwargs: Any) -> Any:
    """A ``tqdm`` bar over ``total`` items on standard error (keyword arguments go to tqdm)."""
    stream = kwargs.pop("file", sys.stderr)
    options: dict[str, Any] = {"file": stream, "dynamic_ncols": True}
    if not _is_terminal(stream):
        options["maxinterval"] = float("inf")  # no forced redraws from tqdm's monitor thread
        if total:
            options.update(mininterval=0.0, miniters=max(1, -(-total // 4)))
        else:
            options.update(mininterval=60.0)
    options.update(kwargs)
    return tqdm(total=total, disable=disable, **options)


def _is_terminal(stream: Any) -> bool:
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty and isatty())
    except ValueError:  # a closed stream
        return False
