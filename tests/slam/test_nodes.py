"""The ``slam_gmapping`` and ``hector_mapping`` nodes: topics, TF, parameters, the TF message
filter, reset, seeding, and their launch-registry entries (the seed 000 launch files)."""

from __future__ import annotations

import dataclasses
import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context, Node, ServiceError, Time
from roverlab.geometry import SE2, Transform3
from roverlab.launch import LaunchError, build_launch
from roverlab.msgs import String, Twist, make_scan, xytheta_from_pose
from roverlab.msgs import classes as mc
from roverlab.raycast import Scene, cast_2d
from roverlab.sim.app import Simulation
from roverlab.sim.node import SpawnPose
from roverlab.slam.data.mapquality import MapQuality, evaluate_map, grid_from_msg, ground_truth
from roverlab.slam.gmapping import GMappingParams
from roverlab.slam.gmapping.node import SlamGMapping
from roverlab.slam.graph.node import SlamToolbox
from roverlab.slam.hector import HectorParams
from roverlab.slam.hector.node import NODE_DEFAULTS, HectorMapping
from roverlab.slam.laser import laser_geometry
from roverlab.tf import (
    Buffer,
    StaticTransformBroadcaster,
    TransformBroadcaster,
    TransformListener,
    transform_to_msg,
)
from roverlab.world.yaml_world import world_from_dict
from tests.helpers.nodes import collect

FIXTURES = Path(__file__).parent / "fixtures"
ROOM = {
    "name": "room",
    "walls": [{"points": [[-3, -2], [3, -2], [3, 2], [-3, 2]], "closed": True}],
    "boxes": [{"center": [1.2, 0.8], "size": [0.5, 0.5, 1.0]}],
}
# the seed's gmapping parameters, cheaper: fewer particles, faster map updates
FAST_GMAPPING = {"particles": 8, "map_update_interval": 1.0, "base_frame": "base_footprint"}


def _room() -> Any:
    return world_from_dict(ROOM, source=Path("room.yaml"))


def _room_map_quality(msg: Any, sim: Simulation) -> MapQuality:
    """The map scored against the room's ground truth at the lidar's height (the map
    frame is the world frame: the odometry is the world pose here)."""
    z = float(sim.config.lidars[0].mount.translation[2])
    gt = ground_truth(sim.world_model, resolution=float(msg.info.resolution), z_m=max(z, 0.01))
    return evaluate_map(grid_from_msg(msg), gt)


def _drive(ctx: Context, steps: list[tuple[float, float, float]]) -> None:
    cmd = ctx.create_node("driver").create_publisher(Twist, "/cmd_vel", 1)
    for v, w, secs in steps:
        cmd.publish(Twist(linear_x=v, angular_z=w))
        ctx.spin_for(secs)
    cmd.publish(Twist())


# ------------------------------------------------------------------------ slam_gmapping
def test_gmapping_node_in_the_simulator() -> None:
    ctx = Context()
    sim = Simulation(
        context=ctx, world=_room(), robot="mybot", cameras=False, spawn=SpawnPose(-1.0, 0.0, 0.0)
    )
    node = SlamGMapping(ctx, parameter_overrides=FAST_GMAPPING)
    got = collect(
        ctx,
        {
            "/map_metadata": mc.MapMetaData,
            "/slam_gmapping/entropy": mc.Float64,
            "/tf": mc.TFMessage,
        },
    )
    buf = Buffer()
    TransformListener(buf, ctx.create_node("listener"))
    _drive(ctx, [(0.0, 0.6, 6.0), (0.25, 0.0, 4.0), (0.0, -0.6, 3.0), (0.2, 0.1, 3.0)])
    assert node.scans_processed >= 8 and node.scan_filter.dropped == 0
    # map_update_interval: maps at least 1 s of scan time apart
    stamps = [Time.from_msg(m.map_load_time).seconds for m in got["/map_metadata"]]
    assert len(stamps) >= 4 and min(np.diff(stamps)) >= 1.0
    # late subscribers get the latched map
    late: list[Any] = []
    ctx.create_node("late").create_subscription(mc.OccupancyGrid, "/map", late.append, 1)
    ctx.spin_for(0.01)
    assert len(late) == 1 and late[0].header.frame_id == "map"
    assert late[0].info.resolution == pytest.approx(0.05)
    q = _room_map_quality(late[0], sim)
    assert q.accuracy >= 0.95 and q.wall_distance_p95 <= 1.0, q.summary()
    assert q.occupied_cells > 100 and q.coverage > 0.5, q.summary()
    # entropy of 8 weights: in [0, log 8]
    ent = [m.data for m in got["/slam_gmapping/entropy"]]
    assert len(ent) == len(stamps) and all(0.0 <= e <= math.log(8) + 1e-9 for e in ent)
    # map -> odom every transform_publish_period (0.05 s), future-dated by tf_delay
    map_odom = [t for m in got["/tf"] for t in m.transforms if t.header.frame_id == "map"]
    assert all(t.child_frame_id == "odom" for t in map_odom)
    assert abs(len(map_odom) - ctx.now().seconds / 0.05) <= 2
    # the estimate matches the truth (odometry is the world pose here, so map ~ world)
    tf, _ = buf.lookup_transform("map", "base_footprint", Time(0))
    est = tf.to_se2()
    assert math.hypot(est.x - sim.simulator.x, est.y - sim.simulator.y) < 0.05
    assert abs(est.theta - sim.simulator.yaw) < 0.03


