"""True-grid generators: pure functions of their arguments and a ``numpy.random.Generator``."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

FOUR_CONNECTED = ndimage.generate_binary_structure(2, 1)


def random_obstacle_map(
    height: int, width: int, obstacle_prob: float, rng: np.random.Generator
) -> np.ndarray:
    """Obstacles drawn independently per cell with probability ``obstacle_prob``.

    Returns a bool array ``(height, width)``, ``True`` = occupied. At least one cell is free.
    """
    grid = rng.random((height, width)) < obstacle_prob
    if grid.all():
        grid[rng.integers(height), rng.integers(width)] = False
    return grid


def largest_free_component(true_grid: np.ndarray) -> np.ndarray:
    """Bool mask of the largest 4-connected component of free cells (ties: lowest label)."""
    labels, count = ndimage.label(~true_grid, structure=FOUR_CONNECTED)
    if count == 0:
        raise ValueError("the map has no free cell")
    sizes = np.bincount(labels.ravel())[1:]
    return labels == (int(np.argmax(sizes)) + 1)


def sample_start_cells(region: np.ndarray, count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` distinct cells drawn uniformly from the True cells of ``region``, as (count, 2)."""
    cells = np.argwhere(region)
    if len(cells) < count:
        raise ValueError(
            f"the start region has {len(cells)} free cells, fewer than n_agents={count}"
        )
    chosen = rng.choice(len(cells), size=count, replace=False)
    return cells[chosen].astype(np.int64)


