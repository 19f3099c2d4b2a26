"""VizBridge in one in-process context: subscriptions follow the config, map patches,
statuses, Save map, compressed images, drive speeds."""

from __future__ import annotations

import io
import json
import struct
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.core import Context, QoSProfile, Time
from roverlab.geometry import Transform3
from roverlab.maps import load_map
from roverlab.msgs import (
    CompressedImage,
    array_to_occupancy_grid,
    make,
    make_scan,
    pose_from_xytheta,
)
from roverlab.tf import StaticTransformBroadcaster
from roverlab.tf.convert import transform_to_msg
from roverlab.viz.bridge import VizBridge
from roverlab.viz.config import DashboardConfig, DisplayConfig
from roverlab.viz.errors import DashboardError
from roverlab.viz.protocol import KIND_MAP, KIND_MAP_PATCH, KIND_POSES, POSES_3D
from roverlab.viz.status import RateMeter

LATCHED = QoSProfile(depth=1, durability="transient_local")


def _config(*displays: DisplayConfig, frame: str = "map") -> DashboardConfig:
    return DashboardConfig(fixed_frame=frame, displays=list(displays))


def _rows(bridge: VizBridge, slot: int) -> dict[str, tuple[str, str]]:
    status = bridge.status({}, [])
    return {name: (level, text) for level, name, text in status["displays"][slot]}


def test_map_updates_travel_as_patches_and_save_map(tmp_path: Path) -> None:
    ctx = Context()
    node = ctx.create_node("pub")
    pub = node.create_publisher("nav_msgs/msg/OccupancyGrid", "/map", LATCHED)
    bridge = VizBridge(
        context=ctx, config=_config(DisplayConfig("map", "Map", True, "/map")), map_dir=tmp_path
    )
    cells = np.zeros((60, 80), dtype=np.int8)
    cells[:, :10] = -1
    pub.publish(array_to_occupancy_grid(cells, resolution=0.1, origin=(-1.0, -2.0, 0.0)))
    ctx.spin_for(0.1)
    (d,) = bridge.displays
    assert d.map_base is not None and d.map_base.payload[0] == KIND_MAP
    assert struct.unpack_from("<II", d.map_base.payload, 4) == (80, 60)
    cells2 = cells.copy()
    cells2[30:33, 40:45] = 100
    pub.publish(array_to_occupancy_grid(cells2, resolution=0.1, origin=(-1.0, -2.0, 0.0)))
    ctx.spin_for(0.1)
    assert len(d.map_patches) == 1 and d.frame is d.map_patches[0]
    patch = d.map_patches[0].payload
    assert patch[0] == KIND_MAP_PATCH
    assert struct.unpack_from("<IIII", patch, 4) == (40, 30, 5, 3)
    assert len(patch) == 20 + 15  # only the changed window travels
    # the same map again changes nothing; a new origin sends a full map
    pub.publish(array_to_occupancy_grid(cells2, resolution=0.1, origin=(-1.0, -2.0, 0.0)))
    ctx.spin_for(0.1)
    assert len(d.map_patches) == 1
    pub.publish(array_to_occupancy_grid(cells2, resolution=0.1, origin=(0.0, 0.0, 0.0)))
    ctx.spin_for(0.1)
    assert d.map_patches == [] and d.frame is d.map_base
    yaml_path = bridge.save_map("saved")
    assert yaml_path == tmp_path / "saved.yaml"
    loaded = load_map(yaml_path)
    assert loaded.data.shape == (60, 80) and (loaded.data[30:33, 40:45] == 100).all()
    with pytest.raises(DashboardError, match="bad map name"):
        bridge.save_map("../evil")
    ctx.shutdown()


