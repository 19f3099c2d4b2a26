"""Laser logs from ROS 1 ``.bag`` files, ROS 2 bag folders and ``.mcap`` files
(:func:`read_bag`), via rosbags: ``sensor_msgs/LaserScan`` on ``/scan``, odometry from
``nav_msgs/Odometry`` on ``/odom`` or else from the ``odom -> base`` transforms on ``/tf``,
the laser's mounting from ``/tf_static``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader, AnyReaderError

from roverlab.geometry import SE2, yaw_from_quat
from roverlab.msgs import STORE
from roverlab.slam.data.errors import LogError
from roverlab.slam.data.scans import ScanRecord, _PoseStream

__all__ = ["read_bag"]


# ----------------------------------------------------------------------------- ROS bags


def _stamp(header: Any) -> tuple[int, str]:
    sec, nanosec = int(header.stamp.sec), int(header.stamp.nanosec)
    return sec * 1_000_000_000 + nanosec, f"{sec}.{nanosec:09d}"


def _static_offset(
    static: dict[str, tuple[str, SE2]], base_frame: str, laser_frame: str
) -> SE2 | None:
    """Pose of ``laser_frame`` in ``base_frame`` through the static tree, if connected."""
    chain = SE2()
    frame = laser_frame
    seen = set()
    while frame != base_frame:
        if frame in seen or frame not in static:
            return None
        seen.add(frame)
        parent, t = static[frame]
        chain = t * chain
        frame = parent
    return chain


def _transform_se2(tf: Any) -> tuple[str, str, SE2]:
    tr, q = tf.transform.translation, tf.transform.rotation
    pose = SE2(float(tr.x), float(tr.y), yaw_from_quat((q.x, q.y, q.z, q.w)))
    return tf.header.frame_id.lstrip("/"), tf.child_frame_id.lstrip("/"), pose


def read_bag(
    path: str | Path,
    *,
    scan_topic: str = "/scan",
    odom_topic: str | None = "/odom",
    tf_topic: str | None = "/tf",
    tf_static_topic: str = "/tf_static",
    odom_frame: str = "odom",
    base_frame: str | None = None,
    laser_frame: str | None = None,
) -> Iterator[ScanRecord]:
    """Stream the scans of a ROS 1 bag, ROS 2 bag folder or MCAP file.

    Odometry comes from ``nav_msgs/Odometry`` on ``odom_topic`` if the bag has it, else
    from the ``odom_frame -> base_frame`` transforms on ``tf_topic``; the robot pose at a
    scan is interpolated (linear, angles the short way) at the scan's header stamp. The
    laser offset is ``base_frame -> laser_frame`` through the transforms of
    ``tf_static_topic`` (zero when they do not connect the two frames).

    Args:
        path: A ``.bag`` file, a ROS 2 bag folder or a ``.mcap`` file.
        scan_topic: ``sensor_msgs/LaserScan`` topic.
        odom_topic: ``nav_msgs/Odometry`` topic (None: do not use one).
        tf_topic: Dynamic transforms, used when there is no odometry topic (None: never).
        tf_static_topic: Static transforms, for the laser offset.
        odom_frame: Parent frame of the odometry transforms on ``tf_topic``.
        base_frame: Robot frame. Default: the Odometry messages' ``child_frame_id``, or the
            child of the first ``odom_frame`` transform on ``tf_topic``.
        laser_frame: Laser frame. Default: the scans' ``header.frame_id``.

    Yields:
        The scans in bag order, each once the odometry after it has been read.

    Raises:
        LogError: the bag cannot be read, has no scan topic, or has no odometry while
            ``odom_topic`` or ``tf_topic`` asked for it (pass both as None to read scans
            without odometry: their poses are then the identity).
    """
    p = Path(path)
    if p.is_file() and p.suffix.lower() == ".db3":  # a ROS 2 bag named by its database
        p = p.parent
    try:
        reader = AnyReader([p], default_typestore=STORE.typestore)
        reader.open()
    except (AnyReaderError, OSError, ValueError, KeyError) as err:
        raise LogError(f"{p}: cannot read as a ROS bag or MCAP file: {err}") from err
    try:
        yield from _bag_scans(
            reader,
            p,
            scan_topic=scan_topic,
            odom_topic=odom_topic,
            tf_topic=tf_topic,
            tf_static_topic=tf_static_topic,
            odom_frame=odom_frame.lstrip("/"),
            base_frame=base_frame.lstrip("/") if base_frame else None,
            laser_frame=laser_frame.lstrip("/") if laser_frame else None,
        )
    except LogError:
        raise
    except Exception as err:  # rosbags raises many kinds on corrupt data
        raise LogError(f"{p}: cannot read: {err}") from err
    finally:
        reader.close()


class _Frames:
    """The robot and laser frames of a bag and the laser offset between them."""

    def __init__(
        self, static: dict[str, tuple[str, SE2]], base: str | None, laser: str | None
    ) -> None:
        self.static = static
        self.base = base
        self.laser = laser
        self._offset: SE2 | None = None

    def offset(self) -> SE2:
        """``base -> laser`` through the static transforms (identity if not connected)."""
        if self._offset is None:
            found = _static_offset(self.static, self.base or "base_footprint", self.laser or "")
            self._offset = found if found is not None else SE2()
        return self._offset


def _scan_maker(msg: Any, ns: int, text: str, frames: _Frames) -> Callable[[SE2], ScanRecord]:
    ranges = np.array(msg.ranges, dtype=np.float32)
    fields = (
        float(msg.angle_min),
        float(msg.angle_increment),
        float(msg.range_min),
        float(msg.range_max),
    )

    def make(odom: SE2) -> ScanRecord:
        return ScanRecord(ns * 1e-9, ranges, *fields, odom, frames.offset(), text)

    return make


def _bag_scans(
    reader: Any,
    p: Path,
    *,
    scan_topic: str,
    odom_topic: str | None,
    tf_topic: str | None,
    tf_static_topic: str,
    odom_frame: str,
    base_frame: str | None,
    laser_frame: str | None,
) -> Iterator[ScanRecord]:
    by_topic: dict[str, list[Any]] = {}
    for con in reader.connections:
        by_topic.setdefault(con.topic, []).append(con)
    if scan_topic not in by_topic:
        topics = ", ".join(sorted(by_topic)) or "none"
        raise LogError(f"{p}: no topic {scan_topic} (topics: {topics})")
    use_odom = odom_topic is not None and odom_topic in by_topic
    use_tf = not use_odom and tf_topic is not None and tf_topic in by_topic
    if (odom_topic is not None or tf_topic is not None) and not (use_odom or use_tf):
        asked = " or ".join(t for t in (odom_topic, tf_topic) if t is not None)
        raise LogError(
            f"{p}: no odometry: no topic {asked} (pass odom_topic=None, tf_topic=None to "
            "read the scans without odometry)"
        )
    static: dict[str, tuple[str, SE2]] = {}
    if tf_static_topic in by_topic:  # (no connections would mean every message)
        for con, _, raw in reader.messages(connections=by_topic[tf_static_topic]):
            for tf in reader.deserialize(raw, con.msgtype).transforms:
                parent, child, pose = _transform_se2(tf)
                static[child] = (parent, pose)
    frames = _Frames(static, base_frame, laser_frame)
    conns = list(by_topic[scan_topic])
    if use_odom:
        conns += by_topic[str(odom_topic)]
    elif use_tf:
        conns += by_topic[str(tf_topic)]
    stream = _PoseStream()
    for con, log_ns, raw in reader.messages(connections=conns):
        msg = reader.deserialize(raw, con.msgtype)
        if con.topic == scan_topic:
            ns, text = _stamp(msg.header)
            if ns == 0:  # an unstamped scan: use the recording time
                ns = log_ns
                text = f"{log_ns // 1_000_000_000}.{log_ns % 1_000_000_000:09d}"
            if frames.laser is None:
                frames.laser = msg.header.frame_id.lstrip("/")
            make = _scan_maker(msg, ns, text, frames)
            if not (use_odom or use_tf):
                yield make(SE2())
                continue
            stream.pending.append((ns * 1e-9, make))
        elif use_odom:
            if frames.base is None:
                frames.base = msg.child_frame_id.lstrip("/") or None
            ns, _ = _stamp(msg.header)
            pose = msg.pose.pose
            q = pose.orientation
            stream.add(
                ns * 1e-9,
                float(pose.position.x),
                float(pose.position.y),
                yaw_from_quat((q.x, q.y, q.z, q.w)),
            )
        else:
            for tf in msg.transforms:
                parent, child, se2 = _transform_se2(tf)
                if parent != odom_frame or (frames.base is not None and child != frames.base):
                    continue
                frames.base = child
                ns, _ = _stamp(tf.header)
                stream.add(ns * 1e-9, se2.x, se2.y, se2.theta)
        yield from stream.ready()
    if stream.pending and not stream.times:
        source = (
            f"messages on {odom_topic}"
            if use_odom
            else f"{odom_frame} -> base transforms on {tf_topic}"
        )
        raise LogError(
            f"{p}: no odometry: no {source} (pass odom_topic=None, tf_topic=None to read "
            "the scans without odometry)"
        )
    yield from stream.drain()
