"""numpy converters: scans, orientation, poses, grids, stamps, images, point clouds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab import msgs
from roverlab.msgs import MessageValueError, deserialize, serialize


def _tiny_scan() -> object:
    # 4 beams at -90, 0, 90, 180 degrees
    return msgs.make_scan(
        [1.0, 2.0, np.inf, 0.5],
        angle_min=-math.pi / 2,
        angle_max=math.pi,
        range_min=0.1,
        range_max=10.0,
        stamp=1_500_000_000,
    )


def test_make_scan_fields() -> None:
    scan = _tiny_scan()
    assert scan.angle_increment == pytest.approx(math.pi / 2)
    assert scan.header.frame_id == "laser"
    assert (scan.header.stamp.sec, scan.header.stamp.nanosec) == (1, 500_000_000)
    assert scan.ranges.dtype == np.float32 and len(scan.ranges) == 4
    assert scan.intensities.shape == (0,)
    with pytest.raises(MessageValueError, match="intensities"):
        msgs.make_scan(
            [1.0, 2.0], angle_min=0, angle_max=1, range_min=0, range_max=5, intensities=[1]
        )


def test_scan_angles() -> None:
    np.testing.assert_allclose(
        msgs.scan_angles(_tiny_scan()), [-math.pi / 2, 0.0, math.pi / 2, math.pi], atol=1e-6
    )


def test_scan_to_points_geometry() -> None:
    pts = msgs.scan_to_points(_tiny_scan())
    assert pts.dtype == np.float64 and pts.shape == (3, 2)  # inf beam dropped
    np.testing.assert_allclose(pts, [[0.0, -1.0], [2.0, 0.0], [-0.5, 0.0]], atol=1e-6)


def test_scan_to_points_range_limits_and_keep_invalid() -> None:
    scan = msgs.make_scan(
        [0.05, 1.0, 11.0, np.nan], angle_min=0.0, angle_max=0.3, range_min=0.1, range_max=10.0
    )
    pts = msgs.scan_to_points(scan)
    assert pts.shape == (1, 2)
    np.testing.assert_allclose(pts[0], [math.cos(0.1), math.sin(0.1)], atol=1e-6)
    every = msgs.scan_to_points(scan, keep_invalid=True)
    assert every.shape == (4, 2)
    assert np.isnan(every[3]).all()
    np.testing.assert_allclose(every[2], [11.0 * math.cos(0.2), 11.0 * math.sin(0.2)], atol=1e-5)


@pytest.mark.parametrize("yaw", [0.0, 0.3, -1.2, math.pi / 2, 3.0, -3.0])
def test_quaternion_yaw_round_trip(yaw: float) -> None:
    q = msgs.quaternion_from_yaw(yaw)
    assert isinstance(q, msgs.Quaternion)
    assert (q.x, q.y) == (0.0, 0.0)
    assert q.z == pytest.approx(math.sin(yaw / 2)) and q.w == pytest.approx(math.cos(yaw / 2))
    assert msgs.yaw_from_quaternion(q) == pytest.approx(yaw)


def test_pose_xytheta_round_trip() -> None:
    pose = msgs.pose_from_xytheta(1.5, -2.0, 0.75)
    assert isinstance(pose, msgs.Pose)
    assert (pose.position.x, pose.position.y, pose.position.z) == (1.5, -2.0, 0.0)
    x, y, theta = msgs.xytheta_from_pose(pose)
    assert (x, y) == (1.5, -2.0) and theta == pytest.approx(0.75)


def test_time_ns_conversions() -> None:
    t = msgs.time_from_ns(12_000_000_345)
    assert isinstance(t, msgs.Time)
    assert (t.sec, t.nanosec) == (12, 345)
    assert msgs.time_to_ns(t) == 12_000_000_345
    assert msgs.time_to_ns(msgs.Duration(sec=-1, nanosec=500_000_000)) == -500_000_000
    neg = msgs.time_from_ns(-1)
    assert (neg.sec, neg.nanosec) == (-1, 999_999_999)
    with pytest.raises(MessageValueError, match="out of range for int32"):
        msgs.time_from_ns(2**31 * 1_000_000_000)


def test_stamp_forms() -> None:
    class FakeTime:
        nanoseconds = 3_000_000_001

    assert msgs.time_to_ns(msgs.stamp_to_msg(FakeTime())) == 3_000_000_001
    assert msgs.time_to_ns(msgs.stamp_to_msg(None)) == 0
    stamp = msgs.Time(sec=4)
    assert msgs.stamp_to_msg(stamp) is stamp
    with pytest.raises(MessageValueError, match="expected a stamp"):
        msgs.stamp_to_msg(1.5)


def test_occupancy_grid_round_trip() -> None:
    cells = np.array([[0, 100, -1], [50, 0, 0]], dtype=np.int8)
    grid = msgs.array_to_occupancy_grid(
        cells, resolution=0.05, origin=(1.0, -2.0, 0.5), stamp=7_000_000_000
    )
    assert (grid.info.width, grid.info.height) == (3, 2)
    assert grid.info.resolution == pytest.approx(0.05)
    assert grid.header.frame_id == "map" and grid.header.stamp.sec == 7
    assert grid.info.map_load_time.sec == 7
    assert grid.data.tolist() == [0, 100, -1, 50, 0, 0]  # row 0 first (y = origin)
    assert msgs.xytheta_from_pose(grid.info.origin) == pytest.approx((1.0, -2.0, 0.5))
    back = msgs.occupancy_grid_to_array(deserialize(serialize(grid), "nav_msgs/msg/OccupancyGrid"))
    assert back.dtype == np.int8 and back.shape == (2, 3)
    np.testing.assert_array_equal(back, cells)


def test_occupancy_grid_validation() -> None:
    with pytest.raises(MessageValueError, match="-1"):
        msgs.array_to_occupancy_grid(np.array([[101]]), resolution=1.0)
    with pytest.raises(MessageValueError, match="2-D"):
        msgs.array_to_occupancy_grid(np.zeros(3), resolution=1.0)
    bad = msgs.OccupancyGrid(info_width=2, info_height=2, data=[0, 0, 0])
    with pytest.raises(MessageValueError, match="3 cells for 2x2"):
        msgs.occupancy_grid_to_array(bad)


@pytest.mark.parametrize(
    ("encoding", "dtype", "shape"),
    [
        ("rgb8", np.uint8, (3, 4, 3)),
        ("bgr8", np.uint8, (3, 4, 3)),
        ("mono8", np.uint8, (3, 4)),
        ("16UC1", np.uint16, (3, 4)),
        ("mono16", np.uint16, (2, 5)),
        ("32FC1", np.float32, (3, 4)),
        ("rgba8", np.uint8, (1, 2, 4)),
        ("64FC3", np.float64, (2, 2, 3)),
    ],
)
def test_image_round_trip(
    encoding: str, dtype: type, shape: tuple[int, ...], rng: np.random.Generator
) -> None:
    arr = (rng.random(shape) * 200).astype(dtype)
    img = msgs.array_to_image(arr, encoding, frame_id="cam", stamp=5)
    assert img.encoding == encoding and img.header.frame_id == "cam"
    assert (img.height, img.width) == shape[:2]
    assert img.step == shape[1] * arr.itemsize * (shape[2] if len(shape) == 3 else 1)
    back = msgs.image_to_array(deserialize(serialize(img), "sensor_msgs/msg/Image"))
    assert back.dtype == np.dtype(dtype) and back.shape == shape
    np.testing.assert_array_equal(back, arr)


def test_image_to_array_honours_step_padding() -> None:
    # 2x3 mono8 with 2 padding bytes per row
    data = bytes([1, 2, 3, 0, 0, 4, 5, 6, 0, 0])
    img = msgs.Image(height=2, width=3, step=5, encoding="mono8", data=data)
    np.testing.assert_array_equal(msgs.image_to_array(img), [[1, 2, 3], [4, 5, 6]])


def test_image_to_array_big_endian() -> None:
    values = np.array([[1, 258]], dtype=">u2")
    img = msgs.Image(
        height=1, width=2, step=4, encoding="16UC1", is_bigendian=1, data=values.tobytes()
    )
    back = msgs.image_to_array(img)
    assert back.dtype.byteorder in "=<|"
    assert back.tolist() == [[1, 258]]


def test_image_errors() -> None:
    with pytest.raises(MessageValueError, match="unsupported image encoding"):
        msgs.array_to_image(np.zeros((2, 2), np.uint8), "jpeg")
    with pytest.raises(MessageValueError, match="3 channel"):
        msgs.array_to_image(np.zeros((2, 2), np.uint8), "rgb8")
    with pytest.raises(MessageValueError, match="out of range"):
        msgs.array_to_image(np.full((2, 2), 300), "mono8")
    short = msgs.Image(height=2, width=2, step=2, encoding="mono8", data=b"\x00\x00\x00")
    with pytest.raises(MessageValueError, match="cannot hold"):
        msgs.image_to_array(short)


def test_pointcloud_round_trip(rng: np.random.Generator) -> None:
    pts = rng.normal(size=(50, 3)).astype(np.float32)
    pc = msgs.xyz_to_pointcloud2(pts, "velodyne", 9)
    assert [f.name for f in pc.fields] == ["x", "y", "z"]
    assert [f.offset for f in pc.fields] == [0, 4, 8]
    assert all(f.datatype == msgs.PointField.FLOAT32 and f.count == 1 for f in pc.fields)
    assert (pc.height, pc.width, pc.point_step, pc.row_step) == (1, 50, 12, 600)
    assert pc.is_dense is True and pc.is_bigendian is False
    back = msgs.pointcloud2_to_xyz(deserialize(serialize(pc), "sensor_msgs/msg/PointCloud2"))
    assert back.dtype == np.float32 and back.shape == (50, 3)
    np.testing.assert_array_equal(back, pts)


def test_pointcloud_rgb_round_trip() -> None:
    pts = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    rgb = np.array([[255, 0, 10], [1, 128, 255]], dtype=np.uint8)
    pc = msgs.xyz_to_pointcloud2(pts, "map", rgb=rgb)
    assert [f.name for f in pc.fields] == ["x", "y", "z", "rgb"]
    assert pc.point_step == 16 and pc.fields[3].offset == 12
    packed = np.frombuffer(pc.data.tobytes(), dtype="<u4").reshape(2, 4)[:, 3]
    assert packed.tolist() == [0xFF000A, 0x0180FF]
    np.testing.assert_array_equal(msgs.pointcloud2_to_xyz(pc), pts.astype(np.float32))
    np.testing.assert_array_equal(msgs.pointcloud2_to_rgb(pc), rgb)
    floats = msgs.xyz_to_pointcloud2(pts, "map", rgb=rgb / 255.0)
    np.testing.assert_array_equal(msgs.pointcloud2_to_rgb(floats), rgb)


def test_pointcloud_to_xyz_handles_padding_offsets_and_nans() -> None:
    # organised 2x2 cloud, float64 z before float32 x/y, 4 bytes padding per point and row
    record = np.dtype(
        {
            "names": ["z", "x", "y"],
            "formats": ["<f8", "<f4", "<f4"],
            "offsets": [0, 8, 12],
            "itemsize": 20,
        }
    )
    rows = np.zeros((2, 2), dtype=record)
    rows["x"] = [[1, 2], [3, 4]]
    rows["y"] = [[5, 6], [7, np.nan]]
    rows["z"] = [[9, 10], [11, 12]]
    raw = b"".join(rows[i].tobytes() + b"\xee" * 8 for i in range(2))
    fields = [
        msgs.PointField(name="z", offset=0, datatype=msgs.PointField.FLOAT64, count=1),
        msgs.PointField(name="x", offset=8, datatype=msgs.PointField.FLOAT32, count=1),
        msgs.PointField(name="y", offset=12, datatype=msgs.PointField.FLOAT32, count=1),
    ]
    pc = msgs.PointCloud2(height=2, width=2, fields=fields, point_step=20, row_step=48, data=raw)
    xyz = msgs.pointcloud2_to_xyz(pc)
    np.testing.assert_array_equal(xyz[:3], [[1, 5, 9], [2, 6, 10], [3, 7, 11]])
    assert np.isnan(xyz[3, 1])
    assert msgs.pointcloud2_to_xyz(pc, skip_nans=True).shape == (3, 3)


def test_pointcloud_errors() -> None:
    with pytest.raises(MessageValueError, match=r"\(N, 3\)"):
        msgs.xyz_to_pointcloud2(np.zeros((4, 2)), "map")
    with pytest.raises(MessageValueError, match="no point field 'x'"):
        msgs.pointcloud2_to_xyz(msgs.PointCloud2())
    with pytest.raises(MessageValueError, match=r"0\.\.255"):
        msgs.xyz_to_pointcloud2(np.zeros((1, 3)), "map", rgb=[[0, 0, 256]])
