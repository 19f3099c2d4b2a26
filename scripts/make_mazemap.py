"""Write the bundled navigation maps: robot_navigation's maps/mazemap (seed 003's maze,
bingda_tutorials' world/maze.world, where simulation_robot.launch puts mybot) and
mbot_navigation's maps/hui (seed 000's hui.world), each rasterised at 5 cm,
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

MAPS = (
    ("bingda_tutorials", "world/maze.world", "src/roverlab/packages/robot_navigation/maps/mazemap"),
    ("mbot_description", "worlds/hui.world", "src/roverlab/packages/mbot_navigation/maps/hui"),
)


def write_map(package: str, world_file: str, out: Path) -> None:
    world = load_world(find_package(package) / world_file)
    occ, (ox, oy) = world.occupancy(0.05, 0.0, 2.0, padding=0.3)
    free = ~occ
    labels, _ = ndimage.label(free)
    spawn = labels[int(round(-oy / 0.05)), int(round(-ox / 0.05))]
    grid = np.full(occ.shape, -1, dtype=np.int8)
    grid[labels == spawn] = 0
    # walls seen from the inside: occupied cells next to reachable free space
    seen = ndimage.binary_dilation(labels == spawn, iterations=2) & occ
    grid[seen] = 100
    out.parent.mkdir(parents=True, exist_ok=True)
    saved = save_map(out, grid, resolution=0.05, origin=(ox, oy, 0.0))
    print(f"wrote {saved.image_path} and {saved.yaml_path} ({grid.shape[1]} x {grid.shape[0]})")


def main() -> None:
    for package, world_file, out in MAPS:
        write_map(package, world_file, Path(out))


if __name__ == "__main__":
    main()