def test_statuses_no_publisher_no_messages_tf_failure_and_ok() -> None:
    ctx = Context()
    node = ctx.create_node("pub")
    StaticTransformBroadcaster(node).send_transform(
        transform_to_msg("map", "odom", Time(0), Transform3((1.0, 0.0, 0.0)))
    )
    good = node.create_publisher("geometry_msgs/msg/PoseArray", "/good", 1)
    lost = node.create_publisher("geometry_msgs/msg/PoseArray", "/lost", 1)
    node.create_publisher("geometry_msgs/msg/PoseArray", "/quiet", 1)
    bridge = VizBridge(
        context=ctx,
        config=_config(
            DisplayConfig("pose_array", "good", True, "/good"),
            DisplayConfig("pose_array", "lost", True, "/lost"),
            DisplayConfig("pose_array", "quiet", True, "/quiet"),
            DisplayConfig("pose_array", "nobody", True, "/nobody"),
            DisplayConfig("odometry", "wrong type", True, "/good"),
            DisplayConfig("pose_array", "off", False, "/good"),
        ),
    )
    assert _rows(bridge, 2)["Topic"] == ("ok", "Subscribed to /quiet; waiting for messages")
    bridge.quiet_after_s = 0.0  # as if 5 s had passed
    ctx.spin_for(0.1)
    good.publish(make("geometry_msgs/msg/PoseArray", header={"frame_id": "odom"},
                      poses=[pose_from_xytheta(1.0, 2.0, 0.0)]))  # fmt: skip
    lost.publish(make("geometry_msgs/msg/PoseArray", header={"frame_id": "ghost"},
                      poses=[pose_from_xytheta(0.0, 0.0, 0.0)]))  # fmt: skip
    ctx.spin_for(0.1)
    assert _rows(bridge, 0)["Topic"][0] == "ok" and _rows(bridge, 0)["Transform"][0] == "ok"
    frame = bridge.displays[0].frame
    assert frame is not None and frame.payload[0] == KIND_POSES
    assert frame.payload[1] == POSES_3D
    pose = np.frombuffer(frame.payload[8:], dtype="<f4")
    assert np.allclose(pose, [2.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0])  # odom is 1 m along map's x
    level, text = _rows(bridge, 1)["Transform"]
    assert level == "error" and "ghost" in text
    level, text = _rows(bridge, 2)["Topic"]
    assert level == "warn" and text.startswith("No messages received on /quiet for ")
    assert text.endswith(" s (1 publisher(s) sent nothing)")
    assert _rows(bridge, 3)["Topic"] == ("warn", "No publisher on /nobody")
    assert _rows(bridge, 4)["Topic"][0] == "error"  # /good carries PoseArray, not Odometry
    assert _rows(bridge, 5) == {"Status": ("disabled", "disabled")}
    glob = bridge.status({}, [])["global"]
    assert glob[0][:2] == ["ok", "Fixed Frame"]
    ctx.shutdown()


def test_config_changes_move_subscriptions() -> None:
    ctx = Context()
    bridge = VizBridge(context=ctx, config=_config(DisplayConfig("laser_scan", "s", True, "/scan")))
    assert "/scan" in ctx.graph.topics
    first = bridge.displays[0]
    bridge.set_config(
        _config(
            DisplayConfig("path", "p", True, "/plan"),
            DisplayConfig("laser_scan", "s", True, "/scan", {"decay_s": 1.0}),
        )
    )
    ctx.spin_for(0.05)
    assert bridge.displays[1] is first and first.slot == 1  # kept, with its data
    assert first.config.option("decay_s") == 1.0
    bridge.set_config(_config(DisplayConfig("laser_scan", "s", True, "/scan2")))
    ctx.spin_for(0.05)
    assert "/scan" not in ctx.graph.topics and "/plan" not in ctx.graph.topics
    assert bridge.displays[0] is not first and "/scan2" in ctx.graph.topics
    ctx.shutdown()


