"""The dashboard's pure parts: frame encodings, image conversion, URDF top views."""

from __future__ import annotations

import io
import math
import struct

import numpy as np
import pytest
from PIL import Image

from roverlab.description.urdf import parse_urdf
from roverlab.geometry import Transform3, quat_from_yaw
from roverlab.viz.protocol import (
    IMAGE_JPEG,
    IMAGE_PNG,
    INITIALPOSE_COVARIANCE,
    KIND_IMAGE,
    KIND_MAP,
    KIND_MAP_PATCH,
    KIND_PATH,
    KIND_POINTS,
    KIND_POSES,
    KIND_SCAN,
    colorize,
    convex_hull,
    encode_image,
    encode_image_file,
    encode_map,
    encode_map_patch,
    encode_path,
    encode_points,
    encode_poses,
    encode_scan,
    image_to_rgb8,
    rainbow,
    robot_outlines,
)
from roverlab.viz.server import is_loopback

URDF = """<robot name="r">
  <material name="blue"><color rgba="0 0 0.8 1"/></material>
  <link name="base_link"><visual><geometry><box size="0.4 0.2 0.1"/></geometry>
    <material name="blue"/></visual></link>
  <link name="wheel"><visual><geometry><cylinder radius="0.05" length="0.02"/></geometry>
    </visual></link>
  <joint name="j" type="fixed"><parent link="base_link"/><child link="wheel"/>
    <origin xyz="0 0.12 0" rpy="1.5707963 0 0"/></joint>
</robot>"""


def test_map_frame_round_trips() -> None:
    cells = np.array([[0, 100, -1], [50, 0, 0]], dtype=np.int8)
    frame = encode_map(cells, resolution_m=0.05, origin=(-1.0, 2.0, 0.5))
    kind, w, h, res, ox, oy, oyaw = struct.unpack_from("<B3xIIffff", frame)  # slot 0
    assert (kind, w, h) == (KIND_MAP, 3, 2)
    assert math.isclose(res, 0.05, rel_tol=1e-6) and (ox, oy) == (-1.0, 2.0)
    assert math.isclose(oyaw, 0.5, rel_tol=1e-6)
    assert np.array_equal(np.frombuffer(frame[28:], dtype=np.int8).reshape(2, 3), cells)


def test_scan_frame_round_trips() -> None:
    pts = np.array([[1.0, 2.0], [-3.5, 0.25]])
    frame = encode_scan(pts)
    assert frame[0] == KIND_SCAN and struct.unpack_from("<II", frame, 4) == (2, 1)
    assert struct.unpack_from("<I", frame, 12)[0] == 2  # one bucket of both points
    assert frame[16:20] == bytes([255, 0, 0, 255])
    assert np.array_equal(np.frombuffer(frame[20:], dtype="<f4").reshape(-1, 2), pts)


def test_points_are_sorted_into_colour_buckets() -> None:
    pts = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]])
    palette = [(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 128)]
    frame = encode_points(pts, np.array([2, 0, 2, 0]), palette, slot=7)
    kind, _, slot, n, nb = struct.unpack_from("<BBHII", frame)
    assert (kind, slot, n, nb) == (KIND_POINTS, 7, 4, 3)
    counts = np.frombuffer(frame[12:24], dtype="<u4")
    assert counts.tolist() == [2, 0, 2]
    assert frame[24:36] == bytes([255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 128])
    out = np.frombuffer(frame[36:], dtype="<f4").reshape(-1, 2)
    assert out.tolist() == [[1, 1], [3, 3], [0, 0], [2, 2]]


def test_pose_path_and_patch_frames() -> None:
    poses = np.array([[1.0, 2.0, 0.5]])
    f = encode_poses(poses, slot=3)
    assert struct.unpack_from("<BBHI", f) == (KIND_POSES, 0, 3, 1)
    assert np.allclose(np.frombuffer(f[8:], dtype="<f4"), [1.0, 2.0, 0.5])
    p = encode_path(np.array([[0.0, 0.0], [1.0, 0.5]]))
    assert struct.unpack_from("<BBHI", p) == (KIND_PATH, 0, 0, 2)
    cells = np.array([[1, 2, 3]], dtype=np.int8)
    m = encode_map_patch(cells, 4, 5)
    assert struct.unpack_from("<BBHIIII", m) == (KIND_MAP_PATCH, 0, 0, 4, 5, 3, 1)
    assert m[20:] == cells.tobytes()


