"""The ``amcl`` node: map from static_map or the map topic, scans through TF, amcl_pose,
particlecloud, map -> odom, initialpose, services, saved pose, bad input, launch files."""

from __future__ import annotations

import itertools
import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context, Node, QoSProfile, Time
from roverlab.geometry import SE2, Transform3, quat_from_rpy
from roverlab.launch import LaunchError, build_launch
from roverlab.localization.amcl import AmclParams
from roverlab.localization.amcl.node import AmclNode
from roverlab.maps import save_map
from roverlab.maps.node import MapServer
from roverlab.msgs import (
    PoseWithCovarianceStamped,
    array_to_occupancy_grid,
    make_scan,
    pose_from_xytheta,
    stamp_to_msg,
    xytheta_from_pose,
)
from roverlab.msgs import classes as mc
from roverlab.tf import StaticTransformBroadcaster, TransformBroadcaster, transform_to_msg
from tests.helpers.nodes import collect
from tests.localization.amcl.helpers import BEARINGS, ORIGIN, RES, room_grid, scan_at

START = SE2(2.0, 1.5, 0.3)  # the robot in the map frame


class FakeRobot(Node):
    """Odometry (odom -> base_link at 50 Hz) and 360-beam scans (10 Hz) of a robot in the
    room; ``odom_from_map`` is where the odometry frame starts in the map."""

    def __init__(self, ctx: Context, *, laser_frame: str = "laser", tf: bool = True,
                 upside_down: bool = False) -> None:  # fmt: skip
        super().__init__("fake_robot", context=ctx)
        self.truth = START
        self.odom_from_map = SE2(-1.0, 0.5, -0.2)
        self.laser_frame = laser_frame
        self.upside_down = upside_down
        self.nan_scans = False
        self.scan_pub = self.create_publisher(mc.LaserScan, "/scan", 10)
        self.tf = TransformBroadcaster(self)
        if tf:
            q = quat_from_rpy(math.pi, 0.0, 0.0) if upside_down else (0.0, 0.0, 0.0, 1.0)
            StaticTransformBroadcaster(self).send_transform(
                transform_to_msg("base_link", "laser", Time(0), Transform3((0.0, 0.0, 0.2), q))
            )
            self.create_timer(0.02, self._tf_tick)
        self.create_timer(0.1, self._scan_tick)

    @property
    def odom(self) -> SE2:
        return self.odom_from_map * self.truth

    def _tf_tick(self) -> None:
        now = self.get_clock().now()
        self.tf.send_transform(
            transform_to_msg("odom", "base_link", now, Transform3.from_se2(self.odom))
        )

    def _scan_tick(self) -> None:
        r = scan_at(self.truth, rng=np.random.default_rng(len(self.scan_pub.topic.name)),
                    noise=0.005)  # fmt: skip
        if self.upside_down:  # laser angle a points at base angle -a: beam i reads r[-i]
            r = np.roll(r[::-1], 1)
        if self.nan_scans:
            r = np.full(r.shape, np.nan)
        self.scan_pub.publish(
            make_scan(np.asarray(r, np.float32), angle_min=float(BEARINGS[0]),
                      angle_max=float(BEARINGS[-1]), range_min=0.05, range_max=10.0,
                      frame_id=self.laser_frame, stamp=self.get_clock().now())
        )  # fmt: skip


def _map_file(tmp_path: Path, data: np.ndarray | None = None) -> Path:
    saved = save_map(tmp_path / "room", room_grid() if data is None else data,
                     resolution=RES, origin=(ORIGIN[0], ORIGIN[1], 0.0))  # fmt: skip
    return saved.yaml_path


def _estimate(node: AmclNode, robot: FakeRobot) -> SE2:
    assert node.map_to_odom is not None
    return node.map_to_odom.to_se2() * robot.odom


_RVIZ = itertools.count()


def _initialpose(ctx: Context, pose: SE2, frame: str = "map", sigma: float = 0.1) -> None:
    pub = ctx.create_node(f"rviz_{next(_RVIZ)}").create_publisher(
        mc.PoseWithCovarianceStamped, "/initialpose", 1
    )
    cov = np.zeros(36)
    cov[0] = cov[7] = sigma**2
    cov[35] = 0.05
    pub.publish(PoseWithCovarianceStamped(
        header={"frame_id": frame, "stamp": stamp_to_msg(ctx.now())},
        pose={"pose": pose_from_xytheta(pose.x, pose.y, pose.theta), "covariance": cov},
    ))  # fmt: skip


