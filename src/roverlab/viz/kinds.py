"""The dashboard's display kinds: each kind's message types, default topic and options.

Pure data (:data:`DISPLAY_KINDS`), one entry per rviz display class it stands for
(:data:`RVIZ_CLASSES`); :mod:`roverlab.viz.config` validates options against it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Final

__all__ = ["DISPLAY_KINDS", "POINT_COLOR_OPTIONS", "RVIZ_CLASSES", "DisplayKind"]

POINT_COLOR_OPTIONS: Final[dict[str, Any]] = {
    # rviz's Intensity colour transformer
    "channel_name": "intensity",
    "autocompute_intensity_bounds": True,
    "min_intensity": 0.0,
    "max_intensity": 4096.0,
    "use_rainbow": True,
    "invert_rainbow": False,
    "min_color": [0, 0, 0],
    "max_color": [255, 255, 255],
    # rviz's AxisColor colour transformer
    "axis": "Z",
    "autocompute_value_bounds": True,
    "min_value": -10.0,
    "max_value": 10.0,
    "use_fixed_frame": True,
}
"""Options of the LaserScan and PointCloud2 displays' colour transformers, rviz's defaults."""


@dataclass(frozen=True)
class DisplayKind:
    """What one kind of display draws and how it is configured.

    Attributes:
        kind: the dashboard's name (``map``, ``laser_scan``, ...).
        types: message types its topic may carry (empty: no topic).
        default_topic: topic of a new display of this kind.
        options: option name -> default value (its type is the default's type).
    """

    kind: str
    types: tuple[str, ...]
    default_topic: str
    options: Mapping[str, Any]


def _kind(kind: str, types: tuple[str, ...], topic: str, **options: Any) -> DisplayKind:
    return DisplayKind(kind, types, topic, options)


DISPLAY_KINDS: Final[dict[str, DisplayKind]] = {
    k.kind: k
    for k in (
        _kind(
            "grid",
            (),
            "",
            cell_size=1.0,
            cell_count=10,
            color=[160, 160, 164],
            alpha=0.5,
            reference_frame="",
        ),
        _kind(
            "map",
            ("nav_msgs/msg/OccupancyGrid",),
            "/map",
            alpha=0.7,
            color_scheme="map",
            draw_behind=False,
        ),
        _kind(
            "laser_scan",
            ("sensor_msgs/msg/LaserScan",),
            "/scan",
            color=[255, 0, 0],
            color_transformer="FlatColor",
            size_px=3.0,
            alpha=1.0,
            decay_s=0.0,
            **POINT_COLOR_OPTIONS,
        ),
        _kind("robot_model", (), "/robot_description", alpha=1.0),
        _kind("tf", (), "", show_names=True, show_axes=True, scale=1.0),
        _kind(
            "odometry",
            ("nav_msgs/msg/Odometry",),
            "/odom",
            keep=100,
            color=[255, 25, 0],
            alpha=1.0,
            position_tolerance=0.1,
            angle_tolerance=0.1,
            length=1.3,
        ),
        _kind(
            "path",
            ("nav_msgs/msg/Path",),
            "/move_base/NavfnROS/plan",
            color=[25, 255, 0],
            alpha=1.0,
            line_width=0.03,
        ),
        _kind(
            "pose_array",
            ("geometry_msgs/msg/PoseArray",),
            "/particlecloud",
            color=[255, 25, 0],
            alpha=1.0,
            length=0.3,
        ),
        _kind(
            "point_cloud2",
            ("sensor_msgs/msg/PointCloud2",),
            "/camera/depth/points",
            color_transformer="AxisColor",
            color=[255, 255, 255],
            size_px=2.0,
            alpha=1.0,
            max_points=20000,
            decay_s=0.0,
            **POINT_COLOR_OPTIONS,
        ),
        _kind("marker", ("visualization_msgs/msg/Marker",), "/visualization_marker"),
        _kind(
            "marker_array",
            ("visualization_msgs/msg/MarkerArray",),
            "/visualization_marker_array",
        ),
        _kind(
            "pose",
            ("geometry_msgs/msg/PoseStamped",),
            "/move_base_simple/goal",
            color=[255, 25, 0],
            alpha=1.0,
            length=1.3,
        ),
        _kind(
            "polygon",
            ("geometry_msgs/msg/PolygonStamped",),
            "/move_base/local_costmap/footprint",
            color=[25, 255, 0],
            alpha=1.0,
        ),
        _kind(
            "pose_with_covariance",
            ("geometry_msgs/msg/PoseWithCovarianceStamped",),
            "/amcl_pose",
            color=[255, 25, 0],
            alpha=1.0,
            length=1.0,
            covariance_scale=1.0,
        ),
        _kind(
            "image",
            ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"),
            "/image_raw",
            color_map="jet",
            min_value=0.0,
            max_value=0.0,
        ),
    )
}

RVIZ_CLASSES: Final[dict[str, str]] = {
    "rviz/Grid": "grid",
    "rviz/Map": "map",
    "rviz/LaserScan": "laser_scan",
    "rviz/RobotModel": "robot_model",
    "rviz/TF": "tf",
    "rviz/Odometry": "odometry",
    "rviz/Path": "path",
    "rviz/PoseArray": "pose_array",
    "rviz/PointCloud2": "point_cloud2",
    "rviz/Marker": "marker",
    "rviz/MarkerArray": "marker_array",
    "rviz/Pose": "pose",
    "rviz/PoseWithCovariance": "pose_with_covariance",
    "rviz/Polygon": "polygon",
    "rviz/PolygonStamped": "polygon",
    "rviz/Image": "image",
    "rviz/Camera": "image",
}
"""rviz display class -> dashboard display kind (rviz 2's ``rviz_default_plugins/X`` too)."""
