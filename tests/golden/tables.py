"""Golden tables: the printed tables and JSON rows of baseline and model evaluations.

``python tests/golden/tables.py`` rewrites ``tables.json`` (only for a deliberate change of
behaviour). The JSON rows are hashed without their ``config`` entries and file paths, so that a
new config key alone does not count as a change; every figure and per-episode record does.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import re
import sys
import tempfile
from pathlib import Path
from typing import Any

GOLDEN_FILE = Path(__file__).with_name("tables.json")

_SINGLE = "greedy-distance,greedy-gain,cost-utility,random,first-slot"
_TEAM = "greedy-distance,cost-utility,coordinated-assignment,utility-discount"

COMMANDS: dict[str, list[str]] = {
    "baselines-20x20-static": [
        "baselines",
        "--preset",
        "thesis-20x20",
        "--map-mode",
        "static",
        "--policies",
        _SINGLE,
    ],
    "baselines-20x20-dynamic": [
        "baselines",
        "--preset",
        "thesis-20x20",
        "--map-mode",
        "dynamic",
        "--policies",
        _SINGLE,
    ],
    "baselines-30x30-static": [
        "baselines",
        "--preset",
        "thesis-30x30",
        "--map-mode",
        "static",
        "--policies",
        _SINGLE,
    ],
    "baselines-30x30-dynamic": [
        "baselines",
        "--preset",
        "thesis-30x30",
        "--map-mode",
        "dynamic",
        "--policies",
        _SINGLE,
    ],
    "baselines-rooms64-team": [
        "baselines",
        "--map",
        "rooms-64",
        "--agents",
        "4",
        "--policies",
        _TEAM,
        "--episodes",
        "10",
    ],
    "evaluate-shipped-model": ["evaluate", "thesis-config01"],
}


#: Keys left out of the digest: the resolved env config (new keys may be added), file paths and
#: the kind of model evaluated (a label, added 2026-12-07).
_UNHASHED = {"config", "env_config", "model_path", "kind"}


def _strip_config(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _strip_config(v) for k, v in value.items() if k not in _UNHASHED}
    if isinstance(value, list):
        return [_strip_config(v) for v in value]
    return value


def run(name: str) -> dict[str, Any]:
    """The command's table (printed lines, file paths as ``<path>``) and its JSON digest."""
    from frontier_marl.cli.main import main

    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "rows.json"
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            code = main([*COMMANDS[name], "--json", str(out), "--no-progress"])
        if code != 0:
            raise RuntimeError(f"{name} exited with {code}")
        rows = _strip_config(json.loads(out.read_text()))
    lines = [re.sub(r"(^|\s)/\S+", r"\1<path>", line) for line in printed.getvalue().splitlines()]
    canonical = json.dumps(rows, sort_keys=True).encode()
    return {"table": lines, "json_sha256": hashlib.sha256(canonical).hexdigest()}


if __name__ == "__main__":
    golden = {name: run(name) for name in COMMANDS}
    GOLDEN_FILE.write_text(json.dumps(golden, indent=1, sort_keys=True) + "\n")
    print(f"wrote {len(golden)} tables to {GOLDEN_FILE}", file=sys.stderr)