def test_gmapping_parameters_have_the_ros_names_and_defaults() -> None:
    ctx = Context()
    node = SlamGMapping(ctx)
    for f in dataclasses.fields(GMappingParams):
        assert node.get_parameter(f.name).value == f.default
    assert node.params == GMappingParams()
    assert node.get_parameter("seed").value == 0
    other = SlamGMapping(
        ctx,
        node_name="other",
        parameter_overrides={"maxRange": 5, "particles": 12, "tf_delay": 0.1},
    )
    assert other.params.maxRange == 5.0 and other.params.particles == 12
    assert other.params.tf_delay == pytest.approx(0.1)


class FakeRobot(Node):
    """A robot standing at ``pose`` in a room: scans at 10 Hz, TF only when switched on."""

    def __init__(self, ctx: Context, pose: SE2, *, base: str = "base_link", odom: bool = True):
        super().__init__("fake_robot", context=ctx)
        self.scene: Scene = _room().to_scene()
        self.pose = pose
        self.base = base
        self.odom = odom
        self.tf_on = False
        self.scan_pub = self.create_publisher(mc.LaserScan, "/scan", 10)
        self.tf = TransformBroadcaster(self)
        self.static = StaticTransformBroadcaster(self)
        self.create_timer(0.1, self._tick)
        self.create_timer(0.02, self._tf_tick)

    def start_tf(self) -> None:
        self.tf_on = True
        laser = Transform3((0.1, 0.0, 0.2), (0.0, 0.0, 0.0, 1.0))
        self.static.send_transform(transform_to_msg(self.base, "laser", Time(0), laser))

    def _tf_tick(self) -> None:
        if self.tf_on and self.odom:
            now = self.get_clock().now()
            self.tf.send_transform(
                transform_to_msg("odom", self.base, now, Transform3.from_se2(self.pose))
            )

    def _tick(self) -> None:
        p = self.pose
        lx, ly = p.x + 0.1 * math.cos(p.theta), p.y + 0.1 * math.sin(p.theta)
        angles = np.linspace(-math.pi, math.pi, 361)[:-1]
        ranges = cast_2d(self.scene, lx, ly, 0.2, angles + p.theta, 10.0)
        self.scan_pub.publish(
            make_scan(
                ranges,
                angle_min=-math.pi,
                angle_max=math.pi - 2 * math.pi / 360,
                range_min=0.1,
                range_max=10.0,
                frame_id="laser",
                stamp=self.get_clock().now(),
            )
        )


