"""Seeded world families for navigation benchmarks (``roverlab.world.generate``).

Every world comes with a start and a goal that are connected for a robot of radius
``robot_radius_m`` (checked on the rasterised world: free cells farther than the radius
from every obstacle, 8-connected); a draw that is not connected is replaced by the next
draw of the same generator, so a family and a seed always give the same worlds.

Families:

* ``barn``: BARN's recipe (Perille et al. 2020): a 30 x 30 grid of 0.15 m cells filled
  at random (fill ratio drawn in ``[0.25, 0.45]``), smoothed by a cellular automaton
  (1-4 rounds of the 4-5 rule: a filled cell stays with 4 filled neighbours of 8, an
  empty one fills with 5),
  each filled cell a cylinder of radius 0.075 m; the grid spans x in [-4.5, 0], y in
  [5, 9.5] between side walls, start (-2.25, 3.0, pi/2) and goal (-2.25, 13.0) as BARN's.
* ``corridor``: a 24 x 8 m floor, a corridor 1.4-2.0 m wide along it, rooms on both
  sides behind doors 0.8-1.2 m wide, thin pillars beside the doors and along the
  corridor; start at the corridor's west end, goal in a room of the east half.
* ``office``: 4 x 3 rooms of 3 x 3 m; the walls between rooms of a random spanning tree
  (and of a few more pairs) have doors 0.55-0.9 m wide; start in the south-west room,
  goal in the room farthest from it.
* ``clutter``: a 10 x 10 m room with 25-45 boxes (0.2-0.8 m) and cylinders (radius
  0.1-0.35 m) at least 0.5 m apart; start in the south-west corner, goal in the north-east.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from scipy import ndimage

from roverlab.fileio import atomic_write_bytes
from roverlab.world.errors import WorldError
from roverlab.world.yaml_world import world_from_dict

__all__ = ["FAMILIES", "GeneratedWorld", "connected", "generate", "generate_family"]

_MAX_DRAWS = 200
# a family's draw: the YAML world, start (x, y, yaw) and goal (x, y, yaw)
_Draw = tuple[dict[str, Any], tuple[float, ...], tuple[float, ...]]


@dataclass(frozen=True)
class GeneratedWorld:
    """One generated world: its YAML world (``data``, with ``spawn`` = ``start``), start
    ``(x, y, yaw)`` and goal ``(x, y, yaw)``."""

    name: str
    family: str
    seed: int
    data: dict[str, Any]
    start: tuple[float, float, float]
    goal: tuple[float, float, float]

    def write(self, folder: Path) -> Path:
        """``folder/NAME.yaml`` (replaced atomically); start and goal in a comment."""
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{self.name}.yaml"
        head = (
            f"# {self.family} world, seed {self.seed} (roverlab.world.generate)\n"
            f"# start: {list(self.start)}  goal: {list(self.goal)}\n"
        )
        atomic_write_bytes(path, (head + yaml.safe_dump(self.data, sort_keys=False)).encode())
        return path


def _r(v: float) -> float:
    return round(float(v), 3)


def _wall(a: tuple[float, float], b: tuple[float, float], t: float = 0.1) -> dict[str, Any]:
    return {"from": [_r(a[0]), _r(a[1])], "to": [_r(b[0]), _r(b[1])], "thickness": t}


def _with_door(
    a: tuple[float, float], b: tuple[float, float], at: float, width: float
) -> list[dict[str, Any]]:
    """The wall from ``a`` to ``b`` with a door ``width`` wide (clear) centred ``at`` m
    from ``a``: two segments whose ends (half the 0.1 m thickness past each end) leave
    exactly ``width`` between them."""
    length = math.dist(a, b)
    ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
    lo, hi = at - width / 2 - 0.05, at + width / 2 + 0.05
    out = []
    if lo > 0.05:
        out.append(_wall(a, (a[0] + ux * lo, a[1] + uy * lo)))
    if hi < length - 0.05:
        out.append(_wall((a[0] + ux * hi, a[1] + uy * hi), b))
    return out


def connected(
    data: dict[str, Any],
    start: tuple[float, float, float],
    goal: tuple[float, float, float],
    robot_radius_m: float,
    resolution: float = 0.05,
) -> bool:
    """Whether a disc of ``robot_radius_m`` can move from ``start`` to ``goal``."""
    world = world_from_dict(data, source=Path("generated.yaml"))
    xs, ys = (start[0], goal[0]), (start[1], goal[1])
    b = world.bounds
    lo_x, lo_y = min(*xs, b[0]) - 1.0, min(*ys, b[1]) - 1.0
    hi_x, hi_y = max(*xs, b[2]) + 1.0, max(*ys, b[3]) + 1.0
    occ, origin = world.occupancy(resolution, 0.0, 1.0, bounds=(lo_x, lo_y, hi_x, hi_y))
    free = ndimage.distance_transform_edt(~occ) * resolution > robot_radius_m
    labels, _ = ndimage.label(free, structure=np.ones((3, 3)))

    def cell(p: tuple[float, float, float]) -> tuple[int, int]:
        return int((p[1] - origin[1]) / resolution), int((p[0] - origin[0]) / resolution)

    a, z = labels[cell(start)], labels[cell(goal)]
    return bool(a != 0 and a == z)


# ----------------------------------------------------------------------- families
def _barn(rng: np.random.Generator) -> _Draw:
    fill = rng.uniform(0.25, 0.45)
    grid = rng.random((30, 30)) < fill
    ring = np.ones((3, 3), dtype=np.int64)
    ring[1, 1] = 0
    for _ in range(int(rng.integers(1, 5))):  # the 4-5 rule: survive with 4, born with 5
        count = ndimage.convolve(grid.astype(np.int64), ring, mode="constant")
        grid = np.where(grid, count >= 4, count >= 5)
    rows, cols = np.nonzero(grid)
    cylinders = [
        {"center": [_r(c * 0.15 - 4.5 + 0.075), _r(r * 0.15 + 5.0 + 0.075)], "radius": 0.075,
         "height": 1.0}
        for r, c in zip(rows.tolist(), cols.tolist(), strict=True)
    ]  # fmt: skip
    walls = [_wall((-4.65, 1.0), (-4.65, 9.6)), _wall((0.15, 1.0), (0.15, 9.6)),
             _wall((-4.65, 1.0), (0.15, 1.0))]  # fmt: skip
    data = {"name": "barn", "walls": walls, "cylinders": cylinders}
    return data, (-2.25, 3.0, math.pi / 2), (-2.25, 13.0, math.pi / 2)


def _corridor(
    rng: np.random.Generator,
) -> _Draw:
    length, depth = 24.0, 8.0
    width = rng.uniform(1.4, 2.0)
    y0, y1 = depth / 2 - width / 2, depth / 2 + width / 2
    walls: list[dict[str, Any]] = [
        {"points": [[0, 0], [length, 0], [length, depth], [0, depth]], "closed": True}
    ]
    cylinders: list[dict[str, Any]] = []
    n = int(rng.integers(4, 7))
    edges = np.linspace(0.0, length, n + 1)
    rooms = []
    for side_y, room_y in ((y0, y0 / 2), (y1, (y1 + depth) / 2)):
        for i in range(n):
            x_lo, x_hi = edges[i], edges[i + 1]
            if i > 0:  # the wall between two rooms
                walls.append(_wall((x_lo, side_y), (x_lo, 0.0 if side_y == y0 else depth)))
            door_w = rng.uniform(0.8, 1.2)
            at = rng.uniform(0.6 + door_w / 2, (x_hi - x_lo) - 0.6 - door_w / 2)
            walls += _with_door((x_lo, side_y), (x_hi, side_y), at, door_w)
            rooms.append(((x_lo + x_hi) / 2, room_y))
            # a pillar beside the door, on the corridor side, leaving the door clear
            side = 1.0 if rng.random() < 0.5 else -1.0
            px = x_lo + at + side * (door_w / 2 + rng.uniform(0.25, 0.5))
            py = side_y + (0.25 if side_y == y0 else -0.25)
            cylinders.append({"center": [_r(px), _r(py)], "radius": _r(rng.uniform(0.08, 0.15)),
                              "height": 1.0})  # fmt: skip
    for x in rng.uniform(3.0, length - 2.0, int(rng.integers(2, 5))):  # along the middle
        cylinders.append({"center": [_r(x), _r(depth / 2 + rng.uniform(-0.15, 0.15))],
                          "radius": _r(rng.uniform(0.08, 0.15)), "height": 1.0})  # fmt: skip
    east = [r for r in rooms if r[0] > length / 2]
    gx, gy = east[int(rng.integers(len(east)))]
    data = {"name": "corridor", "walls": walls, "cylinders": cylinders}
    return data, (0.8, depth / 2, 0.0), (gx, gy, 0.0)


def _office(
    rng: np.random.Generator,
) -> _Draw:
    nx, ny, size = 4, 3, 3.0
    walls: list[dict[str, Any]] = [
        {"points": [[0, 0], [nx * size, 0], [nx * size, ny * size], [0, ny * size]],
         "closed": True}
    ]  # fmt: skip
    pairs = [((i, j), (i + 1, j)) for i in range(nx - 1) for j in range(ny)]
    pairs += [((i, j), (i, j + 1)) for i in range(nx) for j in range(ny - 1)]
    order = rng.permutation(len(pairs))
    parent = {(i, j): (i, j) for i in range(nx) for j in range(ny)}

    def root(a: tuple[int, int]) -> tuple[int, int]:
        while parent[a] != a:
            a = parent[a]
        return a

    doors = set()
    for k in order:  # Kruskal on a random order: a random spanning tree
        a, b = pairs[k]
        if root(a) != root(b):
            parent[root(a)] = root(b)
            doors.add(pairs[k])
        elif rng.random() < 0.25:  # and a few loops
            doors.add(pairs[k])
    for a, b in pairs:
        if a[0] != b[0]:  # a vertical wall at x = b's west edge
            p, q = (b[0] * size, a[1] * size), (b[0] * size, (a[1] + 1) * size)
        else:
            p, q = (a[0] * size, b[1] * size), ((a[0] + 1) * size, b[1] * size)
        if (a, b) in doors:
            w = rng.uniform(0.55, 0.9)
            walls += _with_door(p, q, rng.uniform(0.4 + w / 2, size - 0.4 - w / 2), w)
        else:
            walls.append(_wall(p, q))
    # the goal: the room farthest (in doors) from the start's
    dist = {(0, 0): 0}
    frontier = [(0, 0)]
    while frontier:
        cur = frontier.pop(0)
        for a, b in doors:
            for u, v in ((a, b), (b, a)):
                if u == cur and v not in dist:
                    dist[v] = dist[u] + 1
                    frontier.append(v)
    far = max(sorted(dist), key=lambda r: dist[r])
    data = {"name": "office", "walls": walls}
    centre = (size / 2, size / 2, 0.0)
    return data, centre, ((far[0] + 0.5) * size, (far[1] + 0.5) * size, 0.0)


def _clutter(
    rng: np.random.Generator,
) -> _Draw:
    size = 10.0
    start, goal = (1.0, 1.0, math.pi / 4), (9.0, 9.0, math.pi / 4)
    placed: list[tuple[float, float, float]] = []
    boxes: list[dict[str, Any]] = []
    cylinders: list[dict[str, Any]] = []
    want = int(rng.integers(25, 46))
    tries = 0
    while len(placed) < want and tries < 5000:
        tries += 1
        is_box = rng.random() < 0.5
        if is_box:
            w, d = rng.uniform(0.2, 0.8, 2)
            r = 0.5 * math.hypot(w, d)
        else:
            r = rng.uniform(0.1, 0.35)
        x, y = rng.uniform(0.5 + r, size - 0.5 - r, 2)
        if min(math.dist((x, y), start[:2]), math.dist((x, y), goal[:2])) < r + 0.8:
            continue
        if any(math.dist((x, y), (px, py)) < r + pr + 0.5 for px, py, pr in placed):
            continue
        placed.append((x, y, r))
        if is_box:
            boxes.append({"center": [_r(x), _r(y)], "size": [_r(w), _r(d), 0.5],
                          "yaw": _r(rng.uniform(-math.pi, math.pi))})  # fmt: skip
        else:
            cylinders.append({"center": [_r(x), _r(y)], "radius": _r(r), "height": 0.5})
    walls = [{"points": [[0, 0], [size, 0], [size, size], [0, size]], "closed": True}]
    data = {"name": "clutter", "walls": walls, "boxes": boxes, "cylinders": cylinders}
    return data, start, goal


_Family = Callable[[np.random.Generator], _Draw]
FAMILIES: dict[str, _Family] = {
    "barn": _barn,
    "corridor": _corridor,
    "office": _office,
    "clutter": _clutter,
}


def generate(family: str, seed: int, *, robot_radius_m: float = 0.2) -> GeneratedWorld:
    """The world of ``family`` for ``seed``: the first draw of a generator seeded with
    ``seed`` whose start and goal are connected for ``robot_radius_m``.

    Raises:
        WorldError: an unknown family, or no connected draw in 200.
    """
    make = FAMILIES.get(family)
    if make is None:
        raise WorldError(f"unknown world family {family!r}: use {', '.join(FAMILIES)}")
    rng = np.random.default_rng(seed)
    for _ in range(_MAX_DRAWS):
        data, start, goal = make(rng)
        s3 = (float(start[0]), float(start[1]), float(start[2]))
        g3 = (float(goal[0]), float(goal[1]), float(goal[2]))
        if connected(data, s3, g3, robot_radius_m):
            data = {**data, "name": f"{family}_{seed:04d}",
                    "spawn": {"x": _r(s3[0]), "y": _r(s3[1]), "yaw": _r(s3[2])}}  # fmt: skip
            return GeneratedWorld(data["name"], family, seed, data, s3, g3)
    raise WorldError(
        f"{family} seed {seed}: no world in {_MAX_DRAWS} draws connects start and goal for "
        f"a robot of radius {robot_radius_m} m"
    )


def generate_family(
    family: str, count: int, *, first_seed: int = 0, robot_radius_m: float = 0.2
) -> list[GeneratedWorld]:
    """``count`` worlds of ``family`` with seeds ``first_seed`` .. ``first_seed + count - 1``."""
    return [
        generate(family, s, robot_radius_m=robot_radius_m)
        for s in range(first_seed, first_seed + count)
    ]
