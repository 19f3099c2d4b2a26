"""CARMEN ``.clf`` logs, plain, gzip or bzip2 (:func:`read_clf`): ``FLASER``,
``ROBOTLASER1`` and (on request) ``RAWLASER1`` front-laser lines, ``ODOM`` lines for scans
that carry no pose. The scan timestamp is the line's ``ipc_timestamp``, kept as the original
text (:attr:`~roverlab.slam.data.scans.ScanRecord.timestamp_text`) so that trajectory files
can repeat it byte for byte.
"""

from __future__ import annotations

import bz2
import gzip
import io
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Final

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2
from roverlab.slam.data.errors import LogError
from roverlab.slam.data.reversing import ReversingRepair
from roverlab.slam.data.scans import ScanRecord, _PoseStream

__all__ = ["CLF_RANGE_MAX_M", "carmen_beam_geometry", "read_clf"]

#: Range limit given to FLASER scans, which do not carry one: CARMEN's ``maximum_range``
#: for the old laser messages. SICK scanners report "no return" as 81.83 or 81.91 m, which
#: lies above it, so those beams are invalid as in a ROS ``LaserScan``.
CLF_RANGE_MAX_M: Final = 80.0

#: Front-laser lines of :func:`read_clf`: those with the robot's pose, and the raw one
#: (read only on request, posed from the ODOM lines).
_POSE_LASERS: Final = ("FLASER", "ROBOTLASER1")
_RAW_LASERS: Final = ("RAWLASER1",)


# ----------------------------------------------------------------------------- CARMEN


def carmen_beam_geometry(num_readings: int) -> tuple[float, float]:
    """``(angle_min, angle_increment)`` of a FLASER scan of ``num_readings`` beams.

    A FLASER scan spans 180 degrees from -90 degrees. "Evenly" follows CARMEN
    (``carmen_laser_get_angle_increment``): an odd count covers both ends, so 181 beams
    are 1 degree apart and 361 beams 0.5 degrees (``pi / (n - 1)``); an even count is that
    same scanner with the last beam dropped, so 180 beams are 1 degree apart and end at
    +89 degrees, 360 beams 0.5 degrees apart ending at +89.5 (``pi / n``).
    """
    n = int(num_readings)
    if n <= 1:
        return -0.5 * math.pi, 0.0
    return -0.5 * math.pi, math.pi / (n if n % 2 == 0 else n - 1)


def _open_text_log(path: Path) -> io.BufferedIOBase:
    """The file's bytes, decompressed when it starts with a gzip or bzip2 signature."""
    try:
        with open(path, "rb") as fh:
            magic = fh.read(3)
        if magic[:2] == b"\x1f\x8b":
            return gzip.open(path, "rb")
        if magic == b"BZh":
            return bz2.open(path, "rb")
        return open(path, "rb")
    except OSError as err:
        raise LogError(f"{path}: cannot read: {err.strerror or err}") from err


def _ranges(parts: list[bytes], start: int, n: int) -> NDArray[np.float32]:
    r = np.array(parts[start : start + n], dtype=np.float32)
    if r.shape != (n,):
        raise ValueError(f"expected {n} ranges")
    return r


def _pose(parts: list[bytes], start: int) -> SE2:
    return SE2(float(parts[start]), float(parts[start + 1]), float(parts[start + 2]))