START_PARAMS = {"initial_pose_x": START.x, "initial_pose_y": START.y, "initial_pose_a": START.theta}


def test_localises_and_publishes_pose_cloud_and_tf(tmp_path: Path) -> None:
    ctx = Context()
    MapServer(ctx, yaml_path=_map_file(tmp_path))
    robot = FakeRobot(ctx)
    node = AmclNode(ctx, parameter_overrides={**START_PARAMS, "initial_pose_x": 2.2})
    got = collect(ctx, {"/amcl_pose": mc.PoseWithCovarianceStamped,
                         "/particlecloud": mc.PoseArray, "/tf": mc.TFMessage})  # fmt: skip
    for k in range(40):  # drive 2 m back and forth along x
        robot.truth = SE2(START.x + 1.0 - abs(1.0 - 0.05 * (k % 40)), START.y, START.theta)
        ctx.spin_for(0.25)
    est = _estimate(node, robot)
    assert math.hypot(est.x - robot.truth.x, est.y - robot.truth.y) < 0.06
    assert abs(math.remainder(est.theta - robot.truth.theta, 2 * math.pi)) < 0.03
    poses = got["/amcl_pose"]
    assert len(poses) >= 5 and poses[-1].header.frame_id == "map"
    cov = np.asarray(poses[-1].pose.covariance).reshape(6, 6)
    assert 0 < cov[0, 0] < 0.1 and 0 < cov[5, 5] < 0.05 and cov[2, 2] == 0.0  # shrunk from 0.25
    clouds = got["/particlecloud"]
    assert len(clouds) >= len(poses) and clouds[-1].header.frame_id == "map"
    assert 100 <= len(clouds[-1].poses) < 5000
    map_odom = [t for m in got["/tf"] for t in m.transforms if t.header.frame_id == "map"]
    assert map_odom and all(t.child_frame_id == "odom" for t in map_odom)
    # future-dated by transform_tolerance from the scan's stamp (scans every 0.1 s)
    last = Time.from_msg(map_odom[-1].header.stamp).seconds
    assert ctx.now().seconds + 0.1 - 0.1 - 1e-6 <= last <= ctx.now().seconds + 0.1 + 1e-6
    # the latched pose reaches a late subscriber
    late: list[Any] = []
    ctx.create_node("late").create_subscription(mc.PoseWithCovarianceStamped, "/amcl_pose",
                                                late.append, 1)  # fmt: skip
    ctx.spin_for(0.01)
    assert late and late[-1] is poses[-1]


def test_particle_cloud_is_built_only_for_a_reader(tmp_path: Path) -> None:
    ctx = Context()
    MapServer(ctx, yaml_path=_map_file(tmp_path))
    robot = FakeRobot(ctx)
    node = AmclNode(ctx, parameter_overrides=START_PARAMS)
    for k in range(8):
        robot.truth = SE2(START.x + 0.05 * k, START.y, START.theta)
        ctx.spin_for(0.25)
    assert node.amcl is not None and node.amcl.pf.poses.shape[0] >= 100
    assert node.cloud_publisher.topic.published == 0  # filter updates, nobody listening
    late: list[Any] = []
    ctx.create_node("late").create_subscription(mc.PoseArray, "/particlecloud", late.append, 1)
    ctx.spin_for(0.01)
    assert len(late) == 1 and late[0].header.frame_id == "map"
    assert len(late[0].poses) == node.amcl.pf.poses.shape[0]


def test_parameters_have_the_ros_names_and_defaults() -> None:
    node = AmclNode(Context())
    for name, value in AmclParams().to_ros().items():
        assert node.get_parameter(name).value == value
    assert node.params == AmclParams() and node.get_parameter("seed").value == 0
    # the odometry model's alphas: a launch file choosing ROS's diff gets ROS's 0.2
    diff = AmclNode(Context(), parameter_overrides={"odom_model_type": "diff"})
    assert diff.get_parameter("odom_alpha1").value == 0.2
    assert diff.params.odom_alphas == (0.2,) * 5