def test_compressed_images_pass_through() -> None:
    buf = io.BytesIO()
    Image.fromarray(np.zeros((4, 4, 3), dtype=np.uint8)).save(buf, format="PNG")
    png = buf.getvalue()
    frame = encode_image_file(png)
    assert frame[0] == KIND_IMAGE and frame[1] == IMAGE_PNG and frame[4:] == png
    jpeg = encode_image(np.zeros((4, 4, 3), dtype=np.uint8))[4:]
    assert encode_image_file(jpeg)[1] == IMAGE_JPEG
    with pytest.raises(ValueError, match="neither JPEG nor PNG"):
        encode_image_file(b"GIF89a....")


def test_image_frame_is_a_jpeg_of_rgb_pixels() -> None:
    bgr = np.zeros((8, 8, 3), dtype=np.uint8)
    bgr[..., 0] = 255  # blue in BGR
    rgb = image_to_rgb8(bgr, "bgr8")
    assert rgb[0, 0].tolist() == [0, 0, 255]
    frame = encode_image(rgb)
    assert frame[0] == KIND_IMAGE
    decoded = np.asarray(Image.open(io.BytesIO(frame[4:])))
    assert decoded.shape == (8, 8, 3) and decoded[4, 4, 2] > 200 and decoded[4, 4, 0] < 50


def test_depth_image_is_scaled_to_eight_bits() -> None:
    depth = np.array([[1.0, 2.0], [3.0, np.nan]], dtype=np.float32)
    out = image_to_rgb8(depth, "32FC1")
    assert out.dtype == np.uint8 and out.tolist() == [[0, 127], [255, 0]]


def test_depth_colour_maps() -> None:
    depth = np.array([[0, 1000, 2000, 3000]], dtype=np.uint16)  # 16UC1 mm; 0 = no data
    jet = image_to_rgb8(depth, "16UC1", color_map="jet")
    assert jet.shape == (1, 4, 3)
    assert jet[0, 0].tolist() == [0, 0, 0]  # no data: black
    assert jet[0, 1, 2] > 100 and jet[0, 1, 0] == 0  # near: blue
    assert jet[0, 3, 0] > 100 and jet[0, 3, 2] == 0  # far: red
    fixed = colorize(np.array([[1.0, 5.0, 9.0]]), "gray", min_value=1.0, max_value=5.0)
    assert fixed[0, :, 0].tolist() == [0, 255, 255]  # clipped at max_value
    hot = colorize(np.array([[0.0, 1.0]]), "hot")
    assert hot[0, 0].tolist() == [0, 0, 0] and hot[0, 1].tolist() == [255, 255, 255]
    with pytest.raises(ValueError, match="unknown colour map"):
        colorize(depth, "viridis")


def test_rainbow_runs_from_magenta_to_red() -> None:
    ends = (rainbow(np.array([0.0, 0.5, 1.0])) * 255).round().astype(int).tolist()
    assert ends[0] == [255, 0, 255] and ends[2] == [255, 0, 0]
    assert ends[1][1] == 255  # the middle is green-ish


def test_convex_hull_drops_inner_points() -> None:
    hull = convex_hull([(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)])
    assert sorted(hull) == [(0, 0), (0, 1), (1, 0), (1, 1)]


