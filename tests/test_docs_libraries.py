"""docs/libraries.md: every Python snippet runs as written (skipped when a library it imports is
not installed)."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parent.parent / "docs" / "libraries.md"
SNIPPETS = re.findall(r"```python\n(.*?)```", PAGE.read_text(), flags=re.DOTALL)
#: A snippet's title: the heading above it.
TITLES = [
    re.findall(r"^## (.+)$", PAGE.read_text().split(snippet)[0], flags=re.MULTILINE)[-1]
    for snippet in SNIPPETS
]


def test_the_page_has_the_five_libraries() -> None:
    assert len(SNIPPETS) == 5
    for name in ("SuperSuit", "MaskablePPO", "TorchRL", "Tianshou", "skrl"):
        assert any(name in title for title in TITLES), name


@pytest.mark.parametrize("snippet", SNIPPETS, ids=TITLES)
def test_snippet_runs(snippet: str) -> None:
    for module in sorted(set(re.findall(r"^(?:from|import) (\w+)", snippet, flags=re.M))):
        pytest.importorskip(module)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        exec(compile(snippet, str(PAGE), "exec"), {"__name__": "snippet"})
