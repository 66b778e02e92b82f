"""Loading a true grid from a file: text, PGM (e.g. ROS / Explore-Bench maps) or PNG.

* ``.txt``: one line per row, ``#`` occupied and ``.`` free; blank lines at the end are ignored.
* ``.pgm`` (P5 binary or P2 text): a pixel is free when its value is at least 250 (ROS
  map_server's 254), anything darker is occupied, so ROS's "unknown" grey (205) is a wall.
* ``.png``: same rule on the grey level (the mean of the colour channels), scaled to 0..255
  whatever the bit depth.

Every loader returns a bool array, True = occupied, and rejects malformed files with a
``ValueError`` that names the file and what is wrong.
"""

from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import numpy as np

FREE_LEVEL = 250


def load_map(path: str | Path) -> np.ndarray:
    """The true grid stored in ``path`` (by suffix: .txt, .pgm, .png)."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"map file {path} is a folder, not a map file (.txt, .pgm, .png)")
    if not path.is_file():
        raise ValueError(f"map file {path} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".txt":
        grid = parse_text_map(_read_text(path), str(path))
    elif suffix == ".pgm":
        grid = parse_pgm(path.read_bytes(), str(path))
    elif suffix == ".png":
        grid = _load_png(path)
    else:
        raise ValueError(f"map file {path}: unsupported suffix {suffix!r} (use .txt, .pgm, .png)")
    if grid.all():
        raise ValueError(f"map file {path} has no free cell")
    return grid


def parse_text_map(text: str, name: str = "<text>") -> np.ndarray:
    """Parse ``#``/``.`` rows into a bool grid (True = occupied)."""
    lines = text.splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        raise ValueError(f"map {name} is empty")
    width = len(lines[0])
    for number, line in enumerate(lines, start=1):
        if len(line) != width:
            raise ValueError(
                f"map {name}: row {number} has {len(line)} cells, row 1 has {width} "
                "(rows must all have the same length)"
            )
        bad = set(line) - {"#", "."}
        if bad:
            column = min(line.index(ch) for ch in bad) + 1
            raise ValueError(
                f"map {name}: row {number}, column {column}: unexpected character "
                f"{line[column - 1]!r} (use '#' for occupied and '.' for free)"
            )
    if width == 0:
        raise ValueError(f"map {name} has empty rows")
    grid = np.array([[ch == "#" for ch in line] for line in lines], dtype=bool)
    if grid.all():
        raise ValueError(f"map {name} has no free cell")
    return grid


def format_text_map(grid: np.ndarray) -> str:
    """The inverse of :func:`parse_text_map`."""
    return "\n".join("".join("#" if cell else "." for cell in row) for row in grid) + "\n"


def parse_pgm(data: bytes, name: str = "<pgm>") -> np.ndarray:
    """Parse a P5 (binary) or P2 (ASCII) PGM image into a bool grid (True = occupied)."""
    tokens: list[bytes] = []
    position = 0
    # Header: magic, width, height, maxval, separated by whitespace, with # comments.
    while len(tokens) < 4:
        if position >= len(data):
            raise ValueError(f"map {name}: truncated PGM header")
        byte = data[position : position + 1]
        if byte == b"#":
            end = data.find(b"\n", position)
            position = len(data) if end < 0 else end + 1
        elif byte.isspace():
            position += 1
        else:
            start = position
            while position < len(data) and not data[position : position + 1].isspace():
                position += 1
            tokens.append(data[start:position])
    magic = tokens[0]
    if magic not in (b"P5", b"P2"):
        raise ValueError(f"map {name}: not a PGM file (magic {magic!r}, expected P5 or P2)")
    try:
        width, height, maxval = (int(token) for token in tokens[1:])
    except ValueError as error:
        raise ValueError(f"map {name}: malformed PGM header {tokens!r}") from error
    if width < 1 or height < 1 or not 0 < maxval < 65536:
        raise ValueError(f"map {name}: bad PGM size {width}x{height} or maxval {maxval}")
    if magic == b"P5":
        position += 1  # exactly one whitespace byte after maxval
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype(np.uint8)
        count = width * height
        available = (len(data) - position) // dtype.itemsize
        if available < count:
            raise ValueError(f"map {name}: {available} pixels, expected {width}x{height}")
        pixels = np.frombuffer(data, dtype=dtype, count=count, offset=position)
    else:
        values = data[position:].split()
        if len(values) < width * height:
            raise ValueError(f"map {name}: {len(values)} pixels, expected {width}x{height}")
        try:
            pixels = np.array([int(v) for v in values[: width * height]])
        except ValueError as error:
            raise ValueError(f"map {name}: a P2 pixel is not an integer ({error})") from error
    levels = pixels.reshape(height, width).astype(np.float64) * (255.0 / maxval)
    return levels < FREE_LEVEL


def _read_text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as error:
        raise ValueError(
            f"map file {path} is not a text map: byte {error.start} is not UTF-8 text "
            "(a .txt map holds rows of '#' and '.')"
        ) from None


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _load_png(path: Path) -> np.ndarray:
    with path.open("rb") as handle:
        if handle.read(len(PNG_SIGNATURE)) != PNG_SIGNATURE:
            raise ValueError(f"map file {path} is not a PNG image (no PNG signature)")
    try:
        raw = np.asarray(iio.imread(path, extension=".png", plugin="pillow"))
    except Exception as error:  # imageio raises OSError, ValueError or its own errors
        raise ValueError(f"map file {path} is a damaged PNG image ({error})") from None
    if raw.dtype == bool:
        levels = raw.astype(np.float64) * 255.0
    elif np.issubdtype(raw.dtype, np.integer):
        levels = raw.astype(np.float64) * (255.0 / np.iinfo(raw.dtype).max)
    else:
        levels = raw.astype(np.float64) * 255.0  # float images are in [0, 1]
    if levels.ndim == 3:
        levels = levels[..., :3].mean(axis=2)
    if levels.ndim != 2:
        raise ValueError(f"map file {path}: expected a 2D image, got shape {raw.shape}")
    return levels < FREE_LEVEL
