"""One small handler per display type, as rviz has one plugin per display.

Each :class:`DisplayHandler` turns its topic's messages into what the page draws: a binary
frame (:mod:`roverlab.viz.protocol`) or JSON primitives, stored in the display's
:class:`DisplayState` with a version number. Handlers run on the executor thread; they reach
TF and the version counter through the :class:`BridgeLike` they are given (the
:class:`~roverlab.viz.bridge.VizBridge`). :data:`HANDLERS` maps display kinds to them.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Final, Protocol

import numpy as np

from roverlab.core import Context, Time
from roverlab.geometry import Transform3
from roverlab.msgs import (
    occupancy_grid_to_array,
    pointcloud2_field,
    pointcloud2_to_rgb,
    pointcloud2_to_xyz,
    scan_to_points,
    yaw_from_quaternion,
)
from roverlab.viz.config import DisplayConfig
from roverlab.viz.displays import (
    MarkerStore,
    PoseTrail,
    color_buckets,
    map_change,
    pose_covariance_primitives,
    poses3_in_fixed,
    poses_in_fixed,
    yaw_of_poses3,
)
from roverlab.viz.protocol import (
    encode_map,
    encode_map_patch,
    encode_path,
    encode_points,
    encode_poses,
)

__all__ = [
    "HANDLERS",
    "BridgeLike",
    "DisplayHandler",
    "DisplayState",
    "Versioned",
    "markers_changed",
    "rgb_option",
    "stamp_time",
]

_MAX_PATCHES: Final = 16


@dataclass(frozen=True)
class Versioned:
    """A payload and the version it belongs to (versions only grow)."""

    version: int
    payload: Any


@dataclass
class DisplayState:
    """What one display has: its config, subscription, newest frame and status.

    Attributes:
        slot: index in the configuration (the server writes it into the frames' header,
            which are stored with slot 0, so a reordered configuration re-uses them).
        config: the display's configuration.
        frame: newest binary frame (for markers: the JSON text of the primitive list).
        map_base: a map display's last full frame; ``map_patches`` follow it.
        status: status-tree rows ``name -> (level, text)``, level ``ok|warn|error``.
        received: messages received since subscribing.
        subscribed_s: when it subscribed (``time.monotonic()``), None if it is not.
        last_message_s: when its newest message arrived (``time.monotonic()``).
        info: small per-display data for the JSON state (e.g. a map's frame).
    """

    slot: int
    config: DisplayConfig
    frame: Versioned | None = None
    map_base: Versioned | None = None
    map_patches: list[Versioned] = field(default_factory=list)
    map_cells: Any = None
    map_key: tuple[Any, ...] = ()
    map_msg: Any = None
    status: dict[str, tuple[str, str]] = field(default_factory=dict)
    received: int = 0
    subscribed_s: float | None = None
    last_message_s: float | None = None
    info: dict[str, Any] = field(default_factory=dict)
    sub: Any = None
    sub_key: tuple[str, str] = ("", "")
    trail: PoseTrail | None = None
    markers: MarkerStore | None = None
    image_msg: Versioned | None = None
    image_jpeg: Versioned | None = None
    error: str | None = None

    @property
    def kind(self) -> str:
        return self.config.kind


def stamp_time(header: Any) -> Time:
    """A message header's stamp as a :class:`Time`."""
    return Time(int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec))


def rgb_option(config: DisplayConfig) -> tuple[int, int, int]:
    """A display's ``color`` option as integers."""
    c = config.option("color")
    return int(c[0]), int(c[1]), int(c[2])


class BridgeLike(Protocol):
    """What handlers need of the dashboard's node."""

    context: Context

    def lookup_why(
        self, frame: str, stamp: Time | None = None
    ) -> tuple[Transform3 | None, str]: ...

    def next_version(self) -> int: ...


