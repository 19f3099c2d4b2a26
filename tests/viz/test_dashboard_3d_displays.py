"""The 3D view's displays beyond the robot (Playwright + Debian's chromium, screenshots):

* LaserScan with rviz's Intensity transformer: the beams' intensities on the rainbow
  (lowest red, highest magenta), at the laser's height;
* MarkerArray: CUBE, SPHERE, CYLINDER, ARROW, LINE_STRIP, LINE_LIST, POINTS, CUBE_LIST,
  SPHERE_LIST, TEXT_VIEW_FACING with their full pose, scale and colour, kept apart by
  namespace and id; DELETE, DELETEALL and lifetime remove them;
* Pose / Path at their real height, the pose fully oriented (pitched up);
* a URDF whose visual is a COLLADA (.dae) mesh is drawn with the file's own colour.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context, Time
from roverlab.description.node import RobotStatePublisher
from roverlab.geometry import Transform3, quat_from_rpy
from roverlab.msgs import make, make_scan
from roverlab.tf import StaticTransformBroadcaster
from roverlab.tf.convert import transform_to_msg
from roverlab.viz import DashboardServer
from roverlab.viz.config import DashboardConfig, DisplayConfig

from .test_dashboard_3d import _open, _screen, _shot

BOX_URDF = """<robot name="boxbot"><link name="base_link"><visual><geometry>
  <box size="0.3 0.2 0.1"/></geometry></visual></link></robot>"""
ORBIT = {"mode": "Orbit", "focal_point": [1.5, 0.5, 0.5], "distance": 9.0, "yaw": -0.9,
         "pitch": 0.55}  # fmt: skip
MARKERS, SCAN, POSE, PATH = 2, 3, 4, 5  # display slots


def _pose(x: float, y: float, z: float, rpy: tuple[float, float, float] = (0, 0, 0)) -> Any:
    q = quat_from_rpy(*rpy)
    return {"position": {"x": x, "y": y, "z": z},
            "orientation": {"x": q[0], "y": q[1], "z": q[2], "w": q[3]}}  # fmt: skip


def _marker(ns: str, mid: int, kind: int, **kw: Any) -> Any:
    rgba = kw.pop("rgba", (1.0, 1.0, 1.0, 1.0))
    pts = kw.pop("points", [])
    return make(
        "visualization_msgs/msg/Marker",
        header={"frame_id": kw.pop("frame", "map")},
        ns=ns,
        id=mid,
        type=kind,
        action=kw.pop("action", 0),
        pose=kw.pop("pose", _pose(0, 0, 0)),
        scale=dict(zip("xyz", kw.pop("scale", (1.0, 1.0, 1.0)), strict=True)),
        color=dict(zip("rgba", rgba, strict=True)),
        points=[{"x": p[0], "y": p[1], "z": p[2]} for p in pts],
        **kw,
    )


def _markers() -> list[Any]:
    red, green, blue = (1.0, 0.0, 0.0, 1.0), (0.0, 1.0, 0.0, 1.0), (0.0, 0.3, 1.0, 1.0)
    return [
        # a cube rolled 45 degrees about x and a second one of the same id in another ns
        _marker("solids", 0, 1, pose=_pose(3.0, 0.0, 1.0, (math.pi / 4, 0, 0)),
                scale=(0.6, 0.6, 0.6), rgba=red),
        _marker("more", 0, 2, pose=_pose(3.0, 2.0, 1.0), scale=(0.5, 0.5, 0.5), rgba=green),
        _marker("solids", 1, 3, pose=_pose(0.0, 3.0, 0.5), scale=(0.4, 0.4, 1.0), rgba=blue),
        _marker("solids", 2, 0, pose=_pose(1.0, -1.5, 0.3, (0, -math.pi / 4, 0)),
                scale=(1.0, 0.1, 0.1), rgba=(1.0, 1.0, 0.0, 1.0)),
        _marker("lines", 0, 4, scale=(0.08, 0, 0), rgba=(1.0, 0.5, 0.0, 1.0),
                points=[(-1, -1, 1.5), (0, -1, 2.0), (1, -1, 1.5)]),
        _marker("lines", 1, 5, scale=(0.05, 0, 0), rgba=(0.0, 1.0, 1.0, 1.0),
                points=[(-1, 1, 0.2), (-1, 1, 1.2), (-2, 1, 0.2), (-2, 1, 1.2)]),
        _marker("lists", 0, 8, scale=(0.1, 0.1, 0), rgba=(1.0, 1.0, 1.0, 1.0),
                points=[(-2.0, -2.0, 0.1 * i) for i in range(10)]),
        _marker("lists", 1, 6, scale=(0.2, 0.2, 0.2), rgba=(0.8, 0.0, 0.8, 1.0),
                points=[(0.5 * i, -3.0, 0.1) for i in range(5)]),
        _marker("lists", 2, 7, scale=(0.2, 0.2, 0.2), rgba=(0.0, 0.8, 0.0, 1.0),
                points=[(0.5 * i, 4.0, 0.1) for i in range(5)]),
        _marker("text", 0, 9, pose=_pose(3.0, 0.0, 2.0), scale=(0, 0, 0.3), text="CUBE"),
        _marker("doomed", 0, 1, pose=_pose(-3.0, 0.0, 0.5), scale=(0.3, 0.3, 0.3)),
    ]  # fmt: skip


class _Feed:
    """Publishes the current messages at 5 Hz until stopped."""

    def __init__(self, ctx: Context) -> None:
        node = ctx.create_node("feed")
        self.pubs = {
            "/markers": node.create_publisher("visualization_msgs/msg/MarkerArray", "/markers", 10),
            "/scan": node.create_publisher("sensor_msgs/msg/LaserScan", "/scan", 10),
            "/pose": node.create_publisher("geometry_msgs/msg/PoseStamped", "/pose", 10),
            "/path": node.create_publisher("nav_msgs/msg/Path", "/path", 10),
        }
        n = 360
        self.msgs: dict[str, Any] = {
            "/markers": make("visualization_msgs/msg/MarkerArray", markers=_markers()),
            "/scan": make_scan(np.full(n, 2.0), angle_min=-math.pi, angle_max=math.pi,
                               range_min=0.1, range_max=10.0, frame_id="laser",
                               intensities=np.arange(n, dtype=float) * 10.0),
            # pitched up 45 degrees (nose up: rotation of -45 degrees about y) at 1 m
            "/pose": make("geometry_msgs/msg/PoseStamped", header={"frame_id": "map"},
                          pose=_pose(-1.0, -3.0, 1.0, (0, -math.pi / 4, 0))),
            "/path": make("nav_msgs/msg/Path", header={"frame_id": "map"},
                          poses=[{"header": {"frame_id": "map"},
                                  "pose": _pose(-3 + 0.5 * i, 2.0, 0.2 * i)} for i in range(8)]),
        }  # fmt: skip
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self.stop.wait(0.2):
            for topic, msg in list(self.msgs.items()):
                if msg is not None:
                    self.pubs[topic].publish(msg)


@pytest.fixture(scope="module")
def scene() -> Iterator[tuple[DashboardServer, _Feed]]:
    ctx = Context()
    RobotStatePublisher(ctx, robot_description=BOX_URDF)
    node = ctx.create_node("frames")
    stb = StaticTransformBroadcaster(node)
    stb.send_transform(transform_to_msg("map", "base_link", Time(0), Transform3((0.0, 0.0, 0.0))))
    stb.send_transform(transform_to_msg("base_link", "laser", Time(0), Transform3((0.0, 0.0, 0.5))))
    displays = [
        DisplayConfig("grid", "Grid", True, ""),
        DisplayConfig("robot_model", "RobotModel", True, "/robot_description"),
        DisplayConfig("marker_array", "Markers", True, "/markers"),
        DisplayConfig("laser_scan", "Scan", True, "/scan",
                      {"color_transformer": "Intensity", "size_px": 6.0}),
        DisplayConfig("pose", "Pose", True, "/pose", {"length": 1.0}),
        DisplayConfig("path", "Path", True, "/path"),
    ]  # fmt: skip
    config = DashboardConfig(fixed_frame="map", displays=displays, view=dict(ORBIT))
    server = DashboardServer(ctx, "127.0.0.1", 0, config=config)
    ctx.spin_in_thread()
    server.start()
    feed = _Feed(ctx)
    yield server, feed
    feed.stop.set()
    feed.thread.join()
    server.stop()
    ctx.shutdown()


def _drawn(page: Any) -> dict[str, Any]:
    out: dict[str, Any] = page.evaluate(
        f"""() => {{
        const e = viz.objects3d.get({MARKERS}); if (!e || !e.byId) return {{}};
        const out = {{}};
        for (const [id, it] of e.byId) out[id] = {{type: it.obj.type,
            pos: it.obj.position.toArray(), quat: it.obj.quaternion.toArray()}};
        return out; }}"""
    )
    return out


def _colour_near(img: np.ndarray, sx: float, sy: float, r: int = 4) -> np.ndarray:
    """The most saturated pixel within ``r`` of a point (the background is grey)."""
    patch = img[int(sy) - r : int(sy) + r + 1, int(sx) - r : int(sx) + r + 1].reshape(-1, 3)
    sat = patch.max(axis=1) - patch.min(axis=1)
    return patch[int(np.argmax(sat))]


def test_intensity_scan_markers_and_poses_in_3d(
    scene: tuple[DashboardServer, _Feed],
    browser: Any,
    tmp_path: Path,
) -> None:
    server, feed = scene
    ready = (f"viz.data.layers[{SCAN}] && viz.data.layers[{SCAN}].points"
             f" && viz.data.layers[{MARKERS}] && viz.data.layers[{MARKERS}].markers3d"
             f" && viz.data.layers[{POSE}] && viz.data.layers[{POSE}].poses3"
             f" && viz.data.layers[{PATH}] && viz.data.layers[{PATH}].path3")  # fmt: skip
    page = _open(browser, server, ready)
    page.wait_for_timeout(800)
    img = _shot(page, tmp_path / "displays_3d.png")
    # --- the scan: intensity 0 (beam 0, at -pi) red, the highest (beam 359, +pi) magenta,
    # the middle one (beam 180, angle 0: intensity 1800 of 0..3590) green-cyan; at z 0.5
    scan = page.evaluate(
        f"() => {{ const s = viz.data.layers[{SCAN}].points.at(-1);"
        " return {n: s.n, z: s.xyz[2], buckets: s.buckets.length}; }"
    )
    assert scan["n"] == 360 and scan["z"] == pytest.approx(0.5) and scan["buckets"] > 30
    for angle, want in ((-math.pi + 0.05, (255, 0, 0)), (math.pi - 0.05, (255, 0, 255)),
                        (0.0, (0, 255, 128))):  # fmt: skip
        sx, sy = _screen(page, 2.0 * math.cos(angle), 2.0 * math.sin(angle), 0.5)
        got = _colour_near(img, sx, sy)
        assert np.abs(got - np.array(want)).max() < 70, (angle, got.tolist(), want)
    # --- markers: one object per (ns, id), at their full pose
    drawn = _drawn(page)
    assert set(drawn) >= {"solids/0", "more/0", "solids/1", "solids/2", "lines/0", "lines/1",
                          "lists/0", "lists/1", "lists/2", "text/0", "doomed/0"}  # fmt: skip
    cube = drawn["solids/0"]
    assert cube["pos"] == pytest.approx([3.0, 0.0, 1.0])
    assert cube["quat"] == pytest.approx(list(quat_from_rpy(math.pi / 4, 0, 0)), abs=1e-5)
    types = page.evaluate(
        f"() => Object.fromEntries([...viz.objects3d.get({MARKERS}).byId].map(([id, it]) =>"
        " [id, [it.obj.type, ...it.obj.children.map(c => c.type)]]))"
    )
    assert types["lines/0"] == ["Group", "Line2"] and types["lines/1"] == ["Group", "LineSegments2"]
    assert types["lists/0"][0] == "Points" and types["lists/1"][0] == "Mesh"  # instanced
    assert types["text/0"][0] == "Sprite"
    # pixels: the red cube and the green sphere where their poses project
    sx, sy = _screen(page, 3.0, 0.0, 1.0)
    assert _colour_near(img, sx, sy, 3)[0] > 150 and _colour_near(img, sx, sy, 3)[1] < 60
    sx, sy = _screen(page, 3.0, 2.0, 1.0)
    g = _colour_near(img, sx, sy, 3)
    assert g[1] > 150 and g[0] < 80
    # --- the pose arrow at 1 m, pitched up; the path's points at their heights
    arrow = page.evaluate(
        f"() => {{ const a = viz.objects3d.get({POSE}).obj.children[0];"
        " return [a.position.toArray(), a.quaternion.toArray()]; }"
    )
    assert arrow[0] == pytest.approx([-1.0, -3.0, 1.0], abs=1e-5)
    assert arrow[1] == pytest.approx(list(quat_from_rpy(0, -math.pi / 4, 0)), abs=1e-5)
    zs = page.evaluate(
        f"() => Array.from(viz.objects3d.get({PATH}).obj.geometry.attributes.position.array)"
        ".filter((v, i) => i % 3 == 2)"
    )
    assert zs == pytest.approx([0.2 * i for i in range(8)], abs=1e-5)
    # --- DELETE one marker, then a lifetime, then DELETEALL
    arr = feed.msgs["/markers"]
    feed.msgs["/markers"] = make(
        "visualization_msgs/msg/MarkerArray",
        markers=[_marker("doomed", 0, 1, action=2),
                 _marker("brief", 0, 2, scale=(0.3, 0.3, 0.3),
                         lifetime={"sec": 0, "nanosec": 300_000_000})],
    )  # fmt: skip
    page.wait_for_function(f"() => !viz.objects3d.get({MARKERS}).byId.has('doomed/0')")
    assert "solids/0" in _drawn(page)  # the others stay
    feed.msgs["/markers"] = None
    page.wait_for_function(f"() => !viz.objects3d.get({MARKERS}).byId.has('brief/0')")
    feed.msgs["/markers"] = make("visualization_msgs/msg/MarkerArray",
                                 markers=[_marker("", 0, 0, action=3)])  # fmt: skip
    page.wait_for_function(f"() => viz.objects3d.get({MARKERS}).byId.size === 0")
    feed.msgs["/markers"] = arr
    assert not page.errors
    page.close()
