"""Write robot_navigation's maps/mazemap.{pgm,yaml}: seed 003's maze (bingda_tutorials'
world/maze.world, where simulation_robot.launch puts mybot) rasterised at 5 cm,
with what the robot cannot reach from its spawn (outside the walls) left unknown, as a map
saved from gmapping would have it. Run from the repository root:

    python scripts/make_mazemap.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import ndimage

from roverlab.description import find_package
from roverlab.maps import save_map
from roverlab.world import load_world

OUT = Path("src/roverlab/robots/robot_navigation/maps/mazemap")


def main() -> None:
    world = load_world(find_package("bingda_tutorials") / "world" / "maze.world")
    occ, (ox, oy) = world.occupancy(0.05, 0.0, 2.0, padding=0.3)
    free = ~occ
    labels, _ = ndimage.label(free)
    spawn = labels[int(round(-oy / 0.05)), int(round(-ox / 0.05))]
    grid = np.full(occ.shape, -1, dtype=np.int8)
    grid[labels == spawn] = 0
    # walls seen from the inside: occupied cells next to reachable free space
    seen = ndimage.binary_dilation(labels == spawn, iterations=2) & occ
    grid[seen] = 100
    saved = save_map(OUT, grid, resolution=0.05, origin=(ox, oy, 0.0))
    print(f"wrote {saved.image_path} and {saved.yaml_path} ({grid.shape[1]} x {grid.shape[0]})")


if __name__ == "__main__":
    main()