def test_gmapping_waits_for_tf_and_drops_with_a_warning(caplog: pytest.LogCaptureFixture) -> None:
    ctx = Context()
    robot = FakeRobot(ctx, SE2(-0.5, 0.2, 0.3))
    node = SlamGMapping(ctx, parameter_overrides={"particles": 4, "temporalUpdate": 0.5})
    dynamic_map = ctx.create_node("caller").create_client("nav_msgs/GetMap", "dynamic_map")
    with pytest.raises(ServiceError, match="no map has been built yet"):
        dynamic_map.call({})
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        ctx.spin_for(1.05)  # ten scans, no TF: five wait, the rest are dropped
        assert node.scans_received == 0 and node.scan_filter.waiting == 5
        assert node.scan_filter.dropped == 5
        # tf2_ros says nothing in the first 15 s (a TF buffer filling at start drops a few)
        assert not [r for r in caplog.records if "MessageFilter" in r.message]
        ctx.spin_for(15.0)
    warnings = [r.message for r in caplog.records if "MessageFilter [target=odom]" in r.message]
    assert len(warnings) == 1 and "dropped 100.00%" in warnings[0]  # then once a minute
    assert "queue is full" in warnings[0]
    robot.start_tf()
    ctx.spin_for(2.0)
    # the waiting scans are older than the first TF: dropped; the new ones go through
    assert node.scans_received >= 15 and node.map_msg is not None
    assert node.scans_processed >= 4  # temporalUpdate 0.5 s
    assert dynamic_map.call({}).map is node.map_msg  # the dynamic_map service
    # the first scan placed the map at the odometry frame's origin: map -> odom = identity
    tf = node.map_to_odom.to_se2()
    assert math.hypot(tf.x, tf.y) < 0.03 and abs(tf.theta) < 0.02


def _gmapping_run(seed: int) -> tuple[bytes, SE2]:
    ctx = Context()
    Simulation(context=ctx, world=_room(), robot="mybot", cameras=False, seed=1)
    node = SlamGMapping(ctx, parameter_overrides={**FAST_GMAPPING, "seed": seed})
    _drive(ctx, [(0.0, 0.6, 3.0), (0.25, 0.0, 3.0)])
    assert node.map_msg is not None
    return bytes(np.asarray(node.map_msg.data)), node.slam.best_particle().pose


def test_gmapping_seeded_runs_reproduce() -> None:
    a, b, c = _gmapping_run(3), _gmapping_run(3), _gmapping_run(4)
    assert a == b
    assert a[1] != c[1]


def test_laser_geometry_upright_and_upside_down() -> None:
    scan = make_scan(np.ones(5), angle_min=-1.0, angle_max=1.0, range_min=0.1, range_max=5.0)
    up = laser_geometry(
        scan, Transform3((0.2, -0.1, 0.3), (0.0, 0.0, math.sin(0.25), math.cos(0.25)))
    )
    assert not up.upside_down and up.z_m == pytest.approx(0.3)
    assert (up.offset.x, up.offset.y, up.offset.theta) == pytest.approx((0.2, -0.1, 0.0))
    assert up.angles == pytest.approx(np.linspace(-1.0, 1.0, 5) + 0.5)
    # rolled by pi: beams sweep the other way
    down = laser_geometry(scan, Transform3((0.0, 0.0, 0.3), (1.0, 0.0, 0.0, 0.0)))
    assert down.upside_down
    assert down.angles == pytest.approx(-np.linspace(-1.0, 1.0, 5))


# ------------------------------------------------------------------------ hector_mapping
# seed 000's hector.launch update parameters, with a smaller map and faster publishing
SEED_HECTOR = {
    "base_frame": "base_footprint",
    "odom_frame": "odom",
    "map_pub_period": 1.0,
    "map_resolution": 0.05,
    "map_size": 512,
    "map_multi_res_levels": 2,
    "laser_max_dist": 5.5,
    "update_factor_occupied": 0.7,
    "map_update_distance_thresh": 0.2,
    "map_update_angle_thresh": 0.06,
}


