"""Parameters of hector_mapping, with the ROS names and defaults of ``HectorMappingRos.cpp``.

Only the parameters that change the algorithm live here; the node-level ones (frames, topics,
publishing periods) are listed in :data:`NODE_PARAMETERS` so a ``.launch`` file's whole
``<param>`` set can be passed to :meth:`HectorParams.from_ros` without tripping the check
for misspelt names.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from roverlab.slam.common import params_from_ros
from roverlab.slam.hector.errors import HectorParamsError

__all__ = ["MOTION_PREDICTIONS", "NODE_PARAMETERS", "HectorParams"]

#: Values of :attr:`HectorParams.motion_prediction`.
MOTION_PREDICTIONS = ("constant_pose", "constant_velocity")

#: hector_mapping parameters handled by the node (frames, topics, TF and publishing options).
NODE_PARAMETERS = frozenset(
    {
        "pub_drawings",
        "pub_debug_output",
        "pub_map_odom_transform",
        "pub_odometry",
        "advertise_map_service",
        "scan_subscriber_queue_size",
        "scan_topic",
        "sys_msg_topic",
        "pose_update_topic",
        "use_tf_scan_transformation",
        "use_tf_pose_start_estimate",
        "base_frame",
        "map_frame",
        "odom_frame",
        "pub_map_scanmatch_transform",
        "tf_map_scanmatch_transform_frame_name",
        "output_timing",
        "map_pub_period",
    }
)


@dataclass(frozen=True, slots=True, kw_only=True)
class HectorParams:
    """Algorithm parameters of hector_mapping (ROS names, SI units, hector's defaults).

    The first group are hector_mapping's own ROS parameters with its defaults; the rest are
    roverlab's (hector hard-codes its prediction and matcher), marked "roverlab" below.

    Attributes:
        map_resolution: cell size of the finest map level (m).
        map_size: cells per side of the finest level (the map is square and fixed).
        map_start_x: where the start pose lies in the map, as a fraction of its width.
        map_start_y: the same for the height.
        map_multi_res_levels: number of levels; level ``i`` has cell size
            ``map_resolution * 2**i`` and ``map_size // 2**i`` cells per side.
        update_factor_free: occupancy probability of a cell a beam passes through; turned
            into the log-odds increment ``log(p / (1 - p))``.
        update_factor_occupied: occupancy probability of a beam's end cell.
        map_update_distance_thresh: the map is updated once the robot has moved this far
            (m) since the last map update ...
        map_update_angle_thresh: ... or turned this much (rad).
        laser_min_dist: endpoints closer than this to the laser are dropped (m).
        laser_max_dist: endpoints this far or farther are dropped (m).
        laser_z_min_value: endpoints below this height in the robot frame are dropped (m).
        laser_z_max_value: endpoints above this height are dropped (m).
        map_with_known_poses: no scan matching: map with the given (odometry) poses.
        use_odometry: (roverlab) start each match at the previous estimate moved by the
            odometry delta since the previous scan (the role of hector's TF start
            estimate); False, hector's default, ignores odometry.
        motion_prediction: (roverlab) the prediction without odometry:
            ``"constant_velocity"`` (the default: the previous estimate moved by the last
            scan-to-scan motion) or ``"constant_pose"`` (hector's: the previous estimate).
            Constant velocity keeps fast turns of low-rate scanners inside the matcher's
            basin (fr079: 0.033 m instead of losing track) and costs nothing.
        scan_match_iterations_coarse: (roverlab) at most this many Gauss-Newton steps on
            each coarse level; a level stops early once the steps become tiny (hector
            always makes 4).
        scan_match_iterations_fine: (roverlab) the same on the finest level (hector: 6).
        scan_match_angle_search: (roverlab) half-width (rad) of a rotational pre-search on
            the coarsest level before Gauss-Newton, so that the prediction survives fast
            turns of low-rate scanners; 0 turns it off (hector's plain matcher).
        scan_match_angle_search_step: (roverlab) heading step (rad) of that search; it
            should move a typical endpoint by no more than a coarsest-level cell.
        scan_match_translation_search: (roverlab) half-width (m) of the translational
            pre-search that follows, in steps of one coarsest-level cell; 0 turns it off.
        scan_match_damping: (roverlab) a step that would raise the cost is retried with
            Levenberg-Marquardt damping instead of taken (False: hector takes every step).
        degenerate_eigen_ratio: (roverlab, with odometry) a scan whose surface normals'
            information has ``lambda_min / lambda_max`` below this cannot fix the robot
            along the weak direction (a bare corridor): along it the odometry increment is
            kept instead of the match (:mod:`roverlab.slam.degeneracy`); 0 turns it
            off (hector: the match is taken and stalls in corridors).
        max_linear_velocity: (roverlab, with odometry) a match that moves the estimate
            faster than this (m/s) since the previous scan is a jump the robot cannot make:
            the odometry prediction is kept and the map is not updated; 0 turns it off.
        max_angular_velocity: (roverlab, with odometry) the same for turning (rad/s).
        max_free_endpoints: (roverlab, with odometry) a match that puts more than this share
            of the endpoints on cells the map holds free has collapsed: the odometry
            prediction is kept and the map is not updated; 1 turns it off.
        rival_match_threshold: (roverlab, with odometry) when the odometry's prediction
            and the scan-only one (``motion_prediction``) differ by more than this (m, or
            rad in heading), the scan is matched from both and the match that passes the
            checks above and fits the map better (hector's cost ``sum (1 - M)^2``) is
            taken: odometry that stalls and then catches up at once (mit-csail's, while
            turning) would otherwise start the match tens of degrees off; 0 turns it off.
        revisit_search: (roverlab, with odometry) half-width (m) of the wide search for
            the map on a revisit (:mod:`roverlab.slam.hector.revisit`): a match that puts
            fewer than ``revisit_trigger`` of the endpoints on occupied cells is searched
            for over this distance around it; 0 turns it off.
        revisit_angle_search: (roverlab) half-width (rad) of that search in heading.
        revisit_trigger: (roverlab) the share of endpoints on occupied cells below which
            the search runs.
        revisit_fit_ratio: (roverlab) a place the search finds is a candidate when its
            cost ``sum (1 - M)^2`` is at most this share of the match's.
        revisit_confirmations: (roverlab) a candidate is taken once this many scans in a
            row find candidates that agree with the odometry between them; until then the
            scans are not mapped.
    """

    map_resolution: float = 0.025
    map_size: int = 1024
    map_start_x: float = 0.5
    map_start_y: float = 0.5
    map_multi_res_levels: int = 3
    update_factor_free: float = 0.4
    update_factor_occupied: float = 0.9
    map_update_distance_thresh: float = 0.4
    map_update_angle_thresh: float = 0.9
    laser_min_dist: float = 0.4
    laser_max_dist: float = 30.0
    laser_z_min_value: float = -1.0
    laser_z_max_value: float = 1.0
    map_with_known_poses: bool = False
    use_odometry: bool = False
    motion_prediction: str = "constant_velocity"
    scan_match_iterations_coarse: int = 10
    scan_match_iterations_fine: int = 20
    scan_match_angle_search: float = 0.3
    scan_match_angle_search_step: float = 0.01
    scan_match_translation_search: float = 0.2
    scan_match_damping: bool = True
    degenerate_eigen_ratio: float = 0.01
    max_linear_velocity: float = 2.0
    max_angular_velocity: float = 4.0
    max_free_endpoints: float = 0.5
    rival_match_threshold: float = 0.1
    revisit_search: float = 1.0
    revisit_angle_search: float = 0.05
    revisit_trigger: float = 0.7
    revisit_fit_ratio: float = 0.6
    revisit_confirmations: int = 3

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.type in ("bool", bool):
                if not isinstance(value, bool):
                    raise HectorParamsError(f"{f.name} must be a bool, got {value!r}")
            elif f.type in ("str", str):
                if not isinstance(value, str):
                    raise HectorParamsError(f"{f.name} must be a string, got {value!r}")
            elif f.type in ("int", int):
                if isinstance(value, bool) or not isinstance(value, int):
                    raise HectorParamsError(f"{f.name} must be an int, got {value!r}")
            else:
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise HectorParamsError(f"{f.name} must be a number, got {value!r}")
                if not math.isfinite(value):
                    raise HectorParamsError(f"{f.name} must be finite, got {value!r}")
        _check(
            self.motion_prediction in MOTION_PREDICTIONS,
            f"motion_prediction must be one of {', '.join(MOTION_PREDICTIONS)}, "
            f"not {self.motion_prediction!r}",
        )
        _check(self.map_resolution > 0.0, "map_resolution must be > 0")
        _check(0.0 <= self.map_start_x <= 1.0, "map_start_x must be in [0, 1]")
        _check(0.0 <= self.map_start_y <= 1.0, "map_start_y must be in [0, 1]")
        _check(1 <= self.map_multi_res_levels <= 8, "map_multi_res_levels must be in [1, 8]")
        coarsest = self.map_size >> (self.map_multi_res_levels - 1)
        _check(
            coarsest >= 8,
            f"map_size {self.map_size} is too small for {self.map_multi_res_levels} levels "
            "(the coarsest level needs >= 8 cells per side)",
        )
        _check(0.0 < self.update_factor_free < 1.0, "update_factor_free must be in (0, 1)")
        _check(0.0 < self.update_factor_occupied < 1.0, "update_factor_occupied must be in (0, 1)")
        _check(self.map_update_distance_thresh >= 0.0, "map_update_distance_thresh must be >= 0")
        _check(self.map_update_angle_thresh >= 0.0, "map_update_angle_thresh must be >= 0")
        _check(self.laser_min_dist >= 0.0, "laser_min_dist must be >= 0")
        _check(self.laser_max_dist > self.laser_min_dist, "laser_max_dist must be > laser_min_dist")
        _check(
            self.laser_z_max_value >= self.laser_z_min_value,
            "laser_z_max_value must be >= laser_z_min_value",
        )
        _check(self.scan_match_iterations_coarse >= 0, "scan_match_iterations_coarse >= 0")
        _check(self.scan_match_iterations_fine >= 0, "scan_match_iterations_fine >= 0")
        _check(self.scan_match_angle_search >= 0.0, "scan_match_angle_search must be >= 0")
        _check(self.scan_match_angle_search <= math.pi, "scan_match_angle_search must be <= pi")
        _check(self.scan_match_angle_search_step > 0.0, "scan_match_angle_search_step must be > 0")
        _check(
            0.0 <= self.scan_match_translation_search <= 2.0,
            "scan_match_translation_search must be in [0, 2] m",
        )

        _check(0.0 <= self.degenerate_eigen_ratio < 1.0, "degenerate_eigen_ratio must be in [0, 1)")
        _check(self.max_linear_velocity >= 0.0, "max_linear_velocity must be >= 0")
        _check(self.max_angular_velocity >= 0.0, "max_angular_velocity must be >= 0")
        _check(0.0 < self.max_free_endpoints <= 1.0, "max_free_endpoints must be in (0, 1]")
        _check(self.rival_match_threshold >= 0.0, "rival_match_threshold must be >= 0")
        _check(0.0 <= self.revisit_search <= 5.0, "revisit_search must be in [0, 5] m")
        _check(0.0 <= self.revisit_angle_search <= 0.5, "revisit_angle_search must be in [0, 0.5]")
        _check(0.0 <= self.revisit_trigger <= 1.0, "revisit_trigger must be in [0, 1]")
        _check(0.0 < self.revisit_fit_ratio <= 1.0, "revisit_fit_ratio must be in (0, 1]")
        _check(self.revisit_confirmations >= 1, "revisit_confirmations must be >= 1")

    @classmethod
    def from_ros(cls, params: Mapping[str, Any]) -> HectorParams:
        """Build from a hector_mapping ``<param>`` set (names as in a ``.launch`` file).

        Integers given for float parameters are accepted (``value="2"``); node-level names
        (:data:`NODE_PARAMETERS`) are ignored; anything else unknown is an error.

        Raises:
            HectorParamsError: an unknown name or a bad value.
        """
        return params_from_ros(
            cls,
            params,
            ignored=NODE_PARAMETERS,
            unknown=lambda name: HectorParamsError(f"unknown hector_mapping parameter {name!r}"),
        )

    def level_resolution(self, level: int) -> float:
        """Cell size (m) of map level ``level`` (0 is the finest)."""
        return self.map_resolution * (1 << level)

    def translation_search_cells(self) -> int:
        """``scan_match_translation_search`` in whole cells of the coarsest level."""
        coarse = self.level_resolution(self.map_multi_res_levels - 1)
        return round(self.scan_match_translation_search / coarse)

    def level_size(self, level: int) -> int:
        """Cells per side of map level ``level``."""
        return self.map_size >> level


def _check(ok: bool, msg: str) -> None:
    if not ok:
        raise HectorParamsError(msg)