class DisplayHandler:
    """Base of the per-display handlers: TF status and poses in the fixed frame."""

    kind: ClassVar[str] = ""

    def __init__(self, bridge: BridgeLike) -> None:
        self.bridge = bridge

    def on_message(self, state: DisplayState, msg: Any) -> None:
        raise NotImplementedError

    def tf_status(self, state: DisplayState, tf: Transform3 | None, why: str) -> bool:
        if tf is None:
            state.status["Transform"] = ("error", why)
            return False
        state.status["Transform"] = ("ok", "Transform OK")
        return True

    def posed(self, state: DisplayState, header: Any, poses: Sequence[Any]) -> np.ndarray | None:
        """``(N, 7)`` full poses in the fixed frame (None, with the TF status, if TF cannot
        say)."""
        tf, why = self.bridge.lookup_why(str(header.frame_id), stamp_time(header))
        if not self.tf_status(state, tf, why):
            return None
        assert tf is not None
        pos = np.array([(p.position.x, p.position.y, p.position.z) for p in poses], dtype=float)
        quat = np.array(
            [(p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w) for p in poses],
            dtype=float,
        )
        return poses3_in_fixed(tf, pos.reshape(-1, 3), quat.reshape(-1, 4))


def markers_changed(bridge: BridgeLike, state: DisplayState) -> None:
    """A marker display's primitives changed: a new frame, and the marker TF status."""
    assert state.markers is not None
    payload = {"items": state.markers.primitives(), "items3d": state.markers.solids()}
    state.frame = Versioned(bridge.next_version(), json.dumps(payload))
    errors = state.markers.errors
    if errors:
        name, why = next(iter(errors.items()))
        state.status["Transform"] = ("error", f"marker {name}: {why}")
    else:
        state.status["Transform"] = ("ok", "Transform OK")


class MapDisplay(DisplayHandler):
    """rviz/Map: an OccupancyGrid, sent whole or as the window of changed cells."""

    kind = "map"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        state.map_msg = msg
        cells = occupancy_grid_to_array(msg)
        o = msg.info.origin
        origin = (float(o.position.x), float(o.position.y), yaw_from_quaternion(o.orientation))
        res = float(msg.info.resolution)
        frame_id = str(msg.header.frame_id).lstrip("/") or "map"
        key = (cells.shape, res, origin, frame_id)
        height, width = cells.shape
        state.info = {"frame": frame_id, "width": int(width), "height": int(height)}
        prev = state.map_cells
        if state.map_base is not None and key == state.map_key and prev is not None:
            change = map_change(prev, cells)
            if change is None:
                return
            x0, y0, window = change
            if len(state.map_patches) < _MAX_PATCHES and window.size * 2 < cells.size:
                state.map_cells = cells
                patch = Versioned(self.bridge.next_version(), encode_map_patch(window, x0, y0))
                state.map_patches = [*state.map_patches, patch]
                state.frame = patch
                return
        encoded = encode_map(cells, resolution_m=res, origin=origin)
        frame = Versioned(self.bridge.next_version(), encoded)
        state.map_cells = cells
        state.map_key = key
        state.map_patches = []
        state.map_base = frame
        state.frame = frame


_AXES: Final = {"X": 0, "Y": 1, "Z": 2}


def _colours(
    state: DisplayState,
    world: np.ndarray,
    local: np.ndarray,
    channel: Callable[[str], np.ndarray | None],
) -> tuple[np.ndarray | None, np.ndarray]:
    """Bucket indices and palette of a LaserScan / PointCloud2 display's points: the
    configured colour transformer over ``channel(name)`` (Intensity) or a coordinate
    (AxisColor, of ``world`` or ``local``); bounds used go into the display's info."""
    cfg = state.config
    transformer = str(cfg.option("color_transformer"))
    values: np.ndarray | None = None
    if transformer == "Intensity":
        name = str(cfg.option("channel_name"))
        values = channel(name)
        if values is None and name == "intensity":  # rviz: 'intensity' also finds 'intensities'
            values = channel("intensities")
        if values is None:
            state.status["Color Transformer"] = ("warn", f"no channel {name!r}: drawn flat")
        else:
            state.status["Color Transformer"] = ("ok", f"Intensity of {name!r}")
    else:
        state.status.pop("Color Transformer", None)
    if transformer == "AxisColor":
        frame = world if bool(cfg.option("use_fixed_frame")) else local
        values = frame[:, _AXES[str(cfg.option("axis"))]] if len(frame) else None
    idx, palette, bounds = color_buckets(
        transformer,
        count=len(world),
        flat_rgb=rgb_option(cfg),
        alpha=float(cfg.option("alpha")),
        values=values,
        option=cfg.option,
    )
    if bounds is not None:
        state.info["bounds"] = [round(bounds[0], 6), round(bounds[1], 6)]
    return idx, palette