def test_hector_node_in_the_simulator() -> None:
    ctx = Context()
    sim = Simulation(
        context=ctx, world=_room(), robot="mybot", cameras=False, spawn=SpawnPose(-1.0, 0.0, 0.0)
    )
    node = HectorMapping(
        ctx,
        parameter_overrides=SEED_HECTOR,
    )
    got = collect(
        ctx,
        {
            "/slam_out_pose": mc.PoseStamped,
            "/poseupdate": mc.PoseWithCovarianceStamped,
            "/map": mc.OccupancyGrid,
        },
    )
    buf = Buffer()
    TransformListener(buf, ctx.create_node("listener"))
    # stand still first: hector's map frame is the pose at the first scan
    _drive(ctx, [(0.0, 0.0, 0.5), (0.0, 0.5, 4.0), (0.25, 0.0, 4.0)])
    n = node.scans_processed
    assert n >= 50 and len(got["/slam_out_pose"]) == n == len(got["/poseupdate"])
    last = got["/poseupdate"][-1]
    assert last.header.frame_id == "map"
    cov = np.asarray(last.pose.covariance).reshape(6, 6)
    assert cov[0, 0] > 0 and cov[5, 5] > 0 and np.allclose(cov, cov.T)
    # a map every map_pub_period (1 s) when it changed
    stamps = [Time.from_msg(m.header.stamp).seconds for m in got["/map"]]
    assert len(stamps) >= 3 and min(np.diff(stamps)) >= 1.0 - 1e-9
    assert got["/map"][-1].info.width == 512
    # map -> odom makes map -> base_footprint the estimate; the map frame is the start pose
    tf, _ = buf.lookup_transform("map", "base_footprint", Time.from_msg(last.header.stamp))
    x, y, _ = xytheta_from_pose(last.pose.pose)
    assert tf.to_se2().x == pytest.approx(x, abs=1e-6) and tf.to_se2().y == pytest.approx(
        y, abs=1e-6
    )
    start = SE2(-1.0, 0.0, 0.0)
    rel = ~start * SE2(sim.simulator.x, sim.simulator.y, sim.simulator.yaw)
    assert math.hypot(node.pose.x - rel.x, node.pose.y - rel.y) < 0.05
    assert abs(node.pose.theta - rel.theta) < 0.02
    scanmatch, _ = buf.lookup_transform("map", "scanmatcher_frame", Time(0))
    assert scanmatch.to_se2().x == pytest.approx(node.pose.x, abs=1e-6)
    # syscommand reset: the map and the pose start again
    ctx.create_node("cmd").create_publisher(String, "/syscommand", 2).publish(String(data="reset"))
    ctx.spin_for(0.05)
    assert node.slam.map_updates <= 1
    ctx.spin_for(1.5)
    assert abs(node.pose.x) < 0.1 and abs(node.pose.y) < 0.1  # standing still since the reset


def test_hector_without_odometry_publishes_map_to_base(caplog: pytest.LogCaptureFixture) -> None:
    ctx = Context()
    robot = FakeRobot(ctx, SE2(0.3, -0.4, 0.2), base="base_link", odom=False)
    node = HectorMapping(ctx, parameter_overrides={"odom_frame": "base_link", "map_size": 512})
    buf = Buffer()
    TransformListener(buf, ctx.create_node("listener"))
    with caplog.at_level(logging.INFO, logger="roverlab"):
        ctx.spin_for(1.0)  # no laser transform: each scan waits 0.5 s, then is dropped
    assert node.scans_processed == 0
    msgs = [r.message for r in caplog.records if "Could not transform laser scan" in r.message]
    assert len(msgs) == 5 and msgs[0].startswith("lookupTransform base_link to laser timed out")
    robot.start_tf()
    ctx.spin_for(1.0)
    assert node.scans_processed >= 9
    tf, _ = buf.lookup_transform("map", "base_link", Time(0))
    assert tf.to_se2().x == pytest.approx(node.pose.x, abs=1e-9)
    assert math.hypot(node.pose.x, node.pose.y) < 0.03  # standing still at the map origin


def test_hector_without_tf_scan_transformation() -> None:
    ctx = Context()
    FakeRobot(ctx, SE2(0.0, 0.0, 0.0), odom=False)
    node = HectorMapping(
        ctx,
        parameter_overrides={
            "use_tf_scan_transformation": False,
            "pub_map_odom_transform": False,
            "map_size": 512,
        },
    )
    got = collect(ctx, {"/tf": mc.TFMessage})
    ctx.spin_for(1.0)
    assert node.scan_filter is None and node.scans_processed == 10
    frames = {t.child_frame_id for m in got["/tf"] for t in m.transforms}
    assert frames == {"scanmatcher_frame"}


def test_hector_parameters_have_the_ros_names_and_defaults() -> None:
    ctx = Context()
    node = HectorMapping(ctx)
    for f in dataclasses.fields(HectorParams):
        assert node.get_parameter(f.name).value == f.default
    for name, value in NODE_DEFAULTS.items():
        assert node.get_parameter(name).value == value
    assert node.params == HectorParams()
    with_start = HectorMapping(
        ctx, node_name="h2", parameter_overrides={"use_tf_pose_start_estimate": True}
    )
    assert with_start.params.use_odometry


