"""The ``slam_toolbox`` / ``slam_karto`` node: a thin wrapper of
:class:`~roverlab.slam.graph.GraphSLAM`.

What slam_toolbox's ``async_slam_toolbox_node`` / ``sync_slam_toolbox_node`` (and ROS 1's
``slam_karto``) do, with their names:

* subscribes ``scan_topic`` (default ``/scan``, ``sensor_msgs/LaserScan``) through a TF
  message filter: a scan is processed once ``odom_frame <- scan frame`` is known at its
  stamp (up to ``scan_queue_size`` scans wait);
* the odometry pose is ``odom_frame -> base_frame`` at the scan's stamp, the laser's pose
  ``base_frame -> scan frame`` (beam directions rotated into the base frame, so an
  upside-down laser needs no special case);
* publishes ``map`` and ``map_metadata`` (latched) every ``map_update_interval`` seconds
  when the graph changed (a new keyframe or a loop closure), rendered from the optimised
  poses;
* broadcasts ``map_frame -> odom_frame`` every ``transform_publish_period`` seconds (0:
  never), the identity until the first scan.

The two slam_toolbox modes differ in what happens to scans that arrive while one is being
processed (a slow machine, or a bag played fast): the asynchronous node (:class:`SlamToolbox`)
keeps only the newest one and skips the rest, so the map keeps up with the robot; the
synchronous node (:class:`SyncSlamToolbox`, and ``slam_karto``) queues every scan and
processes them all in order, warning when the queue grows (offline-quality maps, at the
price of lagging behind). In a ``--rate max`` run simulated time waits for the nodes, so both
see every scan.

Parameters: every field of :class:`~roverlab.slam.graph.GraphParams` under its ROS name
and default, plus the node's ``scan_topic``, ``scan_queue_size`` and
``transform_publish_period`` (slam_toolbox's defaults).
"""

from __future__ import annotations

import dataclasses
from typing import Any

from roverlab.core import Context
from roverlab.geometry import Transform3
from roverlab.msgs import classes as mc
from roverlab.slam.graph.errors import GraphSlamInputError
from roverlab.slam.graph.params import GraphParams
from roverlab.slam.graph.slam import GraphSLAM
from roverlab.slam.node_common import SlamNode
from roverlab.tf import (
    TfMessageFilter,
    transform_to_msg,
)

__all__ = ["NODE_DEFAULTS", "SlamKarto", "SlamToolbox", "SyncSlamToolbox"]


#: The node-level parameters this node implements, with slam_toolbox's defaults.
NODE_DEFAULTS: dict[str, Any] = {
    "scan_topic": "/scan",
    "scan_queue_size": 5,
    "transform_publish_period": 0.02,
}

#: A synchronous node's bound on scans waiting to be processed (slam_toolbox's queue is
#: unbounded; this is a memory guard: about 20 minutes of a 10 Hz laser).
SYNC_QUEUE_LIMIT = 12_000
#: The synchronous node warns when more scans than this wait.
SYNC_QUEUE_WARN = 10