def rooms_map(
    height: int,
    width: int,
    rng: np.random.Generator,
    room_count: int | None = None,
    min_room: int = 3,
    max_room: int | None = None,
    corridor_width: int = 1,
) -> np.ndarray:
    """Rooms and corridors: rectangular rooms joined by L-shaped corridors.

    Rooms are placed at random without overlapping (one wall cell between rooms); each room
    after the first is joined to the nearest earlier room by a corridor, so all free cells form
    one 4-connected component. Returns a bool grid, True = occupied (walls).
    """
    if height < 5 or width < 5:
        raise ValueError(f"rooms_map needs at least 5x5 cells, got {height}x{width}")
    if min_room < 1:
        raise ValueError(f"min_room must be >= 1, got {min_room}")
    if corridor_width < 1:
        raise ValueError(f"corridor_width must be >= 1, got {corridor_width}")
    if max_room is None:
        max_room = max(min_room, min(height, width) // 4)
    if max_room < min_room:
        raise ValueError(f"max_room must be >= min_room={min_room}, got {max_room}")
    if room_count is None:
        room_count = max(2, (height * width) // ((min_room + max_room) ** 2))
    grid = np.ones((height, width), dtype=bool)
    rooms: list[tuple[int, int, int, int]] = []  # top, left, bottom (excl.), right (excl.)
    for _ in range(room_count * 20):
        if len(rooms) == room_count:
            break
        room_h = int(rng.integers(min_room, max_room + 1))
        room_w = int(rng.integers(min_room, max_room + 1))
        if room_h > height - 2 or room_w > width - 2:
            continue
        top = int(rng.integers(1, height - room_h))
        left = int(rng.integers(1, width - room_w))
        candidate = (top, left, top + room_h, left + room_w)
        if any(_rooms_touch(candidate, other) for other in rooms):
            continue
        rooms.append(candidate)
        grid[top : top + room_h, left : left + room_w] = False
    if not rooms:
        grid[1:-1, 1:-1] = False
        return grid
    centres = [
        ((top + bottom - 1) // 2, (left + right - 1) // 2) for top, left, bottom, right in rooms
    ]
    for index in range(1, len(rooms)):
        row, col = centres[index]
        nearest = min(
            range(index), key=lambda j: abs(centres[j][0] - row) + abs(centres[j][1] - col)
        )
        _carve_corridor(grid, centres[index], centres[nearest], corridor_width, rng)
    return grid


def _rooms_touch(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> bool:
    """Whether two rooms overlap or have no wall cell between them."""
    return not (a[2] < b[0] or b[2] < a[0] or a[3] < b[1] or b[3] < a[1])


def _carve_corridor(
    grid: np.ndarray,
    start: tuple[int, int],
    end: tuple[int, int],
    corridor_width: int,
    rng: np.random.Generator,
) -> None:
    """Carve an L-shaped corridor (horizontal then vertical, or the reverse) between cells."""
    (r0, c0), (r1, c1) = start, end
    height, width = grid.shape
    corner = (r0, c1) if rng.random() < 0.5 else (r1, c0)
    for (a_r, a_c), (b_r, b_c) in (((r0, c0), corner), (corner, (r1, c1))):
        top, bottom = sorted((a_r, b_r))
        left, right = sorted((a_c, b_c))
        grid[
            max(top, 1) : min(bottom + corridor_width, height - 1),
            max(left, 1) : min(right + corridor_width, width - 1),
        ] = False


def floorplan_map(
    height: int,
    width: int,
    rng: np.random.Generator,
    min_room: int = 7,
    max_room: int | None = None,
    door: int = 3,
) -> np.ndarray:
    """A building that fills the grid: thin walls split it recursively into rooms, each wall
    with a door (two on long walls), as on real floor plans (no solid rock between rooms).

    A rectangle whose longer side exceeds ``max_room`` is split across that side by a wall one
    cell thick, at a random place that leaves rooms of at least ``min_room`` cells on both
    sides and does not end in a door of an earlier wall; the door (``door`` cells wide) is
    placed at random along the new wall. Every free cell is reachable from every other.
    Returns a bool grid, True = occupied (walls).
    """
    if height < 5 or width < 5:
        raise ValueError(f"floorplan_map needs at least 5x5 cells, got {height}x{width}")
    if min_room < 2:
        raise ValueError(f"min_room must be >= 2, got {min_room}")
    if door < 1 or door > min_room:
        raise ValueError(f"door must be in [1, min_room={min_room}], got {door}")
    if max_room is None:
        max_room = max(2 * min_room + 1, min(height, width) // 3)
    if max_room < 2 * min_room + 1:
        raise ValueError(
            f"max_room must be >= 2 * min_room + 1 = {2 * min_room + 1}, got {max_room}"
        )
    grid = np.zeros((height, width), dtype=bool)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = True
    pending = [(1, 1, height - 1, width - 1)]  # rooms: top, left, bottom (excl.), right (excl.)
    while pending:
        top, left, bottom, right = pending.pop()
        rows, cols = bottom - top, right - left
        across_rows = rows > cols or (rows == cols and rng.random() < 0.5)
        span = rows if across_rows else cols
        if span <= max_room:
            continue
        wall = _place_wall(grid, (top, left, bottom, right), across_rows, min_room, rng)
        if wall is None:
            continue
        if across_rows:
            grid[wall, left:right] = True
            _carve_doors(grid[wall, left:right], door, rng)
            pending += [(top, left, wall, right), (wall + 1, left, bottom, right)]
        else:
            grid[top:bottom, wall] = True
            _carve_doors(grid[top:bottom, wall], door, rng)
            pending += [(top, left, bottom, wall), (top, wall + 1, bottom, right)]
    return grid


def _place_wall(
    grid: np.ndarray,
    room: tuple[int, int, int, int],
    across_rows: bool,
    min_room: int,
    rng: np.random.Generator,
) -> int | None:
    """Row (or column) of a wall that splits ``room`` (longer than ``2 * min_room + 1`` across
    the wall) into two rooms of at least ``min_room`` cells and whose two ends meet walls, not
    doors; ``None`` when 20 draws found none."""
    top, left, bottom, right = room
    low, high = (top, bottom) if across_rows else (left, right)
    for _ in range(20):
        line = int(rng.integers(low + min_room, high - min_room))
        if across_rows:
            ends = grid[line, left - 1], grid[line, right]
        else:
            ends = grid[top - 1, line], grid[bottom, line]
        if all(ends):
            return line
    return None


def _carve_doors(wall: np.ndarray, door: int, rng: np.random.Generator) -> None:
    """Open a door of ``door`` cells in ``wall`` (a view of the new wall's cells), and a second
    one in the other half of a wall longer than six doors."""
    length = len(wall)
    halves = [(0, length)] if length <= 6 * door else [(0, length // 2), (length // 2, length)]
    for start, stop in halves:
        at = int(rng.integers(start, max(start + 1, stop - door + 1)))
        wall[at : at + door] = False
