"""The golden set: whole episodes and result tables recorded before the redesign must replay
to the last digit (see tests/golden/)."""

from __future__ import annotations

import json

import pytest

from tests.golden import episodes, tables

GOLDEN_EPISODES = json.loads(episodes.GOLDEN_FILE.read_text())
GOLDEN_TABLES = json.loads(tables.GOLDEN_FILE.read_text())


def test_golden_set_covers_every_case() -> None:
    assert sorted(GOLDEN_EPISODES) == sorted(name for name, _, _ in episodes.cases())
    assert sorted(GOLDEN_TABLES) == sorted(tables.COMMANDS)


@pytest.mark.parametrize("name,kwargs,policy", list(episodes.cases()), ids=lambda v: str(v))
def test_episodes_replay_exactly(name: str, kwargs: dict, policy: str) -> None:
    for seed in episodes.SEEDS:
        assert episodes.play(kwargs, policy, seed) == GOLDEN_EPISODES[name][str(seed)], seed


@pytest.mark.parametrize("name", list(tables.COMMANDS))
def test_tables_are_unchanged(name: str) -> None:
    assert tables.run(name) == GOLDEN_TABLES[name]