def test_initialpose_reinitialises_and_wrong_frames_are_ignored(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    ctx = Context()
    MapServer(ctx, yaml_path=_map_file(tmp_path))
    robot = FakeRobot(ctx)
    node = AmclNode(ctx, parameter_overrides=START_PARAMS)
    ctx.spin_for(1.0)
    robot.truth = SE2(4.5, 3.0, -1.0)  # carried away: the filter does not follow
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        _initialpose(ctx, SE2(4.5, 3.0, -1.0), frame="odom")
        ctx.spin_for(0.3)
    assert any('Ignoring initial pose in frame "odom"' in r.message for r in caplog.records)
    _initialpose(ctx, SE2(4.6, 2.9, -0.95))  # 2D Pose Estimate
    ctx.spin_for(0.5)
    assert node.amcl is not None
    cloud = node.amcl.pf.poses
    # around the given pose (the scan after it already pulls the cloud 0.1 m to the truth)
    assert np.hypot(cloud[:, 0].mean() - 4.6, cloud[:, 1].mean() - 2.9) < 0.2
    assert np.ptp(cloud[:, 0]) < 1.0
    est = _estimate(node, robot)
    assert math.hypot(est.x - 4.5, est.y - 3.0) < 0.2
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        _initialpose(ctx, SE2(40.0, 3.0, 0.0))
        ctx.spin_for(0.3)
    assert any("initial pose ignored: initial pose (40.000, 3.000) is outside the map"
               in r.message for r in caplog.records)  # fmt: skip
    assert node.amcl.pf.poses[:, 0].max() < 8.0


def test_services_global_localization_nomotion_update_and_set_map(tmp_path: Path) -> None:
    ctx = Context()
    MapServer(ctx, yaml_path=_map_file(tmp_path))
    robot = FakeRobot(ctx)
    node = AmclNode(ctx, parameter_overrides=START_PARAMS)
    caller = ctx.create_node("caller")
    ctx.spin_for(0.5)
    assert node.amcl is not None
    glob = caller.create_client("std_srvs/srv/Empty", "global_localization")
    glob.call(glob.srv_type.Request())
    assert node.amcl.pf.count == 5000 and np.ptp(node.amcl.pf.poses[:, 0]) > 5.0
    updates = node.amcl.updates
    ctx.spin_for(1.0)  # standing still: only the scan right after the reset updates
    assert node.amcl.updates == updates + 1
    nomotion = caller.create_client("std_srvs/srv/Empty", "request_nomotion_update")
    for _ in range(30):  # no-motion updates: the global filter narrows down where it stands
        nomotion.call(nomotion.srv_type.Request())
        ctx.spin_for(0.1)
    assert node.amcl.updates >= updates + 25 and np.ptp(node.amcl.pf.poses[:, 0]) < 1.0
    # set_map: a new map (the room shifted by 1 m) with a pose in it
    set_map = caller.create_client("nav_msgs/srv/SetMap", "set_map")
    req = set_map.srv_type.Request()
    shifted = (ORIGIN[0] + 1.0, ORIGIN[1], 0.0)
    req.map = array_to_occupancy_grid(room_grid(), resolution=RES, origin=shifted, frame_id="map")
    req.initial_pose.header.frame_id = "map"
    req.initial_pose.pose.pose = pose_from_xytheta(robot.truth.x + 1.0, robot.truth.y,
                                                   robot.truth.theta)  # fmt: skip
    req.initial_pose.pose.covariance = np.diag([0.01, 0.01, 0, 0, 0, 0.01]).ravel()
    assert set_map.call(req).success
    assert node.amcl.map.origin_xy[0] == pytest.approx(ORIGIN[0] + 1.0)
    ctx.spin_for(1.0)
    assert abs(node.amcl.pf.poses[:, 0].mean() - (robot.truth.x + 1.0)) < 0.1


def test_map_topic_first_map_only_and_a_map_without_free_cells(
    caplog: pytest.LogCaptureFixture,
) -> None:
    ctx = Context()
    robot = FakeRobot(ctx)
    pub = ctx.create_node("mapper").create_publisher(
        mc.OccupancyGrid, "/map", QoSProfile(depth=1, durability="transient_local")
    )
    node = AmclNode(ctx, parameter_overrides={**START_PARAMS, "use_map_topic": True,
                                              "first_map_only": True})  # fmt: skip
    blocked = np.full((50, 50), 100, dtype=np.int8)
    with caplog.at_level(logging.ERROR, logger="roverlab"):
        pub.publish(array_to_occupancy_grid(blocked, resolution=RES, origin=(0, 0, 0)))
        ctx.spin_for(0.5)  # scans keep coming: the node keeps running without a map
    assert node.amcl is None
    assert any("map rejected: the map (50 x 50 cells) has no free cell" in r.message
               for r in caplog.records)  # fmt: skip
    good = array_to_occupancy_grid(room_grid(), resolution=RES, origin=(*ORIGIN, 0.0))
    pub.publish(good)
    ctx.spin_for(0.5)
    assert node.amcl is not None
    first = node.amcl
    pub.publish(good)  # first_map_only: ignored
    ctx.spin_for(0.3)
    assert node.amcl is first and node.map_to_odom is not None
    est = _estimate(node, robot)
    assert math.hypot(est.x - START.x, est.y - START.y) < 0.2


def test_initial_pose_off_the_map_falls_back_to_global_localization(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    ctx = Context()
    MapServer(ctx, yaml_path=_map_file(tmp_path))
    FakeRobot(ctx)
    with caplog.at_level(logging.ERROR, logger="roverlab"):
        node = AmclNode(ctx, parameter_overrides={"initial_pose_x": 50.0})
        ctx.spin_for(0.2)
    assert node.amcl is not None and node.amcl.pf.count == 5000
    msgs = [r.message for r in caplog.records]
    assert any("initial pose (50.000, 0.000) is outside the map" in m and
               "global localization" in m for m in msgs)  # fmt: skip


def test_missing_laser_frame_and_nan_scans_are_warned_about(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    ctx = Context()
    MapServer(ctx, yaml_path=_map_file(tmp_path))
    robot = FakeRobot(ctx, laser_frame="front_laser")  # TF only knows "laser"
    node = AmclNode(ctx, parameter_overrides=START_PARAMS)
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        ctx.spin_for(16.0)
    assert node.scans_processed == 0 and node.scan_filter.dropped > 0
    msgs = [r.message for r in caplog.records]
    assert any("No laser scan processed for 15.0 seconds: scans in frame 'front_laser' wait "
               "for the transform 'odom' <- 'front_laser'" in m for m in msgs)  # fmt: skip
    # scans without a single usable reading
    ctx = Context()
    MapServer(ctx, yaml_path=_map_file(tmp_path))
    robot = FakeRobot(ctx)
    robot.nan_scans = True
    node = AmclNode(ctx, parameter_overrides=START_PARAMS)
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        ctx.spin_for(1.0)
    assert node.scans_processed > 0
    assert any("no finite reading within (0.05, 10) m: sensor update skipped" in r.message
               for r in caplog.records)  # fmt: skip


def test_upside_down_laser_and_saved_pose(tmp_path: Path) -> None:
    ctx = Context()
    MapServer(ctx, yaml_path=_map_file(tmp_path))
    robot = FakeRobot(ctx, upside_down=True)
    node = AmclNode(ctx, parameter_overrides={**START_PARAMS, "save_pose_rate": 2.0,
                                              "gui_publish_rate": 1.0})  # fmt: skip
    got = collect(ctx, {"/particlecloud": mc.PoseArray})
    for k in range(20):
        robot.truth = SE2(START.x + 0.1 * k, START.y, START.theta)
        ctx.spin_for(0.25)
    est = _estimate(node, robot)
    assert math.hypot(est.x - robot.truth.x, est.y - robot.truth.y) < 0.06
    # standing still: the pose is written back to the parameters every 0.5 s
    ctx.spin_for(1.0)
    assert node.get_parameter("initial_pose_x").value == pytest.approx(robot.truth.x, abs=0.06)
    assert node.get_parameter("initial_pose_a").value == pytest.approx(START.theta, abs=0.05)
    assert 0 < node.get_parameter("initial_cov_xx").value < 0.25  # shrunk from the start
    # gui_publish_rate 1 Hz: at most one cloud per second
    stamps = [Time.from_msg(m.header.stamp).seconds for m in got["/particlecloud"]]
    assert len(stamps) >= 3 and min(np.diff(stamps)) >= 1.0 - 1e-9


def test_amcl_from_a_launch_file(tmp_path: Path) -> None:
    yaml_path = _map_file(tmp_path)
    params = tmp_path / "amcl_params.yaml"
    params.write_text("min_particles: 200\nodom_model_type: diff-corrected\nlaser_max_beams: 60\n")
    launch = tmp_path / "nav.launch"
    launch.write_text(f"""<launch>
  <node pkg="map_server" name="map_server" type="map_server" args="{yaml_path}">
    <param name="frame_id" value="map"/>
  </node>
  <node pkg="amcl" type="amcl" name="amcl" output="screen">
    <rosparam file="{params}" command="load" />
    <param name="initial_pose_x" value="{START.x}"/>
    <param name="initial_pose_y" value="{START.y}"/>
    <param name="initial_pose_a" value="{START.theta}"/>
  </node>
</launch>""")
    ctx = Context()
    built = build_launch(launch, context=ctx)
    (amcl,) = [n for n in built.nodes if isinstance(n, AmclNode)]
    assert amcl.params.min_particles == 200 and amcl.params.laser_max_beams == 60
    assert amcl.params.odom_model_type == "diff-corrected"
    robot = FakeRobot(ctx)
    ctx.spin_for(1.0)
    est = _estimate(amcl, robot)
    assert math.hypot(est.x - START.x, est.y - START.y) < 0.1
    bad = tmp_path / "bad.launch"
    bad.write_text('<launch><node pkg="amcl" type="amcl" name="amcl">'
                   '<param name="odom_model_type" value="ackermann"/></node></launch>')  # fmt: skip
    with pytest.raises(
        LaunchError, match=r"bad\.launch.*amcl/amcl.*odom_model_type must be one of"
    ):
        build_launch(bad, context=Context())
    # an unknown laser model: amcl warns and uses likelihood_field
    sonar = tmp_path / "sonar.launch"
    sonar.write_text('<launch><node pkg="amcl" type="amcl" name="amcl">'
                     '<param name="laser_model_type" value="sonar"/></node></launch>')  # fmt: skip
    (node,) = [n for n in build_launch(sonar, context=Context()).nodes
               if isinstance(n, AmclNode)]  # fmt: skip
    assert node.params.laser_model_type == "likelihood_field"


def test_seeded_node_runs_repeat(tmp_path: Path) -> None:
    def run(seed: int) -> list[float]:
        ctx = Context()
        MapServer(ctx, yaml_path=_map_file(tmp_path))
        robot = FakeRobot(ctx)
        node = AmclNode(ctx, parameter_overrides={**START_PARAMS, "seed": seed})
        got = collect(ctx, {"/amcl_pose": mc.PoseWithCovarianceStamped})
        for k in range(10):
            robot.truth = SE2(START.x + 0.1 * k, START.y, START.theta)
            ctx.spin_for(0.25)
        assert node.amcl is not None
        return [v for m in got["/amcl_pose"] for v in xytheta_from_pose(m.pose.pose)]

    assert run(3) == run(3)
    assert run(3) != run(4)


def test_std_warn_levels_warn_about_a_wide_estimate(caplog: pytest.LogCaptureFixture) -> None:
    """amcl's standard deviation diagnostic ("Too large" past std_warn_level_*)."""
    ctx = Context()
    node = AmclNode(ctx, parameter_overrides={"std_warn_level_x": 0.1})
    with caplog.at_level(logging.WARNING):
        node._warn_spread(np.diag([0.01, 0.01, 0.001]))  # 0.1, 0.1, 0.03: within
        assert "Standard deviation" not in caplog.text
        node._warn_spread(np.diag([0.04, 0.01, 0.04]))  # x 0.2 and yaw 0.2 are not
    assert "x 0.200 > std_warn_level_x 0.1, yaw 0.200 > std_warn_level_yaw 0.1" in caplog.text
    assert "y 0.100" not in caplog.text
    ctx.shutdown()


def test_a_launch_with_names_amcl_does_not_read_starts_and_warns_once_each(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """ROS's amcl ignores parameters it does not read; roverlab's warns about each once,
    by name, and an unknown laser model falls back to likelihood_field as amcl does."""
    path = tmp_path / "odd.launch"
    path.write_text('<launch><node pkg="amcl" type="amcl" name="amcl">'
                    '<param name="laser_model_type" value="sonar"/>'
                    '<param name="laser_z_hti" value="0.5"/>'
                    '<param name="use_odom_twist" value="true"/></node></launch>')  # fmt: skip
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        started = build_launch(path, context=Context())
    (node,) = [n for n in started.nodes if isinstance(n, AmclNode)]
    assert node.params.laser_model_type == "likelihood_field"
    said = [r.message for r in caplog.records]
    for line in (
        "amcl: unknown parameter 'laser_z_hti' (did you mean laser_z_hit?) is ignored",
        "amcl: unknown parameter 'use_odom_twist' is ignored",
        'Unknown laser model type "sonar"; defaulting to likelihood_field model',
    ):
        assert sum(line in m for m in said) == 1, (line, said)
    assert not any("laser_z_hti" in w for w in started.warnings)  # not a second time
