"""The dashboard's pure parts: frame encodings, image conversion, URDF top views."""

from __future__ import annotations

import io
import math
import struct

import numpy as np
from PIL import Image

from roverlab.description.urdf import parse_urdf
from roverlab.geometry import Transform3, quat_from_yaw
from roverlab.viz.protocol import (
    INITIALPOSE_COVARIANCE,
    KIND_IMAGE,
    KIND_MAP,
    KIND_SCAN,
    convex_hull,
    encode_image,
    encode_map,
    encode_scan,
    image_to_rgb8,
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
    kind, w, h, res, ox, oy, oyaw = struct.unpack_from("<B3xIIffff", frame)
    assert (kind, w, h) == (KIND_MAP, 3, 2)
    assert math.isclose(res, 0.05, rel_tol=1e-6) and (ox, oy) == (-1.0, 2.0)
    assert math.isclose(oyaw, 0.5, rel_tol=1e-6)
    assert np.array_equal(np.frombuffer(frame[28:], dtype=np.int8).reshape(2, 3), cells)


def test_scan_frame_round_trips() -> None:
    pts = np.array([[1.0, 2.0], [-3.5, 0.25]])
    frame = encode_scan(pts)
    assert frame[0] == KIND_SCAN and struct.unpack_from("<I", frame, 4)[0] == 2
    assert np.array_equal(np.frombuffer(frame[8:], dtype="<f4").reshape(-1, 2), pts)


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
