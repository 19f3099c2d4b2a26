"""Pure display geometry: markers, pose trails, map windows, colour buckets, thinning."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.geometry import Transform3, quat_from_rpy, quat_from_yaw, quat_multiply
from roverlab.msgs import Marker, pose_from_xytheta
from roverlab.viz.displays import (
    MarkerStore,
    PoseTrail,
    color_buckets,
    decimate,
    map_change,
    marker_3d,
    marker_primitives,
    pose_covariance_primitives,
    poses3_in_fixed,
    poses_in_fixed,
    yaw_of_poses3,
)

SHIFT = Transform3((10.0, 0.0, 0.0))  # fixed_from_frame: the marker frame 10 m along x


def _marker(**kw: object) -> Marker:
    base: dict[str, object] = {
        "header": {"frame_id": "base"},
        "ns": "n",
        "id": 0,
        "scale": {"x": 1.0, "y": 1.0, "z": 1.0},
        "color": {"r": 1.0, "g": 0.0, "b": 0.0, "a": 1.0},
    }
    base.update(kw)
    return Marker(**base)


def test_cube_sphere_cylinder_seen_from_above() -> None:
    cube = _marker(
        type=1, pose=pose_from_xytheta(1.0, 2.0, math.pi / 4), scale={"x": 2, "y": 2, "z": 1}
    )
    (prim,) = marker_primitives(cube, SHIFT)
    pts = np.array(prim["points"])
    assert prim["shape"] == "polygon" and len(pts) == 4  # a square turned by 45 degrees
    assert np.allclose(pts.max(axis=0), [11.0 + math.sqrt(2), 2.0 + math.sqrt(2)])
    sphere = _marker(type=2, scale={"x": 1.0, "y": 0.5, "z": 0.2})
    pts = np.array(marker_primitives(sphere, Transform3())[0]["points"])
    assert np.allclose(pts.max(axis=0), [0.5, 0.25], atol=1e-6)
    # a cylinder lying on its side (pitched 90 degrees) shows as a rectangle 1 x 0.4
    lying = _marker(type=3, scale={"x": 0.4, "y": 0.4, "z": 1.0})
    q = quat_from_rpy(0.0, math.pi / 2, 0.0)
    lying.pose.orientation.x, lying.pose.orientation.y = float(q[0]), float(q[1])
    lying.pose.orientation.z, lying.pose.orientation.w = float(q[2]), float(q[3])
    pts = np.array(marker_primitives(lying, Transform3())[0]["points"])
    span = pts.max(axis=0) - pts.min(axis=0)
    assert np.allclose(span, [1.0, 0.4], atol=0.01)


def test_arrow_from_pose_and_from_points() -> None:
    a = _marker(
        type=0, pose=pose_from_xytheta(0.0, 0.0, math.pi / 2), scale={"x": 2.0, "y": 0.1, "z": 0.1}
    )
    (prim,) = marker_primitives(a, SHIFT)
    assert prim["shape"] == "arrow" and prim["points"] == [[10.0, 0.0]]
    assert math.isclose(prim["yaw"], math.pi / 2, abs_tol=1e-4) and prim["length"] == 2.0
    b = _marker(type=0, points=[{"x": 0, "y": 0, "z": 0}, {"x": 3, "y": 4, "z": 0}])
    (prim,) = marker_primitives(b, Transform3())
    assert prim["length"] == 5.0 and math.isclose(prim["yaw"], math.atan2(4, 3), abs_tol=1e-4)


def test_lines_points_and_text() -> None:
    pts = [{"x": float(i), "y": 0.0, "z": 0.0} for i in range(5)]
    strip = marker_primitives(_marker(type=4, points=pts, scale={"x": 0.05}), SHIFT)[0]
    assert strip["shape"] == "polyline" and strip["points"][0] == [10.0, 0.0]
    assert strip["width"] == 0.05
    lines = marker_primitives(_marker(type=5, points=pts), Transform3())[0]
    assert lines["shape"] == "lines" and len(lines["points"]) == 4  # odd point dropped
    colours = [{"r": 0.0, "g": 1.0, "b": 0.0, "a": 1.0}] * 5
    dots = marker_primitives(_marker(type=8, points=pts, colors=colours), Transform3())[0]
    assert dots["shape"] == "points" and dots["colors"][0] == [0.0, 1.0, 0.0, 1.0]
    text = marker_primitives(_marker(type=9, text="hi", scale={"z": 0.3}), SHIFT)[0]
    assert text == {"shape": "text", "rgba": [1.0, 0.0, 0.0, 1.0], "points": [[10.0, 0.0]],
                    "text": "hi", "height": 0.3}  # fmt: skip
    assert marker_primitives(_marker(type=10), SHIFT) == []  # meshes are not drawn


def test_marker_store_add_delete_deleteall_lifetime_and_frame_lock() -> None:
    where = {"base": Transform3((1.0, 0.0, 0.0))}
    store = MarkerStore(lambda f: where.get(f))
    assert store.add(_marker(type=1, id=1), 0)
    assert store.add(_marker(type=1, id=2, lifetime={"sec": 2, "nanosec": 0}), 0)
    assert len(store) == 2
    assert not store.add(_marker(type=1, id=3, header={"frame_id": "nowhere"}), 0)
    assert "nowhere" in next(iter(store.errors.values()))
    assert store.refresh(2_000_000_000) and len(store) == 1  # id 2 expired
    assert store.add(_marker(id=1, action=2), 0) and len(store) == 0  # DELETE
    store.add(_marker(type=1, id=5), 0)
    store.add(_marker(type=1, id=6, frame_locked=True), 0)
    before = np.array(store.primitives()[1]["points"])
    where["base"] = Transform3((5.0, 0.0, 0.0))
    assert store.refresh(1)
    after = np.array(store.primitives()[1]["points"])
    assert np.allclose(after - before, [4.0, 0.0])  # the locked marker moved with its frame
    assert np.allclose(store.primitives()[0]["points"], np.array(store.primitives()[0]["points"]))
    assert store.add(_marker(action=3), 0) and len(store) == 0  # DELETEALL


def test_pose_trail_keeps_n_beyond_tolerance() -> None:
    trail = PoseTrail(keep=3, position_tolerance_m=0.1, angle_tolerance_rad=0.1)
    assert trail.add(0.0, 0.0, 0.0)
    assert not trail.add(0.05, 0.0, 0.05)  # within both tolerances
    assert trail.add(0.0, 0.0, 0.2)  # turned
    for i in range(1, 4):
        assert trail.add(float(i), 0.0, 0.2)
    arr = trail.array()
    assert arr.shape == (3, 3) and arr[:, 0].tolist() == [1.0, 2.0, 3.0]


def test_poses_in_fixed_turn_headings() -> None:
    tf = Transform3((1.0, 0.0, 0.0), tuple(quat_from_yaw(math.pi / 2)))
    out = poses_in_fixed(tf, np.array([[1.0, 0.0, 0.0]]), np.array([quat_from_yaw(0.3)]))
    assert np.allclose(out, [[1.0, 1.0, math.pi / 2 + 0.3]])


def test_map_change_window() -> None:
    old = np.zeros((50, 40), dtype=np.int8)
    new = old.copy()
    assert map_change(old, new) is None
    new[10, 5] = 100
    new[12, 8] = -1
    x0, y0, window = map_change(old, new)  # type: ignore[misc]
    assert (x0, y0, window.shape) == (5, 10, (3, 4))
    assert window[0, 0] == 100 and window[2, 3] == -1


def test_colour_buckets_and_decimation() -> None:
    idx, pal, bounds = color_buckets("FlatColor", count=5, flat_rgb=[1, 2, 3], alpha=0.5)
    assert idx is None and pal.tolist() == [[1, 2, 3, 128]] and bounds is None
    z = np.array([0.0, 0.5, 1.0, np.nan])
    idx, pal, bounds = color_buckets("AxisColor", count=4, flat_rgb=[0, 0, 0], alpha=1.0, values=z)
    assert idx is not None and idx.tolist() == [0, 32, 63, 0] and len(pal) == 64
    assert bounds == (0.0, 1.0)
    # rviz's AxisColor: the lowest point red, the highest magenta
    assert pal[0, :3].tolist() == [255, 0, 0] and pal[-1, :3].tolist() == [255, 0, 255]
    pts = np.arange(100_000).reshape(-1, 2)
    assert len(decimate(pts, 20_000)) <= 20_000 and len(decimate(pts, 0)) == 50_000


def test_pose_covariance_primitives_draw_the_sigma_ellipse_and_yaw_wedge() -> None:
    c, s = math.cos(0.5), math.sin(0.5)
    rot = np.array([[c, -s], [s, c]])
    cov = rot @ np.diag([0.3**2, 0.1**2]) @ rot.T  # 0.3 m along 0.5 rad, 0.1 m across
    items = pose_covariance_primitives((1.0, 2.0, 0.2), cov, 0.1**2, rgb=[255, 0, 0],
                                       alpha=0.9, length=1.0, scale=2.0)  # fmt: skip
    ellipse, outline, wedge, arrow = items
    assert [i["shape"] for i in items] == ["polygon", "polyline", "polygon", "arrow"]
    pts = np.array(ellipse["points"]) - (1.0, 2.0)
    local = pts @ rot  # into the ellipse's axes
    assert np.abs(local[:, 0]).max() == pytest.approx(0.6, abs=1e-3)  # 2 sigma
    assert np.abs(local[:, 1]).max() == pytest.approx(0.2, abs=2e-3)
    assert outline["points"][0] == outline["points"][-1]
    assert ellipse["rgba"] == [1.0, 0.0, 0.0, 0.3] and arrow["rgba"] == [1.0, 0.0, 0.0, 0.9]
    angles = np.arctan2(*(np.array(wedge["points"][1:]) - (1.0, 2.0)).T[::-1])
    assert angles.min() == pytest.approx(0.0, abs=1e-3)  # yaw 0.2 -+ 2 sigma (0.1)
    assert angles.max() == pytest.approx(0.4, abs=1e-3)
    assert arrow["yaw"] == 0.2 and arrow["points"] == [[1.0, 2.0]]
    # no covariance (NaN) or no yaw variance: just the arrow
    only = pose_covariance_primitives((0, 0, 0), np.full((2, 2), np.nan), 0.0, rgb=[0, 0, 0],
                                      alpha=1.0, length=1.0)  # fmt: skip
    assert [i["shape"] for i in only] == ["arrow"]


def test_poses3_keep_height_and_full_orientation() -> None:
    tf = Transform3((1.0, 0.0, 0.5), tuple(quat_from_yaw(math.pi / 2)))
    pitch = quat_from_rpy(0.0, -math.pi / 4, 0.0)
    out = poses3_in_fixed(tf, np.array([[1.0, 0.0, 1.0]]), np.array([pitch]))
    assert np.allclose(out[0, :3], [1.0, 1.0, 1.5])
    want = quat_multiply(quat_from_yaw(math.pi / 2), pitch)
    assert np.allclose(out[0, 3:], want) and yaw_of_poses3(out)[0] == pytest.approx(math.pi / 2)
    zero = poses3_in_fixed(Transform3(), np.zeros((1, 3)), np.zeros((1, 4)))
    assert zero[0, 3:].tolist() == [0.0, 0.0, 0.0, 1.0]  # a zero quaternion: identity


def test_marker_3d_keeps_pose_scale_points_and_text() -> None:
    m = _marker(type=4, points=[{"x": 0.0, "y": 0.0, "z": 1.0}, {"x": 1.0, "y": 0.0, "z": 2.0}])
    m.pose.orientation.x, m.pose.orientation.w = math.sin(0.25), math.cos(0.25)
    m.colors = [m.color, m.color]
    solid = marker_3d(m, Transform3((0.0, 0.0, 1.0)))
    assert solid["type"] == 4 and solid["pose"][2] == pytest.approx(m.pose.position.z + 1.0)
    assert solid["pose"][3] == pytest.approx(math.sin(0.25), abs=1e-6)
    assert solid["points"] == [[0.0, 0.0, 1.0], [1.0, 0.0, 2.0]] and len(solid["colors"]) == 2
    assert "text" not in solid
    text = marker_3d(_marker(type=9, text="hi"), Transform3())
    assert text["text"] == "hi" and "points" not in text
