"""The progress bar stays quiet when its output is not a terminal."""

from __future__ import annotations

import io

from frontier_marl.utils.progress import progress_bar


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def redraws(stream: io.StringIO, total: int | None, updates: int, **kwargs: object) -> int:
    bar = progress_bar(total, file=stream, unit="step", **kwargs)
    for _ in range(updates):
        bar.update(1)
    bar.close()
    return stream.getvalue().count("\r")


def test_a_log_file_gets_at_most_a_few_lines() -> None:
    assert redraws(io.StringIO(), 10_000, 10_000) <= 6  # start, each quarter, end
    assert redraws(io.StringIO(), None, 10_000) <= 3  # no total: start and end
    assert redraws(io.StringIO(), 3, 3) <= 5


def test_a_terminal_gets_a_live_bar() -> None:
    assert redraws(Terminal(), 2_000, 2_000, mininterval=0.0, miniters=1) > 20


def test_a_disabled_bar_prints_nothing() -> None:
    stream = io.StringIO()
    bar = progress_bar(100, file=stream, disable=True)
    bar.update(100)
    bar.close()
    assert stream.getvalue() == ""
