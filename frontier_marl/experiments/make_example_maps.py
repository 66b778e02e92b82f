"""Regenerate the example maps in frontier_marl/assets/maps/ from their fixed seeds.

    python baselines/make_example_maps.py            # write the .txt files
    python baselines/make_example_maps.py --check    # exit 1 if a file differs

Each map is :func:`frontier_marl.core.maps.rooms_map` (height, width, seed) as listed in
:data:`frontier_marl.core.example_maps.EXAMPLE_MAPS`, written with ``format_text_map``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy import ndimage

from frontier_marl.core.example_maps import EXAMPLE_MAPS, generate_example_map
from frontier_marl.core.map_files import format_text_map
from frontier_marl.core.maps import FOUR_CONNECTED

#: The package's example maps (``baselines/make_example_maps.py`` passes the checkout's).
OUT = Path(__file__).resolve().parents[1] / "assets" / "maps"


def main(argv: list[str] | None = None, *, default_out: Path = OUT) -> int:
    """The command line of ``baselines/make_example_maps.py`` (``default_out``: ``--out``'s
    default)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare instead of writing")
    parser.add_argument(
        "--out", type=Path, default=default_out, help="folder (default: %(default)s)"
    )
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    stale = []
    for name, (height, width, seed) in EXAMPLE_MAPS.items():
        grid = generate_example_map(name)
        _, components = ndimage.label(~grid, structure=FOUR_CONNECTED)
        text = format_text_map(grid)
        path = args.out / f"{name}.txt"
        if args.check:
            if not path.is_file() or path.read_text() != text:
                stale.append(path)
            continue
        path.write_text(text)
        print(
            f"wrote {path}: {height}x{width}, seed {seed}, "
            f"{np.count_nonzero(~grid)} free cells, {components} free component(s)"
        )
    for path in stale:
        print(f"stale: {path}", file=sys.stderr)
    return 1 if stale else 0