class LaserScanDisplay(DisplayHandler):
    """rviz/LaserScan: the beams as 3-D points in the fixed frame, at the laser's height,
    coloured by a transformer (channels ``intensity`` and ``index``, as laser_geometry's
    projection gives rviz)."""

    kind = "laser_scan"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        tf, why = self.bridge.lookup_why(str(msg.header.frame_id), stamp_time(msg.header))
        if not self.tf_status(state, tf, why):
            return
        assert tf is not None
        rng = np.asarray(msg.ranges, dtype=np.float64)
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(rng) & (rng >= msg.range_min) & (rng <= msg.range_max)
        pts = scan_to_points(msg)
        local = np.column_stack((pts, np.zeros(len(pts))))
        world = tf.apply(local)  # at the laser's height

        def channel(name: str) -> np.ndarray | None:
            if name == "index":
                return np.flatnonzero(ok).astype(np.float64)
            inten = np.asarray(msg.intensities, dtype=np.float64)
            if name in ("intensity", "intensities") and len(inten) == len(rng) > 0:
                found: np.ndarray = inten[ok]
                return found
            return None

        idx, palette = _colours(state, world, local, channel)
        state.frame = Versioned(self.bridge.next_version(), encode_points(world, idx, palette))


class PointCloud2Display(DisplayHandler):
    """rviz/PointCloud2: points in 3-D, RGB8 per point or a colour transformer over a
    channel / coordinate, thinned to Max Points."""

    kind = "point_cloud2"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        cfg = state.config
        tf, why = self.bridge.lookup_why(str(msg.header.frame_id), stamp_time(msg.header))
        if not self.tf_status(state, tf, why):
            return
        assert tf is not None
        transformer = str(cfg.option("color_transformer"))
        names = {f.name for f in msg.fields}
        xyz_all = pointcloud2_to_xyz(msg)
        keep = np.isfinite(xyz_all).all(axis=1)
        step = max(1, math.ceil(int(keep.sum()) / max(1, int(cfg.option("max_points")))))
        local = xyz_all[keep][::step].astype(np.float64)
        world = tf.apply(local)
        state.info = {"points": len(world)}
        if transformer == "RGB8" and ("rgb" in names or "rgba" in names):
            colours = pointcloud2_to_rgb(msg)[keep][::step]
            alpha = round(max(0.0, min(1.0, float(cfg.option("alpha")))) * 255)
            frame = encode_points(world, None, [[255, 255, 255, alpha]], rgb=colours)
            state.frame = Versioned(self.bridge.next_version(), frame)
            return

        def channel(name: str) -> np.ndarray | None:
            if name not in names:
                return None
            values: np.ndarray = pointcloud2_field(msg, name)[keep][::step]
            return values

        idx, palette = _colours(state, world, local, channel)
        state.frame = Versioned(self.bridge.next_version(), encode_points(world, idx, palette))


class OdometryDisplay(DisplayHandler):
    """rviz/Odometry: a trail of arrows (keep, position and angle tolerance), full 3-D
    poses."""

    kind = "odometry"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        arr = self.posed(state, msg.header, [msg.pose.pose])
        if arr is None or state.trail is None:
            return
        yaw = float(yaw_of_poses3(arr)[0])
        if state.trail.add(float(arr[0, 0]), float(arr[0, 1]), yaw, arr[0]):
            state.frame = Versioned(self.bridge.next_version(), encode_poses(state.trail.array3()))


class PathDisplay(DisplayHandler):
    """rviz/Path: the poses' positions as a line, at their heights."""

    kind = "path"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        arr = self.posed(state, msg.header, [p.pose for p in msg.poses])
        if arr is None:
            return
        state.frame = Versioned(self.bridge.next_version(), encode_path(arr[:, :3]))


class PoseArrayDisplay(DisplayHandler):
    """rviz/PoseArray: one arrow per pose, fully oriented."""

    kind = "pose_array"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        arr = self.posed(state, msg.header, list(msg.poses))
        if arr is None:
            return
        state.frame = Versioned(self.bridge.next_version(), encode_poses(arr))