def test_robot_outlines_project_boxes_and_upright_wheels() -> None:
    model = parse_urdf(URDF)
    outlines = {o.link: o for o in robot_outlines(model)}
    assert outlines["base_link"].rgba == (0.0, 0.0, 0.8, 1.0)
    pose = Transform3((1.0, 2.0, 0.0), tuple(quat_from_yaw(math.pi / 2)))
    box = np.array(outlines["base_link"].footprint(pose))
    # turned by 90 degrees, the 0.4 x 0.2 box spans 0.2 in x and 0.4 in y around (1, 2)
    assert np.allclose(box.min(axis=0), [0.9, 1.8]) and np.allclose(box.max(axis=0), [1.1, 2.2])
    wheel_pose = model.link_transform("wheel")
    wheel = np.array(outlines["wheel"].footprint(wheel_pose))
    # a wheel on a horizontal axle is seen from above as a 0.1 x 0.02 rectangle
    span = wheel.max(axis=0) - wheel.min(axis=0)
    assert np.allclose(span, [0.1, 0.02], atol=1e-3)


def test_initialpose_covariance_is_rviz_default() -> None:
    cov = np.array(INITIALPOSE_COVARIANCE).reshape(6, 6)
    assert cov[0, 0] == 0.25 and cov[1, 1] == 0.25 and cov[5, 5] == 0.06853891945200942
    assert np.count_nonzero(cov) == 3


def test_loopback_hosts() -> None:
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("::1")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.5")


def test_points_in_3d_with_per_point_rgb() -> None:
    from roverlab.viz.protocol import POINTS_RGB, POINTS_XYZ, encode_points

    xyz = np.array([[1.0, 2.0, 0.5], [3.0, 4.0, 1.5]])
    rgb = np.array([[255, 0, 0], [0, 0, 255]], dtype=np.uint8)
    frame = encode_points(xyz, None, [[255, 255, 255, 128]], rgb=rgb, slot=3)
    kind, flags, slot, n, nb = struct.unpack_from("<BBHII", frame)
    assert (kind, flags, slot, n, nb) == (KIND_POINTS, POINTS_XYZ | POINTS_RGB, 3, 2, 1)
    at = 12 + 8 * nb
    pts = np.frombuffer(frame, "<f4", 6, at).reshape(2, 3)
    np.testing.assert_allclose(pts, xyz)
    colours = np.frombuffer(frame, np.uint8, 8, at + 24).reshape(2, 4)
    assert colours.tolist() == [[255, 0, 0, 128], [0, 0, 255, 128]]
    flat = encode_points(xyz[:, :2])  # 2-D points keep the old layout (no flags)
    assert struct.unpack_from("<B", flat, 1)[0] == 0


def test_robot_shapes_keep_geometry_origin_and_colour() -> None:
    from roverlab.viz.protocol import robot_shapes

    model = parse_urdf(
        """<robot name="r">
        <link name="base_link"><visual><origin xyz="0 0 0.1"/>
          <geometry><cylinder radius="0.2" length="0.1"/></geometry>
          <material name="y"><color rgba="1 1 0 0.5"/></material></visual></link>
        <link name="cam"><visual><geometry><box size="0.1 0.2 0.3"/></geometry></visual>
          <visual><geometry><mesh filename="package://p/m.stl" scale="2 2 2"/></geometry></visual>
        </link>
        <joint name="j" type="fixed"><parent link="base_link"/><child link="cam"/></joint>
        </robot>""",
        source="r.urdf",
    )
    shapes = {(s.link, s.geometry["type"]): s for s in robot_shapes(model)}
    cyl = shapes[("base_link", "cylinder")]
    assert cyl.geometry == {"type": "cylinder", "radius": 0.2, "length": 0.1}
    assert cyl.origin == [0.0, 0.0, 0.1, 0.0, 0.0, 0.0, 1.0]
    assert cyl.rgba == (1.0, 1.0, 0.0, 0.5)
    assert shapes[("cam", "box")].geometry["size"] == [0.1, 0.2, 0.3]
    assert shapes[("cam", "box")].rgba == (0.6, 0.6, 0.6, 1.0)
    assert shapes[("cam", "mesh")].geometry == {
        "type": "mesh",
        "filename": "package://p/m.stl",
        "scale": [2.0, 2.0, 2.0],
    }