def test_compressed_and_depth_images() -> None:
    ctx = Context()
    node = ctx.create_node("cam")
    pub = node.create_publisher("sensor_msgs/msg/CompressedImage", "/cam/compressed", 1)
    bridge = VizBridge(
        context=ctx, config=_config(DisplayConfig("image", "cam", True, "/cam/compressed"))
    )
    assert bridge.displays[0].sub_key[1] == "sensor_msgs/msg/CompressedImage"
    buf = io.BytesIO()
    Image.fromarray(np.full((8, 8, 3), 200, dtype=np.uint8)).save(buf, format="JPEG")
    pub.publish(CompressedImage(format="jpeg", data=np.frombuffer(buf.getvalue(), np.uint8)))
    ctx.spin_for(0.05)
    assert bridge.image_topics() == ["/cam/compressed"]
    frame = bridge.image_frame(bridge.displays[0])
    assert frame is not None and frame.payload[4:] == buf.getvalue()  # passed through
    # compressedDepth: a 12-byte header, then a 16-bit PNG; shown through the colour map
    depth = np.tile(np.linspace(1000, 3000, 64).astype(np.uint16), (16, 1))
    depth[:, :8] = 0
    png = io.BytesIO()
    Image.fromarray(depth).save(png, format="PNG")
    data = np.frombuffer(b"\0" * 12 + png.getvalue(), np.uint8)
    pub.publish(CompressedImage(format="16UC1; compressedDepth", data=data))
    ctx.spin_for(0.05)
    frame = bridge.image_frame(bridge.displays[0])
    assert frame is not None
    rgb = np.asarray(Image.open(io.BytesIO(frame.payload[4:])).convert("RGB")).astype(int)
    assert rgb.shape == (16, 64, 3) and rgb[8, 2].max() < 40  # no data: black
    assert rgb[8, 12, 2] > 100 and rgb[8, 60, 0] > 100  # near blue, far red
    pub.publish(CompressedImage(format="bmp", data=np.frombuffer(b"BM....", np.uint8)))
    ctx.spin_for(0.05)
    assert bridge.image_frame(bridge.displays[0]) is None
    assert "neither JPEG nor PNG" in (bridge.displays[0].error or "")
    ctx.shutdown()


def test_drive_speed_keys_and_limits() -> None:
    ctx = Context()
    node = ctx.create_node("robot")
    got: list[object] = []
    node.create_subscription("geometry_msgs/msg/Twist", "/cmd_vel", got.append, 10)
    bridge = VizBridge(context=ctx, config=_config())
    assert bridge.drive_key("q")  # speeds up by 10 %, like teleop_twist_keyboard
    assert bridge.speed_mps == pytest.approx(0.33) and bridge.turn_radps == pytest.approx(0.55)
    bridge.drive_key("i")
    ctx.spin_for(0.05)
    assert got and got[-1].linear.x == pytest.approx(0.33)  # type: ignore[attr-defined]
    bridge.set_speeds(1.0, 2.0)
    with pytest.raises(DashboardError, match="speed"):
        bridge.set_speeds(-1.0, 1.0)
    ctx.shutdown()