def read_clf(
    path: str | Path,
    *,
    laser_message: str | None = None,
    range_min_m: float = 0.0,
    range_max_m: float | None = None,
    reversing: ReversingRepair | None = None,
) -> Iterator[ScanRecord]:
    """Stream the front-laser scans of a CARMEN log (plain, gzip or bzip2).

    Lines::

        FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname
            logger_timestamp
        ROBOTLASER1 type start_angle fov resolution max_range accuracy remission_mode n r1..rn
            m v1..vm x y theta odom_x odom_y odom_theta tv rv fwd_safety side_safety
            turn_axis ipc_timestamp ipc_hostname logger_timestamp
        RAWLASER1 type start_angle fov resolution max_range accuracy remission_mode n r1..rn
            m v1..vm ipc_timestamp ipc_hostname logger_timestamp
        ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp

    In FLASER and ROBOTLASER1 the first pose is the laser's and the second the robot's
    odometry pose; :attr:`ScanRecord.laser_offset` is the laser pose in the robot frame,
    ``odom^-1 * laser``. FLASER beams follow :func:`carmen_beam_geometry`. A FLASER line
    without the six pose values (old logs) and RAWLASER1 lines take the odometry pose
    interpolated from the ODOM lines at the scan time, and the offset ``x`` from
    ``PARAM robot_frontlaser_offset``. The timestamp is ``ipc_timestamp``, its text kept.
    Comments (``#``), PARAM, other lasers (RLASER, ROBOTLASER2, ...) and other messages
    are skipped.

    Args:
        path: The log.
        laser_message: Which line type to read: ``"FLASER"``, ``"ROBOTLASER1"`` or
            ``"RAWLASER1"``. Default: the first of FLASER / ROBOTLASER1 in the file (logs
            often hold both for the same scans; the other kind is then skipped).
        range_min_m: ``range_min`` of the scans, m.
        range_max_m: ``range_max`` of the scans, m. Default: the line's maximum range
            (ROBOTLASER1, RAWLASER1) or :data:`CLF_RANGE_MAX_M` (FLASER).
        reversing: repair odometry steps that went forward while ``ODOM``'s ``tv`` was
            negative (see :mod:`roverlab.slam.data.reversing`; its counters tell how many);
            None: the poses as logged.

    Yields:
        The scans in file order (pose-less scans once the odometry around them is read).

    Raises:
        LogError: the file cannot be read or a laser / ODOM line is malformed (the message
            names the file and line number).
    """
    p = Path(path)
    if laser_message is not None and laser_message not in (*_POSE_LASERS, *_RAW_LASERS):
        raise LogError(
            f"unknown CARMEN laser message {laser_message!r} (FLASER, ROBOTLASER1 or RAWLASER1)"
        )
    chosen = laser_message
    stream = _PoseStream()
    front_offset = 0.0
    lineno = 0
    with _open_text_log(p) as fh:
        try:
            for lineno, raw in enumerate(fh, start=1):  # noqa: B007 - used in messages
                parts = raw.split()
                if not parts:
                    continue
                tag = parts[0].decode("ascii", "replace")
                if tag.startswith("#"):
                    continue
                if tag == "ODOM":
                    if len(parts) != 10:
                        raise ValueError(f"ODOM needs 9 values, got {len(parts) - 1}")
                    x, y, a = float(parts[1]), float(parts[2]), float(parts[3])
                    if reversing is not None:
                        fixed = reversing.odom(SE2(x, y, a), float(parts[4]))
                        x, y, a = fixed.x, fixed.y, fixed.theta
                    stream.add(float(parts[7]), x, y, a)
                    yield from stream.ready()
                    continue
                if tag == "PARAM":
                    if len(parts) >= 3 and parts[1] == b"robot_frontlaser_offset":
                        front_offset = float(parts[2])
                    continue
                if tag not in _POSE_LASERS and tag not in _RAW_LASERS:
                    continue
                if chosen is None and tag in _POSE_LASERS:
                    chosen = tag
                if tag != chosen:
                    continue
                fix = _as_logged if reversing is None else reversing.scan
                if tag == "FLASER":
                    rec = _flaser(parts, range_min_m, range_max_m, stream, front_offset, fix)
                else:
                    rec = _carmen_laser(
                        parts, tag, range_min_m, range_max_m, stream, front_offset, fix
                    )
                if rec is not None:
                    yield rec
        except (ValueError, IndexError) as err:
            raise LogError(f"{p}:{lineno}: malformed line: {err}") from err
        except (OSError, EOFError) as err:
            raise LogError(f"{p}:{lineno}: cannot read: {err}") from err
    yield from stream.drain()


def _as_logged(pose: SE2) -> SE2:
    return pose


def _timestamp(parts: list[bytes]) -> tuple[float, str]:
    text = parts[-3].decode("ascii")
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"timestamp {text!r} is not finite")
    return value, text


def _flaser(
    parts: list[bytes],
    range_min: float,
    range_max: float | None,
    stream: _PoseStream,
    front_offset: float,
    fix: Callable[[SE2], SE2],
) -> ScanRecord | None:
    n = int(parts[1])
    if n < 0:
        raise ValueError(f"negative beam count {n}")
    has_pose = len(parts) == n + 11
    if not has_pose and len(parts) != n + 5:
        raise ValueError(
            f"FLASER with {n} ranges needs {n + 10} or {n + 4} values, got {len(parts) - 1}"
        )
    ranges = _ranges(parts, 2, n)
    t, text = _timestamp(parts)
    a0, inc = carmen_beam_geometry(n)
    rmax = CLF_RANGE_MAX_M if range_max is None else range_max

    def make(odom: SE2, offset: SE2) -> ScanRecord:
        return ScanRecord(t, ranges, a0, inc, range_min, rmax, odom, offset, text)

    if has_pose:
        laser, odom = _pose(parts, n + 2), _pose(parts, n + 5)
        return make(fix(odom), ~odom * laser)
    offset = SE2(front_offset, 0.0, 0.0)
    stream.pending.append((t, lambda odom: make(odom, offset)))
    return None


def _carmen_laser(
    parts: list[bytes],
    tag: str,
    range_min: float,
    range_max: float | None,
    stream: _PoseStream,
    front_offset: float,
    fix: Callable[[SE2], SE2],
) -> ScanRecord | None:
    start, res, max_range = float(parts[2]), float(parts[4]), float(parts[5])
    n = int(parts[8])
    if n < 0:
        raise ValueError(f"negative beam count {n}")
    ranges = _ranges(parts, 9, n)
    m = int(parts[9 + n])
    tail = 24 if tag == "ROBOTLASER1" else 13
    if m < 0 or len(parts) != n + m + tail:
        raise ValueError(
            f"{tag} with {n} ranges and {m} remissions needs {n + m + tail - 1} values, "
            f"got {len(parts) - 1}"
        )
    t, text = _timestamp(parts)
    rmax = max_range if range_max is None else range_max

    def make(odom: SE2, offset: SE2) -> ScanRecord:
        return ScanRecord(t, ranges, start, res, range_min, rmax, odom, offset, text)

    if tag == "ROBOTLASER1":
        k = 10 + n + m
        laser, odom = _pose(parts, k), _pose(parts, k + 3)
        return make(fix(odom), ~odom * laser)
    offset = SE2(front_offset, 0.0, 0.0)
    stream.pending.append((t, lambda odom: make(odom, offset)))
    return None
