"""move_base parameter files in BARN's layout for tests: a Jackal-sized footprint, costmaps
from the laser in the odometry frame, and the caller's TrajectoryPlannerROS file."""

from __future__ import annotations

from pathlib import Path

_COMMON = """\
footprint: [[-0.21, -0.165], [-0.21, 0.165], [0.21, 0.165], [0.21, -0.165]]
footprint_padding: {padding}
plugins:
- {{name: obstacles_layer, type: "costmap_2d::ObstacleLayer"}}
- {{name: inflater_layer, type: "costmap_2d::InflationLayer"}}
obstacles_layer:
  observation_sources: scan
  scan: {{sensor_frame: front_laser, data_type: LaserScan, topic: front/scan, marking: true,
         clearing: true, obstacle_range: 2.5, raytrace_range: 3.0}}
inflater_layer: {{inflation_radius: 0.3}}
"""
_GLOBAL = """\
global_costmap: {{global_frame: odom, robot_base_frame: base_link, update_frequency: {hz},
                 width: {size}, height: {size}, resolution: 0.05, origin_x: {origin},
                 origin_y: {origin}, rolling_window: false}}
"""
_LOCAL = """\
local_costmap: {{global_frame: odom, robot_base_frame: base_link, update_frequency: {hz},
                width: 4.0, height: 4.0, resolution: 0.05, rolling_window: true}}
"""


def write_barn_layout(
    folder: Path,
    planner_yaml: str,
    *,
    padding: float,
    global_hz: float,
    global_size_m: float,
    local_hz: float,
) -> None:
    """Write the four files BARN's move_base_DWA.launch loads into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    size, origin = global_size_m, -global_size_m / 2
    files = {
        "costmap_common_params.yaml": _COMMON.format(padding=padding),
        "global_costmap_params.yaml": _GLOBAL.format(hz=global_hz, size=size, origin=origin),
        "local_costmap_params.yaml": _LOCAL.format(hz=local_hz),
        "base_local_planner_params.yaml": planner_yaml,
    }
    for name, text in files.items():
        (folder / name).write_text(text)