def test_marker_lifetime_expires_on_the_executor_clock() -> None:
    ctx = Context()
    node = ctx.create_node("m")
    pub = node.create_publisher("visualization_msgs/msg/Marker", "/m", 10)
    bridge = VizBridge(context=ctx, config=_config(DisplayConfig("marker", "m", True, "/m")))
    pub.publish(
        make(
            "visualization_msgs/msg/Marker",
            header={"frame_id": "map"},
            type=1,
            scale={"x": 1.0, "y": 1.0, "z": 1.0},
            color={"r": 1.0, "a": 1.0},
            lifetime={"sec": 1, "nanosec": 0},
        )
    )
    ctx.spin_for(0.5)
    frame = bridge.displays[0].frame
    assert frame is not None and '"polygon"' in frame.payload
    solid = json.loads(frame.payload)["items3d"][0]
    assert solid["type"] == 1 and solid["pose"] == [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    ctx.spin_for(1.0)
    frame = bridge.displays[0].frame
    assert frame is not None and json.loads(frame.payload) == {"items": [], "items3d": []}
    ctx.shutdown()


def _points_frame(payload: bytes) -> tuple[np.ndarray, np.ndarray]:
    """``(points, rgba per point)`` of a KIND_POINTS frame (bucketed colours)."""
    n, nb = struct.unpack_from("<II", payload, 4)
    counts = np.frombuffer(payload, "<u4", nb, 12)
    palette = np.frombuffer(payload, np.uint8, 4 * nb, 12 + 4 * nb).reshape(nb, 4)
    dims = 3 if payload[1] & 1 else 2
    pts = np.frombuffer(payload, "<f4", n * dims, 12 + 8 * nb).reshape(n, dims)
    return pts, np.repeat(palette, counts, axis=0)


def test_intensity_transformer_colours_scans_and_clouds() -> None:
    ctx = Context()
    node = ctx.create_node("pub")
    StaticTransformBroadcaster(node).send_transform(
        transform_to_msg("map", "laser", Time(0), Transform3((0.0, 0.0, 0.5)))
    )
    scans = node.create_publisher("sensor_msgs/msg/LaserScan", "/scan", 10)
    clouds = node.create_publisher("sensor_msgs/msg/PointCloud2", "/cloud", 10)
    fixed = {"color_transformer": "Intensity", "autocompute_intensity_bounds": False,
             "min_intensity": 0.0, "max_intensity": 100.0, "use_rainbow": False,
             "min_color": [0, 0, 255], "max_color": [255, 255, 0]}  # fmt: skip
    bridge = VizBridge(context=ctx, config=_config(
        DisplayConfig("laser_scan", "s", True, "/scan", {"color_transformer": "Intensity"}),
        DisplayConfig("point_cloud2", "c", True, "/cloud", fixed),
        DisplayConfig("point_cloud2", "m", True, "/cloud", {"color_transformer": "Intensity",
                                                            "channel_name": "heat"}),
    ))  # fmt: skip
    ctx.spin_for(0.1)
    scans.publish(make_scan(np.array([1.0, np.nan, 1.0, 1.0]), angle_min=0.0, angle_max=1.5,
                            range_min=0.1, range_max=5.0, frame_id="laser",
                            intensities=np.array([5.0, 0.0, 50.0, 500.0])))  # fmt: skip
    data = np.array([[1.0, 0, 0, -10.0], [2.0, 0, 0, 50.0], [3.0, 0, 0, 250.0]], "<f4")
    clouds.publish(make("sensor_msgs/msg/PointCloud2", header={"frame_id": "laser"},
                        height=1, width=3, point_step=16, row_step=48, is_dense=True,
                        fields=[{"name": n, "offset": 4 * i, "datatype": 7, "count": 1}
                                for i, n in enumerate(("x", "y", "z", "intensity"))],
                        data=data.tobytes()))  # fmt: skip
    ctx.spin_for(0.2)
    scan, fixed_cloud, missing = bridge.displays
    assert missing.frame is not None  # drawn flat
    assert scan.frame is not None and fixed_cloud.frame is not None
    pts, rgba = _points_frame(scan.frame.payload)
    assert len(pts) == 3 and np.allclose(pts[:, 2], 0.5)  # the NaN beam dropped, at 0.5 m
    # autocomputed over the valid beams (5..500): lowest red, highest magenta
    assert scan.info["bounds"] == [5.0, 500.0]
    assert rgba[0, :3].tolist() == [255, 0, 0] and rgba[-1, :3].tolist() == [255, 0, 255]
    pts, rgba = _points_frame(fixed_cloud.frame.payload)
    order = np.argsort(pts[:, 0])
    got = rgba[order, :3].tolist()
    assert got[0] == [0, 0, 255] and got[2] == [255, 255, 0]  # clipped to 0..100
    assert abs(got[1][0] - 128) <= 3 and abs(got[1][2] - 128) <= 3  # half way
    assert _rows(bridge, 2)["Color Transformer"][0] == "warn"  # no 'heat' channel: flat
    ctx.shutdown()


def test_a_display_receiving_messages_is_ok_whatever_the_graph_says() -> None:
    """rviz's rule: messages arriving is OK, even when the graph shows no publisher (another
    process's publisher not known yet: the old status said "No publisher on /scan (76
    messages received)"); a stream that stops warns and names the cause."""
    ctx = Context()
    bridge = VizBridge(
        context=ctx,
        config=_config(
            DisplayConfig("laser_scan", "scan", True, "/scan"),
            DisplayConfig("path", "plan", True, "/plan"),
        ),
    )
    scan, plan = bridge.displays
    for d in (scan, plan):
        d.received, d.last_message_s = 76, time.monotonic()
    assert _rows(bridge, 0)["Topic"] == ("ok", "76 messages received")
    # the stream stops: the scan warns, the plan (published once) stays OK
    for d in (scan, plan):
        d.last_message_s = time.monotonic() - 6.0
    level, text = _rows(bridge, 0)["Topic"]
    assert level == "warn"
    assert text == "No messages on /scan for 6 s (no publisher; 76 messages received before)"
    assert _rows(bridge, 1)["Topic"] == ("ok", "76 messages received")
    ctx.shutdown()


def test_rate_meter_sums_sources_and_survives_restarts() -> None:
    meter = RateMeter(window_s=3.0)
    for i in range(5):  # one process at 10 Hz, another at 5 Hz on the same topic
        meter.observe("a", float(i), {"/scan": 100 + 10 * i})
        meter.observe("b", float(i) + 0.5, {"/scan": 5 * i, "/odom": 1000 + 20 * i})
    rates = meter.rates(4.5)
    assert rates == pytest.approx({"/scan": 15.0, "/odom": 20.0})
    meter.observe("a", 5.0, {"/scan": 3})  # "a" restarted: its samples start again
    meter.observe("a", 6.0, {"/scan": 13})
    assert meter.rates(6.0)["/scan"] == pytest.approx(15.0)
    assert meter.rates(30.0) == {}  # sources not heard from are forgotten


def test_a_bag_played_again_resets_tf_when_clock_jumps_back() -> None:
    """A second play of a bag: /clock goes back and so do the stamps. The buffer held the
    end of the first play and ignored the new transforms as too old (the robot froze where
    the first play ended); like rviz, the dashboard resets on a jump back in time."""
    ctx = Context(clock="wall", publish_clock=False)
    node = ctx.create_node("player")
    clock = node.create_publisher("rosgraph_msgs/msg/Clock", "/clock", 10)
    tf = node.create_publisher("tf2_msgs/msg/TFMessage", "/tf", 10)
    bridge = VizBridge(context=ctx, config=_config(frame="odom"))

    def play(t_s: float, x_m: float) -> None:
        stamp = Time.from_seconds(t_s)
        clock.publish(make("rosgraph_msgs/msg/Clock", clock=stamp.to_msg()))
        ctx.spin_for(0.05)
        moved = transform_to_msg("odom", "base_footprint", stamp, Transform3((x_m, 0.0, 0.0)))
        tf.publish(make("tf2_msgs/msg/TFMessage", transforms=[moved]))
        ctx.spin_for(0.05)

    play(200.0, 5.0)  # the end of the first play
    here, why = bridge.lookup_why("base_footprint")
    assert here is not None and here.translation[0] == pytest.approx(5.0), why
    play(1.0, 1.0)  # the bag again, from its start
    here, why = bridge.lookup_why("base_footprint")
    assert here is not None and here.translation[0] == pytest.approx(1.0), why
    play(0.5, 0.5)  # half a second back is jitter, not a restart: nothing is dropped
    here, _ = bridge.lookup_why("base_footprint")
    assert here is not None and here.translation[0] == pytest.approx(1.0)
    assert any(sub.topic_name == "/clock" for sub in bridge.node.subscriptions)
    ctx.shutdown()
    # on a simulation's own clock the dashboard leaves /clock alone (it pauses unread)
    sim = Context()
    in_sim = VizBridge(context=sim, config=_config())
    assert all(sub.topic_name != "/clock" for sub in in_sim.node.subscriptions)
    sim.shutdown()
