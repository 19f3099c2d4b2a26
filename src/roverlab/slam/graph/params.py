"""Parameters of the graph SLAM (slam_karto / slam_toolbox names and defaults).

Every field carries the ROS parameter name that slam_toolbox (and, for most, slam_karto)
reads, with slam_toolbox's default except for the four match-acceptance thresholds
(``link_match_minimum_response_fine`` 0.8, ``loop_match_minimum_response_coarse`` 0.7,
``loop_match_minimum_response_fine`` 0.7, ``loop_match_maximum_variance_coarse`` 0.16 =
0.4^2), which follow open_karto's stricter ``Mapper`` defaults: with slam_toolbox's
permissive values (0.1, 0.35, 0.45, 3.0) the Intel log gets wrong near-chain links and
loop closures. Parameters that only concern a running
node's plumbing (topics, TF timing, the solver plugin's Ceres options, interactive mode) are
listed in :data:`NODE_PARAMETERS`, so a whole slam_toolbox / slam_karto ``<param>`` set can be
passed to :meth:`GraphParams.from_ros`; any other unknown name is an error.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from roverlab.slam.common import params_from_ros
from roverlab.slam.graph.errors import GraphSlamParamsError

__all__ = ["NODE_PARAMETERS", "GraphParams"]

#: slam_toolbox / slam_karto parameters that belong to the node, not the algorithm.
NODE_PARAMETERS = frozenset(
    {
        "scan_topic",
        "scan_queue_size",
        "mode",
        "debug_logging",
        "throttle_scans",
        "transform_publish_period",
        "transform_timeout",
        "tf_buffer_duration",
        "stack_size_to_use",
        "enable_interactive_mode",
        "use_sim_time",
        "map_name",
        "map_file_name",
        "map_start_pose",
        "map_start_at_dock",
        "use_map_saver",
        "position_covariance_scale",
        "yaw_covariance_scale",
        "solver_plugin",
        "ceres_linear_solver",
        "ceres_preconditioner",
        "ceres_trust_strategy",
        "ceres_dogleg_type",
        "ceres_loss_function",
        "ceres_num_threads",
        "use_scan_barycenter",
        "minimum_time_interval",
    }
)


@dataclass(frozen=True, slots=True, kw_only=True)
class GraphParams:
    """Algorithm parameters (ROS names, SI units: metres, radians, seconds).

    Attributes:
        resolution: cell size of the published occupancy map (m).
        max_laser_range: readings beyond this are not matched; in the map they clear free
            space up to this range and mark no obstacle (m).
        min_laser_range: readings below this are dropped (m).
        use_scan_matching: correct odometry by scan matching (False: map with odometry).
        minimum_travel_distance: a scan becomes a graph vertex (a keyframe) once the
            odometry moved this far since the last keyframe ... (m)
        minimum_travel_heading: ... or turned this much (rad).
        scan_buffer_size: keyframes kept in the running buffer that new scans are matched
            against.
        scan_buffer_maximum_scan_distance: buffer keyframes farther than this from the
            newest one are dropped (m).
        link_match_minimum_response_fine: a near chain (an older part of the trajectory
            within ``link_scan_maximum_distance`` and linked through the graph) gives an
            edge when its match response exceeds this.
        link_scan_maximum_distance: reach of the near-chain search (m).
        loop_search_maximum_distance: older keyframes within this distance of the new one,
            not linked to it through the graph within that distance, are loop candidates (m).
        do_loop_closing: search for loop closures.
        loop_match_minimum_chain_size: a candidate chain (consecutive keyframes) needs this
            many keyframes; near chains too.
        loop_match_maximum_variance_coarse: the coarse loop match is rejected when its x or
            y variance exceeds this (m^2).
        loop_match_minimum_response_coarse: ... or its response is below this.
        loop_match_minimum_response_fine: the fine loop match must reach this response.
        correlation_search_space_dimension: side of the square searched by the sequential
            matcher around the prediction (m).
        correlation_search_space_resolution: its step, and the cell size of its
            correlation grid (m).
        correlation_search_space_smear_deviation: standard deviation of the Gaussian that
            smears the points of the correlation grid (m).
        loop_search_space_dimension: the same three for the coarse loop-closure matcher.
        loop_search_space_resolution: see above (m).
        loop_search_space_smear_deviation: see above (m).
        distance_variance_penalty: variance of the sequential matcher's penalty for moving
            away from the odometry prediction; a pose ``d`` away scores
            ``max(1 - 0.2 d^2 / distance_variance_penalty, minimum_distance_penalty)`` times
            its response (m^2).
        angle_variance_penalty: the same for the heading (rad^2).
        fine_search_angle_offset: heading step of the fine search (rad), which spans
            ``+- coarse_angle_resolution / 2`` around the coarse result.
        coarse_search_angle_offset: half-width of the coarse heading search (rad).
        coarse_angle_resolution: heading step of the coarse search (rad).
        minimum_angle_penalty: lower bound of the heading penalty factor.
        minimum_distance_penalty: lower bound of the distance penalty factor.
        use_response_expansion: when a match finds no response at all, widen the heading
            search by 20 degrees, up to three times.
        map_update_interval: the node re-renders and publishes the map this often (s).
        base_frame: the robot frame.
        odom_frame: the odometry frame.
        map_frame: the map frame.
        scan_match_refinement: (roverlab) after the lattice search, refine the pose by a
            sub-cell Gauss-Newton step on the bilinearly interpolated correlation grid.
        loop_closure_max_residual: (roverlab) consistency check: a loop-closure edge whose
            translational residual after optimisation exceeds this is removed and the graph
            re-optimised without it (m); 0 turns the check off.
        map_scans: (roverlab) which scans the occupancy map is rendered from:
            ``"keyframes"`` (Karto: the graph's vertices) or ``"all"`` (every scan, at its
            final pose).
        degenerate_eigen_ratio: (roverlab) a scan whose surface normals' information has
            an eigenvalue ratio below this (a bare corridor:
            :func:`roverlab.slam.degeneracy.scan_constraint`) cannot fix the robot along its
            weak direction: there the sequential and near-chain matches keep the odometry's
            position, their edges are loose along it (``degenerate_variance``), and the scan
            closes no loop. 0 turns it off (Karto's behaviour: the match stalls).
        degenerate_variance: (roverlab) variance added along the weak direction to the
            edges of a degenerate scan (m^2).
    """

    resolution: float = 0.05
    max_laser_range: float = 20.0
    min_laser_range: float = 0.0
    use_scan_matching: bool = True
    minimum_travel_distance: float = 0.5
    minimum_travel_heading: float = 0.5
    scan_buffer_size: int = 10
    scan_buffer_maximum_scan_distance: float = 10.0
    link_match_minimum_response_fine: float = 0.8
    link_scan_maximum_distance: float = 1.5
    loop_search_maximum_distance: float = 3.0
    do_loop_closing: bool = True
    loop_match_minimum_chain_size: int = 10
    loop_match_maximum_variance_coarse: float = 0.16
    loop_match_minimum_response_coarse: float = 0.7
    loop_match_minimum_response_fine: float = 0.7
    correlation_search_space_dimension: float = 0.5
    correlation_search_space_resolution: float = 0.01
    correlation_search_space_smear_deviation: float = 0.1
    loop_search_space_dimension: float = 8.0
    loop_search_space_resolution: float = 0.05
    loop_search_space_smear_deviation: float = 0.03
    distance_variance_penalty: float = 0.5
    angle_variance_penalty: float = 1.0
    fine_search_angle_offset: float = 0.00349
    coarse_search_angle_offset: float = 0.349
    coarse_angle_resolution: float = 0.0349
    minimum_angle_penalty: float = 0.9
    minimum_distance_penalty: float = 0.5
    use_response_expansion: bool = True
    map_update_interval: float = 5.0
    base_frame: str = "base_footprint"
    odom_frame: str = "odom"
    map_frame: str = "map"
    scan_match_refinement: bool = True
    loop_closure_max_residual: float = 0.3
    map_scans: str = "keyframes"
    degenerate_eigen_ratio: float = 0.05
    degenerate_variance: float = 0.01

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.type in ("bool", bool):
                if not isinstance(value, bool):
                    raise GraphSlamParamsError(f"{f.name} must be a bool, got {value!r}")
            elif f.type in ("str", str):
                if not isinstance(value, str) or not value:
                    raise GraphSlamParamsError(
                        f"{f.name} must be a non-empty string, got {value!r}"
                    )
            elif f.type in ("int", int):
                if isinstance(value, bool) or not isinstance(value, int):
                    raise GraphSlamParamsError(f"{f.name} must be an int, got {value!r}")
            else:
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise GraphSlamParamsError(f"{f.name} must be a number, got {value!r}")
                if not math.isfinite(value):
                    raise GraphSlamParamsError(f"{f.name} must be finite, got {value!r}")
        positive = (
            "resolution",
            "max_laser_range",
            "correlation_search_space_dimension",
            "correlation_search_space_resolution",
            "correlation_search_space_smear_deviation",
            "loop_search_space_dimension",
            "loop_search_space_resolution",
            "loop_search_space_smear_deviation",
            "distance_variance_penalty",
            "angle_variance_penalty",
            "fine_search_angle_offset",
            "coarse_angle_resolution",
            "map_update_interval",
        )
        for name in positive:
            _check(getattr(self, name) > 0.0, f"{name} must be > 0, got {getattr(self, name)}")
        non_negative = (
            "min_laser_range",
            "minimum_travel_distance",
            "minimum_travel_heading",
            "scan_buffer_maximum_scan_distance",
            "link_scan_maximum_distance",
            "loop_search_maximum_distance",
            "loop_match_maximum_variance_coarse",
            "coarse_search_angle_offset",
            "loop_closure_max_residual",
            "degenerate_variance",
        )
        for name in non_negative:
            _check(getattr(self, name) >= 0.0, f"{name} must be >= 0, got {getattr(self, name)}")
        _check(
            self.max_laser_range > self.min_laser_range,
            "max_laser_range must be > min_laser_range",
        )
        _check(self.scan_buffer_size >= 1, "scan_buffer_size must be >= 1")
        _check(
            self.loop_match_minimum_chain_size >= 1, "loop_match_minimum_chain_size must be >= 1"
        )
        for name in (
            "link_match_minimum_response_fine",
            "loop_match_minimum_response_coarse",
            "loop_match_minimum_response_fine",
            "minimum_angle_penalty",
            "minimum_distance_penalty",
        ):
            _check(0.0 <= getattr(self, name) <= 1.0, f"{name} must be in [0, 1]")
        _check(0.0 <= self.degenerate_eigen_ratio < 1.0, "degenerate_eigen_ratio must be in [0, 1)")
        _check(
            self.coarse_search_angle_offset <= math.pi, "coarse_search_angle_offset must be <= pi"
        )
        _check(
            self.correlation_search_space_dimension >= self.correlation_search_space_resolution,
            "correlation_search_space_dimension must be >= correlation_search_space_resolution",
        )
        _check(
            self.loop_search_space_dimension >= self.loop_search_space_resolution,
            "loop_search_space_dimension must be >= loop_search_space_resolution",
        )
        _check(
            self.correlation_search_space_dimension / self.correlation_search_space_resolution
            <= 2000,
            "correlation_search_space_dimension / correlation_search_space_resolution must be "
            "<= 2000 cells",
        )
        _check(
            self.loop_search_space_dimension / self.loop_search_space_resolution <= 2000,
            "loop_search_space_dimension / loop_search_space_resolution must be <= 2000 cells",
        )
        _check(
            self.coarse_search_angle_offset / self.coarse_angle_resolution <= 1000,
            "coarse_search_angle_offset / coarse_angle_resolution must be <= 1000",
        )
        _check(
            self.map_scans in ("keyframes", "all"),
            f"map_scans must be 'keyframes' or 'all', not {self.map_scans!r}",
        )

    @classmethod
    def from_ros(cls, params: Mapping[str, Any]) -> GraphParams:
        """Build from a slam_toolbox / slam_karto ``<param>`` set (ROS names).

        Integers given for float parameters are accepted (``value="2"``); node-level names
        (:data:`NODE_PARAMETERS`) are ignored; anything else unknown is an error.

        Raises:
            GraphSlamParamsError: an unknown name or a bad value.
        """
        return params_from_ros(
            cls,
            params,
            ignored=NODE_PARAMETERS,
            unknown=lambda name: GraphSlamParamsError(
                f"unknown slam_toolbox/slam_karto parameter {name!r}"
            ),
        )


def _check(ok: bool, msg: str) -> None:
    if not ok:
        raise GraphSlamParamsError(msg)