# ------------------------------------------------------------------------ launch registry
def test_seed_launch_files_start_the_nodes() -> None:
    ctx = Context()
    gm = build_launch(FIXTURES / "gmapping.launch", context=ctx)
    assert [n.get_name() for n in gm.nodes] == ["slam_gmapping"] and gm.warnings == []
    node = gm.nodes[0]
    assert isinstance(node, SlamGMapping)
    assert node.params.particles == 80 and node.params.maxRange == 5.0
    assert node.params.srr == 0.01 and node.params.linearUpdate == 0.5
    ctx2 = Context()
    hec = build_launch(FIXTURES / "hector.launch", context=ctx2)
    node2 = hec.nodes[0]
    assert isinstance(node2, HectorMapping)
    assert node2.params.map_size == 2048 and node2.params.map_multi_res_levels == 2
    assert node2.params.update_factor_occupied == 0.7 and node2.base_frame == "base_footprint"
    (warning,) = hec.warnings
    assert "hector.launch" in warning and "output_timing" in warning
    assert "advertise_map_service" not in warning
    assert "/dynamic_map" in ctx2.graph.services


def test_bad_and_unknown_launch_params(tmp_path: Path) -> None:
    bad = tmp_path / "bad.launch"
    bad.write_text(
        '<launch><node pkg="gmapping" type="slam_gmapping" name="slam_gmapping">'
        '<param name="particles" value="0"/></node></launch>'
    )
    with pytest.raises(LaunchError, match=r"bad.launch.*particles must be >= 1"):
        build_launch(bad, context=Context())
    odd = tmp_path / "odd.launch"
    odd.write_text(
        '<launch><node pkg="hector_mapping" type="hector_mapping" name="hm">'
        '<param name="map_sise" value="512"/><param name="pub_drawings" value="true"/>'
        "</node></launch>"
    )
    launch = build_launch(odd, context=Context())
    assert len(launch.warnings) == 1 and "map_sise, pub_drawings" in launch.warnings[0]


@pytest.mark.parametrize(
    ("node_type", "expected"),
    [("async_slam_toolbox_node", 1), ("sync_slam_toolbox_node", 6)],
)
def test_slam_toolbox_async_takes_the_newest_scan_sync_takes_all(
    node_type: str, expected: int, caplog: pytest.LogCaptureFixture, tmp_path: Path
) -> None:
    """Six scans arrive while the mapper is busy: the asynchronous node processes only the
    newest, the synchronous one all six in order (slam_toolbox's two modes)."""
    ctx = Context()
    robot = FakeRobot(ctx, SE2(-0.5, 0.2, 0.3), base="base_footprint")
    robot.start_tf()
    launch = tmp_path / "slam.launch"
    launch.write_text(f'<launch><node pkg="slam_toolbox" type="{node_type}" name="st"/></launch>')
    (node,) = build_launch(launch, context=ctx).nodes
    assert isinstance(node, SlamToolbox) and node.synchronous == (expected > 1)
    ctx.spin_for(0.55)
    assert node.scans_processed >= 4
    robot.destroy_timer(robot.timers[0])  # no more scans from the robot's own timer
    stamps: list[float] = []
    process = node.slam.process

    def spy(*args: Any, **kwargs: Any) -> Any:
        stamps.append(args[3])
        return process(*args, **kwargs)

    node.slam.process = spy  # type: ignore[method-assign]
    now = robot.get_clock().now().nanoseconds / 1e9
    burst = [round(now - 0.01 * k, 6) for k in range(6, 0, -1)]
    angles = np.linspace(-math.pi, math.pi, 361)[:-1]
    for t in burst:  # published back to back: the executor does not run in between
        robot.scan_pub.publish(
            make_scan(
                np.full(angles.size, 2.0),
                angle_min=-math.pi,
                angle_max=math.pi - 2 * math.pi / 360,
                range_min=0.1,
                range_max=10.0,
                frame_id="laser",
                stamp=Time.from_seconds(t),
            )
        )
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        ctx.spin_for(0.05)
    assert len(stamps) == expected
    assert stamps == pytest.approx(burst[-expected:], abs=1e-6)