class SlamToolbox(SlamNode):
    """``slam_toolbox`` (asynchronous mapping): Karto-style graph SLAM, live.

    Args:
        context: the context the node joins.
        node_name: defaults to ``slam_toolbox``.
        **node_kwargs: ``namespace``, ``parameter_overrides`` (the launch file's or YAML's
            parameters), ``remappings`` of :class:`~roverlab.core.Node`.

    Attributes:
        params: the validated :class:`GraphParams`.
        slam: the algorithm (:class:`GraphSLAM`).
        map_msg: the last ``nav_msgs/OccupancyGrid`` published, or None.
        scans_processed: scans given to the algorithm.

    Raises:
        GraphSlamParamsError: a parameter of the wrong type or out of range.
        ParameterError: a parameter override that does not fit its declared type.
    """

    #: Default of ``base_frame`` for this node (slam_toolbox's).
    default_base_frame = "base_footprint"
    #: False: only the newest waiting scan is processed (slam_toolbox's asynchronous mode);
    #: True: every scan is, in order (its synchronous mode).
    synchronous = False

    def __init__(
        self, context: Context, *, node_name: str = "slam_toolbox", **node_kwargs: Any
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        algo: dict[str, Any] = {}
        for f in dataclasses.fields(GraphParams):
            default = self.default_base_frame if f.name == "base_frame" else f.default
            algo[f.name] = self.declare_parameter(f.name, default).value
        node = {k: self.declare_parameter(k, v).value for k, v in NODE_DEFAULTS.items()}
        if int(node["scan_queue_size"]) < 1:
            raise ValueError("scan_queue_size must be >= 1")
        self.params = GraphParams.from_ros(algo)
        p = self.params
        self.base_frame = p.base_frame.lstrip("/")
        self.odom_frame = p.odom_frame.lstrip("/")
        self.map_frame = p.map_frame.lstrip("/")
        self.slam = GraphSLAM(p)
        self.scans_processed = 0
        self._published_state: tuple[int, int] | None = None
        self._setup_map_io()
        queue = int(node["scan_queue_size"])
        self.scan_filter = TfMessageFilter(
            self, self.tf_buffer, [self.odom_frame], queue, self._on_scan
        )
        depth = SYNC_QUEUE_LIMIT if self.synchronous else 1
        self.scan_subscription = self.create_subscription(
            mc.LaserScan, str(node["scan_topic"]), self._on_scan_message, depth
        )
        self.create_timer(p.map_update_interval, self.publish_map)
        period = float(node["transform_publish_period"])
        if period > 0.0:
            self.create_timer(period, self._publish_transform)

    # ------------------------------------------------------------------ scans
    def _on_scan_message(self, scan: Any) -> None:
        if self.synchronous:
            waiting = self.scan_subscription.pending
            if waiting > SYNC_QUEUE_WARN:
                self._throttle.warning(
                    "queue",
                    f"{waiting} scans wait to be processed: the map lags behind the robot "
                    "(the asynchronous node skips to the newest scan instead)",
                )
        self.scan_filter.add(scan)

    def _on_scan(self, scan: Any) -> None:
        inputs = self._scan_inputs(scan, self.base_frame, self.odom_frame)
        if inputs is None:
            return
        ok, _ = self._process_scan(self.slam.process, scan, inputs, GraphSlamInputError)
        if not ok:
            return
        self.scans_processed += 1
        self._map_to_odom = Transform3.from_se2(self.slam.map_to_odom())
        if self._published_state is None:
            self.publish_map()  # the first map as soon as there is one

    # ------------------------------------------------------------------ map and TF
    def publish_map(self) -> None:
        """Publish ``map`` and ``map_metadata`` if the graph changed since the last map."""
        if self.slam.num_keyframes == 0:
            return
        state = (self.slam.num_keyframes, self.slam.optimisations)
        if state == self._published_state:
            return
        self._published_state = state
        self._publish_map_msg(self._grid_msg(self.slam.occupancy(), self.map_frame))

    def _publish_transform(self) -> None:
        self.tf_broadcaster.send_transform(
            transform_to_msg(
                self.map_frame, self.odom_frame, self.get_clock().now(), self._map_to_odom
            )
        )


class SyncSlamToolbox(SlamToolbox):
    """``sync_slam_toolbox_node``: the same mapper, processing every scan in order."""

    synchronous = True


class SlamKarto(SlamToolbox):
    """ROS 1 ``slam_karto``: the same mapper under slam_karto's node name and base frame;
    like Karto's node it processes every scan (synchronous)."""

    default_base_frame = "base_link"
    synchronous = True

    def __init__(self, context: Context, *, node_name: str = "slam_karto", **node_kwargs: Any):
        super().__init__(context, node_name=node_name, **node_kwargs)
