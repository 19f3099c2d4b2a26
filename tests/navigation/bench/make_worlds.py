"""Writes the held-out benchmark worlds (run once; the YAML files are committed):
``python tests/navigation/bench/make_worlds.py``.

* ``cluttered.yaml``: a 10 x 10 m walled field with 40 boxes and cylinders (0.2..0.8 m)
  at seeded random places, at least 0.5 m apart and 0.8 m from the spawn;
* ``narrow_doors.yaml``: four 3 x 3 m rooms in a row and a hall, joined by doors 0.45 m
  between the wall segments' ends, 0.35 m clear (a wall reaches half its 0.1 m thickness
  past its ends): 1.75 times mybot's 0.20 m width;
* ``corridor.yaml``: a 24 m x 1.2 m corridor and a parallel 1.0 m one, joined at both
  ends (a 50 m loop), with two alcoves and five thin pillars by the walls.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

HERE = Path(__file__).parent / "worlds"


def _wall(a: tuple[float, float], b: tuple[float, float], t: float = 0.1) -> dict[str, Any]:
    return {"from": [round(a[0], 3), round(a[1], 3)], "to": [round(b[0], 3), round(b[1], 3)],
            "thickness": t}  # fmt: skip


def cluttered(seed: int = 13) -> dict[str, Any]:
    rng = np.random.default_rng(seed)

    def uniform(lo: float, hi: float, size: int | None = None) -> Any:
        return np.asarray(rng.uniform(lo, hi, size)).tolist()

    size = 10.0
    walls = [{"points": [[0, 0], [size, 0], [size, size], [0, size]], "closed": True}]
    placed: list[tuple[float, float, float]] = []  # x, y, bounding radius
    boxes, cylinders = [], []
    spawn = (1.0, 1.0)
    while len(placed) < 40:
        kind = "box" if float(rng.random()) < 0.6 else "cyl"
        if kind == "box":
            w, d = uniform(0.2, 0.8, size=2)
            r = 0.5 * math.hypot(w, d)
        else:
            r = uniform(0.1, 0.35)
        x, y = uniform(0.6 + r, size - 0.6 - r, size=2)
        if math.hypot(x - spawn[0], y - spawn[1]) < r + 0.8:
            continue
        if any(math.hypot(x - px, y - py) < r + pr + 0.5 for px, py, pr in placed):
            continue
        placed.append((x, y, r))
        if kind == "box":
            boxes.append({"center": [round(x, 3), round(y, 3)],
                          "size": [round(w, 3), round(d, 3), 0.5],
                          "yaw": round(uniform(-math.pi, math.pi), 3)})  # fmt: skip
        else:
            cylinders.append({"center": [round(x, 3), round(y, 3)], "radius": round(r, 3),
                              "height": 0.5})  # fmt: skip
    return {"name": "cluttered", "walls": walls, "boxes": boxes, "cylinders": cylinders,
            "spawn": {"x": spawn[0], "y": spawn[1], "yaw": 0.0}}  # fmt: skip


def narrow_doors(door: float = 0.45) -> dict[str, Any]:
    # hall: y 0..2, x 0..12; rooms above it: y 2..5, x 0..3, 3..6, 6..9, 9..12
    walls = [{"points": [[0, 0], [12, 0], [12, 5], [0, 5]], "closed": True}]
    half = door / 2
    # the wall between hall and rooms, with one door per room (off-centre)
    xs = [0.0]
    for cx in (1.0, 4.5, 7.2, 10.6):
        xs += [cx - half, cx + half]
    xs.append(12.0)
    for a, b in zip(xs[::2], xs[1::2], strict=True):
        walls.append(_wall((a, 2.0), (b, 2.0)))
    # walls between the rooms, each with a door near the top
    for x in (3.0, 6.0, 9.0):
        walls.append(_wall((x, 2.0), (x, 4.0 - half)))
        walls.append(_wall((x, 4.0 + half), (x, 5.0)))
    boxes = [
        {"center": [5.0, 1.0], "size": [0.6, 0.6, 0.7]},
        {"center": [1.5, 3.8], "size": [0.8, 0.5, 0.7]},
        {"center": [7.8, 4.3], "size": [0.5, 0.8, 0.7]},
    ]
    return {"name": "narrow_doors", "walls": walls, "boxes": boxes,
            "spawn": {"x": 1.0, "y": 1.0, "yaw": 0.0}}  # fmt: skip


def corridor() -> dict[str, Any]:
    # lower corridor y 0..1.2, upper corridor y 2.2..3.2, x 0..24; joined at x 0..1.5 and
    # 22.5..24; the block between them (y 1.2..2.2) from x 1.5 to 22.5
    walls = [
        # the outer wall, open at two 1 m alcoves (0.5 m deep niches) along the bottom
        {"points": [[5.5, 0], [0, 0], [0, 3.2], [24, 3.2], [24, 0], [14.5, 0]]},
        {"points": [[13.5, 0], [6.5, 0]]},
        {"points": [[5.5, 0], [5.5, -0.5], [6.5, -0.5], [6.5, 0]]},
        {"points": [[13.5, 0], [13.5, -0.5], [14.5, -0.5], [14.5, 0]]},
        {"points": [[1.5, 1.2], [22.5, 1.2], [22.5, 2.2], [1.5, 2.2]], "closed": True},
    ]
    boxes: list[dict[str, Any]] = []
    cylinders = [{"center": [x, 0.25], "radius": 0.1, "height": 1.0} for x in (9.0, 17.5)]
    cylinders += [{"center": [x, 2.95], "radius": 0.1, "height": 1.0} for x in (4.0, 12.0, 20.0)]
    return {"name": "corridor", "walls": walls, "boxes": boxes, "cylinders": cylinders,
            "spawn": {"x": 0.75, "y": 0.6, "yaw": 0.0}}  # fmt: skip


def main() -> None:
    HERE.mkdir(exist_ok=True)
    for name, world in (("cluttered", cluttered()), ("narrow_doors", narrow_doors()),
                        ("corridor", corridor())):  # fmt: skip
        (HERE / f"{name}.yaml").write_text(
            f"# held-out world of the navigation benchmark ({Path(__file__).name})\n"
            + yaml.safe_dump(world, sort_keys=False, default_flow_style=None)
        )


if __name__ == "__main__":
    main()