class PoseDisplay(DisplayHandler):
    """rviz/Pose: one arrow, fully oriented."""

    kind = "pose"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        arr = self.posed(state, msg.header, [msg.pose])
        if arr is not None:
            state.frame = Versioned(self.bridge.next_version(), encode_poses(arr))


class PoseWithCovarianceDisplay(DisplayHandler):
    """rviz/PoseWithCovariance."""

    kind = "pose_with_covariance"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        """/amcl_pose: the arrow, the position covariance ellipse (turned into the fixed
        frame) and the yaw wedge, sent as marker primitives."""
        tf, why = self.bridge.lookup_why(str(msg.header.frame_id), stamp_time(msg.header))
        if not self.tf_status(state, tf, why):
            return
        assert tf is not None
        p = msg.pose.pose
        q = (p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w)
        pose = poses_in_fixed(tf, np.array([[p.position.x, p.position.y, p.position.z]]),
                              np.array([q]))[0]  # fmt: skip
        cov = np.asarray(msg.pose.covariance, dtype=np.float64).reshape(6, 6)
        rot = tf.yaw
        r = np.array([[math.cos(rot), -math.sin(rot)], [math.sin(rot), math.cos(rot)]])
        cfg = state.config
        items = pose_covariance_primitives(
            (float(pose[0]), float(pose[1]), float(pose[2])), r @ cov[:2, :2] @ r.T,
            float(cov[5, 5]), rgb=rgb_option(cfg), alpha=float(cfg.option("alpha")),
            length=float(cfg.option("length")), scale=float(cfg.option("covariance_scale")),
        )  # fmt: skip
        state.frame = Versioned(self.bridge.next_version(), json.dumps({"items": items}))


class PolygonDisplay(DisplayHandler):
    """rviz/Polygon."""

    kind = "polygon"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        """rviz's Polygon display (a footprint): the closed outline, as a marker line."""
        tf, why = self.bridge.lookup_why(str(msg.header.frame_id), stamp_time(msg.header))
        if not self.tf_status(state, tf, why):
            return
        assert tf is not None
        pts = np.array([[p.x, p.y, p.z] for p in msg.polygon.points], dtype=np.float64)
        items: list[dict[str, Any]] = []
        if len(pts):
            xy = tf.apply(pts)[:, :2].round(4).tolist()
            r, g, b = rgb_option(state.config)
            rgba = [r / 255.0, g / 255.0, b / 255.0, float(state.config.option("alpha"))]
            items.append({"shape": "polyline", "rgba": rgba, "width": 0.0,
                          "points": [*xy, xy[0]]})  # fmt: skip
        state.frame = Versioned(self.bridge.next_version(), json.dumps({"items": items}))


class MarkerDisplay(DisplayHandler):
    """rviz/Marker: one marker at a time into the display's MarkerStore."""

    kind = "marker"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        assert state.markers is not None
        state.markers.add(msg, self.bridge.context.now().nanoseconds)
        markers_changed(self.bridge, state)


class MarkerArrayDisplay(DisplayHandler):
    """rviz/MarkerArray: every marker of the array into the MarkerStore."""

    kind = "marker_array"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        assert state.markers is not None
        now = self.bridge.context.now().nanoseconds
        for m in msg.markers:
            state.markers.add(m, now)
        markers_changed(self.bridge, state)


class ImageDisplay(DisplayHandler):
    """rviz/Image: the newest frame, encoded when a page asks for it."""

    kind = "image"

    def on_message(self, state: DisplayState, msg: Any) -> None:
        state.image_msg = Versioned(self.bridge.next_version(), msg)


HANDLERS: Final[dict[str, type[DisplayHandler]]] = {
    h.kind: h
    for h in (
        MapDisplay,
        LaserScanDisplay,
        PointCloud2Display,
        OdometryDisplay,
        PathDisplay,
        PoseArrayDisplay,
        PoseDisplay,
        PoseWithCovarianceDisplay,
        PolygonDisplay,
        MarkerDisplay,
        MarkerArrayDisplay,
        ImageDisplay,
    )
}
"""Display kind -> its handler class (kinds without a topic have none)."""
