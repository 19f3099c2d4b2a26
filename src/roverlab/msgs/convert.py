"""Converters between messages and numpy arrays / plain numbers.

The explicit boundary between algorithms (which work on arrays, SI units, radians) and
messages: scans to points, quaternions to yaw, poses to ``(x, y, theta)``, occupancy grids,
images and point clouds to arrays, stamps to integer nanoseconds.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import quat_from_yaw, yaw_from_quat

from . import classes as mc
from .errors import MessageValueError
from .factory import (
    Header,
    Image,
    LaserScan,
    MapMetaData,
    OccupancyGrid,
    PointCloud2,
    PointField,
    Quaternion,
    Time,
)

__all__ = [
    "array_to_image",
    "array_to_occupancy_grid",
    "image_to_array",
    "make_scan",
    "occupancy_grid_to_array",
    "pointcloud2_field",
    "pointcloud2_to_rgb",
    "pointcloud2_to_xyz",
    "pose_from_xytheta",
    "poses_from_xytheta",
    "quaternion_from_yaw",
    "scan_angles",
    "scan_to_points",
    "stamp_to_msg",
    "time_from_ns",
    "time_to_ns",
    "xytheta_from_pose",
    "xyz_to_pointcloud2",
    "yaw_from_quaternion",
]

_NS_PER_S: Final = 1_000_000_000

#: A stamp: a ``builtin_interfaces/Time`` message, integer nanoseconds, an object with an
#: integer ``nanoseconds`` attribute (``roverlab.core.time.Time``), or ``None`` for zero.
Stamp = Any


# -------------------------------------------------------------------------------------- time


def time_to_ns(stamp: Any) -> int:
    """Integer nanoseconds of a ``builtin_interfaces/Time`` (or ``Duration``) message."""
    return int(stamp.sec) * _NS_PER_S + int(stamp.nanosec)


def time_from_ns(ns: int) -> mc.Time:
    """A ``builtin_interfaces/Time`` message of integer nanoseconds (``nanosec`` in [0, 1e9)).

    Raises:
        MessageValueError: ``sec`` does not fit int32.
    """
    sec, nanosec = divmod(int(ns), _NS_PER_S)
    return Time(sec=sec, nanosec=nanosec)


def stamp_to_msg(stamp: Stamp) -> mc.Time:
    """A ``builtin_interfaces/Time`` message of any accepted stamp form (see :data:`Stamp`)."""
    if stamp is None:
        return Time()
    if isinstance(stamp, Time.cls):
        return stamp
    if isinstance(stamp, int | np.integer):
        return time_from_ns(int(stamp))
    nanoseconds = getattr(stamp, "nanoseconds", None)
    if isinstance(nanoseconds, int):
        return time_from_ns(nanoseconds)
    raise MessageValueError(
        f"expected a stamp (Time message, int nanoseconds or None), got {type(stamp).__name__}"
    )


def _header(frame_id: str, stamp: Stamp) -> mc.Header:
    return Header(stamp=stamp_to_msg(stamp), frame_id=frame_id)


# ------------------------------------------------------------------------------ orientation


def quaternion_from_yaw(yaw: float) -> mc.Quaternion:
    """A ``geometry_msgs/Quaternion`` of a rotation by ``yaw`` radians about +z."""
    x, y, z, w = (float(v) for v in quat_from_yaw(yaw))
    return Quaternion(x=x, y=y, z=z, w=w)


def yaw_from_quaternion(q: Any) -> float:
    """Yaw in radians of a ``geometry_msgs/Quaternion`` (as tf2's ``getYaw``)."""
    return yaw_from_quat((q.x, q.y, q.z, q.w))


def pose_from_xytheta(x: float, y: float, theta: float) -> mc.Pose:
    """A planar ``geometry_msgs/Pose``: position ``(x, y, 0)`` in m, heading ``theta`` in rad."""
    half = 0.5 * float(theta)
    return mc.Pose(
        mc.Point(float(x), float(y), 0.0),
        mc.Quaternion(0.0, 0.0, math.sin(half), math.cos(half)),
    )


def poses_from_xytheta(rows: ArrayLike) -> list[mc.Pose]:
    """Planar ``geometry_msgs/Pose`` messages of ``(N, 3)`` ``x, y, theta`` rows (a particle
    cloud, a path): one vectorised pass for the trigonometry."""
    a = np.asarray(rows, dtype=np.float64).reshape(-1, 3)
    s = np.sin(0.5 * a[:, 2]).tolist()
    c = np.cos(0.5 * a[:, 2]).tolist()
    point, quat, pose = mc.Point, mc.Quaternion, mc.Pose
    return [
        pose(point(x, y, 0.0), quat(0.0, 0.0, si, ci))
        for x, y, si, ci in zip(a[:, 0].tolist(), a[:, 1].tolist(), s, c, strict=True)
    ]


def xytheta_from_pose(pose: Any) -> tuple[float, float, float]:
    """``(x, y, theta)`` of a ``geometry_msgs/Pose`` (z and roll/pitch ignored)."""
    return float(pose.position.x), float(pose.position.y), yaw_from_quaternion(pose.orientation)


# ------------------------------------------------------------------------------------- scans


def scan_angles(scan: Any) -> NDArray[np.float64]:
    """Angle in radians of each beam: ``angle_min + i * angle_increment``."""
    count = len(scan.ranges)
    return float(scan.angle_min) + np.arange(count, dtype=np.float64) * float(scan.angle_increment)


def scan_to_points(scan: Any, *, keep_invalid: bool = False) -> NDArray[np.float64]:
    """Beam end points of a ``sensor_msgs/LaserScan`` in its frame, shape ``(N, 2)``, m.

    Args:
        scan: The scan.
        keep_invalid: Keep every beam (NaN/inf ranges give non-finite points) instead of
            dropping non-finite ranges and ranges outside ``[range_min, range_max]``.

    Returns:
        float64 array of ``(x, y)`` rows, in beam order.
    """
    ranges = np.asarray(scan.ranges, dtype=np.float64)
    angles = scan_angles(scan)
    if not keep_invalid:
        with np.errstate(invalid="ignore"):
            valid = (
                np.isfinite(ranges)
                & (ranges >= float(scan.range_min))
                & (ranges <= float(scan.range_max))
            )
        ranges, angles = ranges[valid], angles[valid]
    return np.column_stack((ranges * np.cos(angles), ranges * np.sin(angles)))


def make_scan(
    ranges: ArrayLike,
    *,
    angle_min: float,
    angle_max: float,
    range_min: float,
    range_max: float,
    frame_id: str = "laser",
    stamp: Stamp = None,
    intensities: ArrayLike | None = None,
    time_increment: float = 0.0,
    scan_time: float = 0.0,
) -> mc.LaserScan:
    """A ``sensor_msgs/LaserScan`` from ranges spread evenly over ``[angle_min, angle_max]``.

    ``angle_increment`` is ``(angle_max - angle_min) / (N - 1)``, so the last beam points at
    ``angle_max`` as in ROS drivers.

    Args:
        ranges: N ranges in m (NaN / inf allowed).
        angle_min: Angle of the first beam, rad.
        angle_max: Angle of the last beam, rad.
        range_min: Minimum valid range, m.
        range_max: Maximum valid range, m.
        frame_id: Frame of the scan.
        stamp: Stamp (see :data:`Stamp`).
        intensities: Optional N intensities.
        time_increment: Time between beams, s.
        scan_time: Time between scans, s.

    Raises:
        MessageValueError: ``intensities`` has another length than ``ranges``.
    """
    values = np.asarray(ranges, dtype=np.float32).reshape(-1)
    count = len(values)
    increment = (angle_max - angle_min) / (count - 1) if count > 1 else 0.0
    levels = (
        np.zeros(0, dtype=np.float32)
        if intensities is None
        else np.asarray(intensities, dtype=np.float32).reshape(-1)
    )
    if intensities is not None and len(levels) != count:
        raise MessageValueError(
            f"make_scan: {len(levels)} intensities for {count} ranges (expected equal counts)"
        )
    return LaserScan(
        header=_header(frame_id, stamp),
        angle_min=angle_min,
        angle_max=angle_max,
        angle_increment=increment,
        time_increment=time_increment,
        scan_time=scan_time,
        range_min=range_min,
        range_max=range_max,
        ranges=values,
        intensities=levels,
    )


# ------------------------------------------------------------------------------------- grids


def occupancy_grid_to_array(grid: Any) -> NDArray[np.int8]:
    """The cells of a ``nav_msgs/OccupancyGrid`` as an int8 ``(height, width)`` array.

    Row 0 is the first row of ``data`` (y at the origin), column 0 x at the origin; values
    are -1 (unknown) or 0..100. The result may be a read-only view of the message data:
    ``.copy()`` it to modify.

    Raises:
        MessageValueError: ``data`` does not hold ``width * height`` cells.
    """
    width, height = int(grid.info.width), int(grid.info.height)
    data = np.asarray(grid.data, dtype=np.int8)
    if data.size != width * height:
        raise MessageValueError(
            f"nav_msgs/msg/OccupancyGrid: {data.size} cells for {width}x{height} map"
        )
    return data.reshape(height, width)


def array_to_occupancy_grid(
    arr: ArrayLike,
    *,
    resolution: float,
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
    frame_id: str = "map",
    stamp: Stamp = None,
) -> mc.OccupancyGrid:
    """A ``nav_msgs/OccupancyGrid`` of a ``(height, width)`` array of -1 / 0..100 values.

    Args:
        arr: Cells; row 0 is y at the origin.
        resolution: Cell size, m.
        origin: Pose ``(x, y, yaw)`` of cell (0, 0)'s corner in ``frame_id``, m and rad.
        frame_id: Frame of the map.
        stamp: Stamp of the header and ``info.map_load_time`` (see :data:`Stamp`).

    Raises:
        MessageValueError: ``arr`` is not 2-D or holds values outside -1..100.
    """
    cells = np.asarray(arr)
    if cells.ndim != 2:
        raise MessageValueError(f"occupancy grid: expected a 2-D array, got shape {cells.shape}")
    if cells.size and (cells.min() < -1 or cells.max() > 100):
        raise MessageValueError("occupancy grid: values must be -1 (unknown) or 0..100")
    height, width = cells.shape
    time = stamp_to_msg(stamp)
    info = MapMetaData(
        map_load_time=time,
        resolution=resolution,
        width=width,
        height=height,
        origin=pose_from_xytheta(*origin),
    )
    return OccupancyGrid(
        header=Header(stamp=time, frame_id=frame_id),
        info=info,
        data=np.ascontiguousarray(cells, dtype=np.int8).reshape(-1),
    )


# ------------------------------------------------------------------------------------ images

_NAMED_ENCODINGS: Final[dict[str, tuple[str, int]]] = {
    "rgb8": ("u1", 3),
    "bgr8": ("u1", 3),
    "rgba8": ("u1", 4),
    "bgra8": ("u1", 4),
    "rgb16": ("u2", 3),
    "bgr16": ("u2", 3),
    "rgba16": ("u2", 4),
    "bgra16": ("u2", 4),
    "mono8": ("u1", 1),
    "mono16": ("u2", 1),
    "yuv422": ("u1", 2),
    "bayer_rggb8": ("u1", 1),
    "bayer_bggr8": ("u1", 1),
    "bayer_gbrg8": ("u1", 1),
    "bayer_grbg8": ("u1", 1),
    "bayer_rggb16": ("u2", 1),
    "bayer_bggr16": ("u2", 1),
    "bayer_gbrg16": ("u2", 1),
    "bayer_grbg16": ("u2", 1),
}
_CV_ENCODING: Final = re.compile(r"^(8|16|32|64)([USF])C([1-4])$")


def _encoding_layout(encoding: str) -> tuple[np.dtype[Any], int]:
    """(little-endian element dtype, channels) of an image encoding."""
    named = _NAMED_ENCODINGS.get(encoding)
    if named is not None:
        return np.dtype("<" + named[0]), named[1]
    match = _CV_ENCODING.match(encoding.upper())
    if match is None:
        raise MessageValueError(f"unsupported image encoding {encoding!r}")
    bits, kind, channels = match.groups()
    code = {"U": "u", "S": "i", "F": "f"}[kind]
    if code == "f" and bits in ("8", "16"):
        raise MessageValueError(f"unsupported image encoding {encoding!r}")
    return np.dtype(f"<{code}{int(bits) // 8}"), int(channels)


def image_to_array(img: Any) -> NDArray[Any]:
    """The pixels of a ``sensor_msgs/Image`` as ``(height, width)`` or ``(h, w, channels)``.

    Honours ``step`` (row padding) and ``is_bigendian``; channel order is the encoding's
    (``bgr8`` stays BGR). Supports rgb8/bgr8/rgba8/bgra8, rgb16/bgr16, mono8/mono16,
    yuv422, bayer_*, and ``{8,16,32,64}{U,S,F}C{1..4}`` (``16UC1``, ``32FC1``, ...).

    Raises:
        MessageValueError: Unsupported encoding, or ``data`` too short for the size.
    """
    dtype, channels = _encoding_layout(str(img.encoding))
    if img.is_bigendian:
        dtype = dtype.newbyteorder(">")
    height, width, step = int(img.height), int(img.width), int(img.step)
    row_bytes = width * channels * dtype.itemsize
    raw = np.frombuffer(memoryview(img.data), dtype=np.uint8)
    if step < row_bytes or raw.size < height * step:
        raise MessageValueError(
            f"sensor_msgs/msg/Image: {raw.size} bytes with step {step} cannot hold "
            f"{height}x{width} {img.encoding} pixels"
        )
    rows = raw[: height * step].reshape(height, step)[:, :row_bytes]
    pixels = np.ascontiguousarray(rows).view(dtype).astype(dtype.newbyteorder("="), copy=False)
    shape = (height, width) if channels == 1 else (height, width, channels)
    return pixels.reshape(shape)


def array_to_image(
    arr: ArrayLike, encoding: str, *, frame_id: str = "camera", stamp: Stamp = None
) -> mc.Image:
    """A ``sensor_msgs/Image`` of an array, rows packed (``step = width * pixel bytes``).

    Args:
        arr: ``(height, width)`` or ``(height, width, channels)`` pixels; integer arrays are
            range-checked and cast to the encoding's element type, float arrays cast to a
            float encoding.
        encoding: Image encoding (see :func:`image_to_array`).
        frame_id: Frame of the camera.
        stamp: Stamp (see :data:`Stamp`).

    Raises:
        MessageValueError: Unsupported encoding, or shape / dtype not matching it.
    """
    dtype, channels = _encoding_layout(encoding)
    pixels = np.asarray(arr)
    shape_ok = pixels.ndim == 2 if channels == 1 else pixels.ndim == 3
    if pixels.ndim == 3 and pixels.shape[2] == channels:
        shape_ok = True
    if not shape_ok:
        raise MessageValueError(
            f"image {encoding}: expected {channels} channel(s), got array of shape {pixels.shape}"
        )
    if pixels.dtype != dtype.newbyteorder("="):
        kinds = "iu" if dtype.kind in "iu" else "iuf"
        if pixels.dtype.kind not in kinds:
            raise MessageValueError(f"image {encoding}: cannot store {pixels.dtype} pixels")
        if dtype.kind in "iu" and pixels.size:
            info = np.iinfo(dtype)
            if pixels.min() < info.min or pixels.max() > info.max:
                raise MessageValueError(f"image {encoding}: values out of range for {dtype}")
    pixels = np.ascontiguousarray(pixels, dtype=dtype)  # little endian on any host
    height, width = int(pixels.shape[0]), int(pixels.shape[1])
    return Image(
        header=_header(frame_id, stamp),
        height=height,
        width=width,
        encoding=encoding,
        is_bigendian=0,
        step=width * channels * dtype.itemsize,
        data=pixels.reshape(-1).view(np.uint8),
    )


# ------------------------------------------------------------------------------ point clouds

_POINTFIELD_DTYPES: Final[dict[int, str]] = {
    1: "i1",
    2: "u1",
    3: "i2",
    4: "u2",
    5: "i4",
    6: "u4",
    7: "f4",
    8: "f8",
}


def _read_fields(pc: Any, names: Sequence[str]) -> dict[str, NDArray[Any]]:
    """The named fields of a ``sensor_msgs/PointCloud2``, each a flat array of points."""
    order = ">" if pc.is_bigendian else "<"
    by_name = {f.name: f for f in pc.fields}
    formats, offsets = [], []
    for name in names:
        field = by_name.get(name)
        if field is None:
            raise MessageValueError(
                f"sensor_msgs/msg/PointCloud2 has no point field {name!r} "
                f"(has {', '.join(by_name) or 'none'})"
            )
        code = _POINTFIELD_DTYPES.get(int(field.datatype))
        if code is None:
            raise MessageValueError(
                f"sensor_msgs/msg/PointCloud2 field {name!r}: bad datatype {field.datatype}"
            )
        formats.append(order + code)
        offsets.append(int(field.offset))
    height, width = int(pc.height), int(pc.width)
    point_step, row_step = int(pc.point_step), int(pc.row_step)
    raw = np.frombuffer(memoryview(pc.data), dtype=np.uint8)
    if raw.size < height * row_step or row_step < width * point_step:
        raise MessageValueError(
            f"sensor_msgs/msg/PointCloud2: {raw.size} bytes cannot hold {height}x{width} "
            f"points of {point_step} bytes (row_step {row_step})"
        )
    rows = raw[: height * row_step].reshape(height, row_step)[:, : width * point_step]
    record = np.dtype(
        {"names": list(names), "formats": formats, "offsets": offsets, "itemsize": point_step}
    )
    points = np.ascontiguousarray(rows).reshape(-1).view(record)
    return {name: points[name] for name in names}


def pointcloud2_to_xyz(pc: Any, *, skip_nans: bool = False) -> NDArray[np.float32]:
    """The ``x, y, z`` of a ``sensor_msgs/PointCloud2`` as a float32 ``(N, 3)`` array.

    Honours ``point_step``, ``row_step``, field offsets and datatypes, and ``is_bigendian``.
    Points are in row-major order (``N = height * width``).

    Args:
        pc: The cloud.
        skip_nans: Drop points with a non-finite coordinate.

    Raises:
        MessageValueError: No x / y / z field, or ``data`` too short.
    """
    cols = _read_fields(pc, ("x", "y", "z"))
    xyz = np.column_stack([cols["x"], cols["y"], cols["z"]]).astype(np.float32)
    if skip_nans:
        xyz = xyz[np.isfinite(xyz).all(axis=1)]
    return xyz


def pointcloud2_field(pc: Any, name: str) -> NDArray[np.float64]:
    """One point field of a ``sensor_msgs/PointCloud2`` (e.g. ``intensity``) as float64,
    one value per point in row-major order.

    Raises:
        MessageValueError: No such field, or ``data`` too short.
    """
    return _read_fields(pc, (name,))[name].astype(np.float64)


def pointcloud2_to_rgb(pc: Any) -> NDArray[np.uint8]:
    """The colours of a cloud with a packed ``rgb`` (or ``rgba``) field, uint8 ``(N, 3)``."""
    name = "rgb" if any(f.name == "rgb" for f in pc.fields) else "rgba"
    packed = _read_fields(pc, (name,))[name]
    bits = np.ascontiguousarray(packed.astype(packed.dtype.newbyteorder("="))).view(np.uint32)
    return np.column_stack([(bits >> 16) & 0xFF, (bits >> 8) & 0xFF, bits & 0xFF]).astype(np.uint8)


def xyz_to_pointcloud2(
    points: ArrayLike,
    frame_id: str,
    stamp: Stamp = None,
    *,
    rgb: ArrayLike | None = None,
) -> mc.PointCloud2:
    """An unorganised (``height`` 1) ``sensor_msgs/PointCloud2`` of ``(N, 3)`` points.

    Fields ``x, y, z`` float32 (offsets 0, 4, 8) and, with ``rgb``, ``rgb`` float32 at
    offset 12 holding ``r << 16 | g << 8 | b`` as PCL packs it; little endian;
    ``is_dense`` when every coordinate is finite.

    Args:
        points: ``(N, 3)`` coordinates, m.
        frame_id: Frame of the points.
        stamp: Stamp (see :data:`Stamp`).
        rgb: Optional ``(N, 3)`` colours: integers 0..255, or floats 0..1.

    Raises:
        MessageValueError: Bad shapes or colour values.
    """
    xyz = np.asarray(points, dtype=np.float32)
    if xyz.ndim != 2 or xyz.shape[1] != 3:
        raise MessageValueError(f"point cloud: expected (N, 3) points, got shape {xyz.shape}")
    count = xyz.shape[0]
    names = ["x", "y", "z"]
    columns: list[NDArray[Any]] = [xyz[:, 0], xyz[:, 1], xyz[:, 2]]
    if rgb is not None:
        colours = np.asarray(rgb)
        if colours.shape != (count, 3):
            raise MessageValueError(
                f"point cloud: expected ({count}, 3) colours, got shape {colours.shape}"
            )
        if colours.dtype.kind == "f":
            if colours.size and (colours.min() < 0.0 or colours.max() > 1.0):
                raise MessageValueError("point cloud: float colours must be in [0, 1]")
            colours = np.rint(colours * 255.0)
        elif colours.dtype.kind not in "iu" or (
            colours.size and (colours.min() < 0 or colours.max() > 255)
        ):
            raise MessageValueError("point cloud: integer colours must be in 0..255")
        c = colours.astype(np.uint32)
        packed = (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]
        names.append("rgb")
        columns.append(packed.view(np.float32))
    record = np.dtype({"names": names, "formats": ["<f4"] * len(names)})
    cloud = np.empty(count, dtype=record)
    for name, column in zip(names, columns, strict=True):
        cloud[name] = column
    fields = [
        PointField(name=name, offset=4 * i, datatype=PointField.FLOAT32, count=1)
        for i, name in enumerate(names)
    ]
    return PointCloud2(
        header=_header(frame_id, stamp),
        height=1,
        width=count,
        fields=fields,
        is_bigendian=False,
        point_step=record.itemsize,
        row_step=record.itemsize * count,
        data=cloud.view(np.uint8).reshape(-1),
        is_dense=bool(np.isfinite(xyz).all()),
    )
