"""Pure geometry of the displays: what the page draws, computed from messages and poses.

Nothing here touches the bus or a clock: functions take arrays, message objects and
:class:`~roverlab.geometry.Transform3` poses (``fixed_from_frame``) and return arrays or
small JSON-able dicts in the fixed frame, seen from above.

* :func:`decimate`: server-side thinning of big clouds (the colours:
  :mod:`roverlab.viz.colours`, :func:`color_buckets` re-exported here);
* :class:`PoseTrail`: rviz's Odometry display (keep N arrows, position/angle tolerance);
* :func:`map_change`: the window of cells that changed between two maps;
* :func:`marker_primitives` and :class:`MarkerStore`: ``visualization_msgs/Marker``
  (ARROW, CUBE, SPHERE, CYLINDER, LINE_STRIP, LINE_LIST, CUBE_LIST, SPHERE_LIST, POINTS,
  TEXT_VIEW_FACING; ADD, DELETE, DELETEALL, lifetime, frame_locked) as 2-D primitives,
  and :func:`marker_3d`: the same markers whole for the 3D view (TRIANGLE_LIST too).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import Transform3, quat_rotate, wrap_angle, yaw_from_quat
from roverlab.viz.colours import color_buckets
from roverlab.viz.protocol import convex_hull

__all__ = [
    "MARKER_ARROW",
    "MARKER_POINTS",
    "MarkerStore",
    "PoseTrail",
    "color_buckets",
    "decimate",
    "map_change",
    "marker_3d",
    "marker_primitives",
    "pose_covariance_primitives",
    "poses3_in_fixed",
    "poses_in_fixed",
    "yaw_of_poses3",
]

MARKER_ARROW: Final = 0
MARKER_CUBE: Final = 1
MARKER_SPHERE: Final = 2
MARKER_CYLINDER: Final = 3
MARKER_LINE_STRIP: Final = 4
MARKER_LINE_LIST: Final = 5
MARKER_CUBE_LIST: Final = 6
MARKER_SPHERE_LIST: Final = 7
MARKER_POINTS: Final = 8
MARKER_TEXT: Final = 9
ACTION_ADD: Final = 0
ACTION_DELETE: Final = 2
ACTION_DELETEALL: Final = 3
_RING: Final = 24


# ---------------------------------------------------------------------- points
def decimate(points: NDArray[Any], max_points: int) -> NDArray[Any]:
    """Every k-th row of ``points`` so that at most ``max_points`` remain (k >= 1)."""
    n = len(points)
    if max_points <= 0 or n <= max_points:
        return points
    step = math.ceil(n / max_points)
    return points[::step]


def poses_in_fixed(
    fixed_from_frame: Transform3,
    positions: NDArray[np.floating[Any]],
    quats_xyzw: NDArray[np.floating[Any]],
) -> NDArray[np.float64]:
    """``(N, 3)`` ``(x, y, yaw)`` in the fixed frame of poses given in a frame."""
    pos = fixed_from_frame.apply(np.asarray(positions, dtype=np.float64).reshape(-1, 3))
    q = np.asarray(quats_xyzw, dtype=np.float64).reshape(-1, 4)
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    # each pose's x axis (first column of its rotation matrix), turned into the fixed frame
    axis = np.column_stack(
        (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y))
    )
    heading = quat_rotate(fixed_from_frame.rotation, axis).reshape(-1, 3)
    return np.column_stack((pos[:, :2], np.arctan2(heading[:, 1], heading[:, 0])))


def poses3_in_fixed(
    fixed_from_frame: Transform3,
    positions: NDArray[np.floating[Any]],
    quats_xyzw: NDArray[np.floating[Any]],
) -> NDArray[np.float64]:
    """``(N, 7)`` ``(x, y, z, qx, qy, qz, qw)`` in the fixed frame of poses given in a
    frame: the full 3-D pose (a zero quaternion counts as the identity, as rviz)."""
    pos = fixed_from_frame.apply(np.asarray(positions, dtype=np.float64).reshape(-1, 3))
    q = np.asarray(quats_xyzw, dtype=np.float64).reshape(-1, 4)
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    ok = np.isfinite(norm) & (norm > 1e-12)
    q = np.where(ok, q / np.where(ok, norm, 1.0), np.array([0.0, 0.0, 0.0, 1.0]))
    ax, ay, az, aw = (float(v) for v in fixed_from_frame.rotation)
    bx, by, bz, bw = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    out = np.column_stack(
        (
            pos,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        )
    )
    return out


def yaw_of_poses3(poses: NDArray[np.floating[Any]]) -> NDArray[np.float64]:
    """The heading (yaw of the x axis seen from above) of ``(N, 7)`` poses."""
    q = np.asarray(poses, dtype=np.float64).reshape(-1, 7)[:, 3:]
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.arctan2(2.0 * (x * y + w * z), 1.0 - 2.0 * (y * y + z * z))


def pose_covariance_primitives(
    pose: tuple[float, float, float],
    covariance_xy: NDArray[np.floating[Any]],
    yaw_variance: float,
    *,
    rgb: tuple[int, int, int] | list[int],
    alpha: float,
    length: float,
    scale: float = 1.0,
    segments: int = 48,
) -> list[dict[str, Any]]:
    """rviz's PoseWithCovariance display as primitives (in the fixed frame): the pose's
    arrow, the position covariance as the ``scale``-sigma ellipse (filled, outlined) and
    the yaw's ``scale``-sigma wedge in front of the robot.

    Args:
        pose: ``(x, y, yaw)`` in the fixed frame.
        covariance_xy: ``(2, 2)`` position covariance, already in the fixed frame (m^2).
        yaw_variance: yaw variance (rad^2).
        rgb: the arrow's colour (0..255); the ellipse takes it at a third of ``alpha``.
        alpha: opacity of the arrow.
        length: arrow length (m).
        scale: how many standard deviations the ellipse and wedge span.
        segments: points on the ellipse.
    """
    x, y, yaw = (float(v) for v in pose)
    c = np.asarray(covariance_xy, dtype=np.float64).reshape(2, 2)
    c = 0.5 * (c + c.T)
    rgba = [round(v / 255.0, 3) for v in rgb]
    solid = [*rgba, round(float(alpha), 3)]
    faint = [*rgba, round(float(alpha) / 3.0, 3)]
    out: list[dict[str, Any]] = []
    if np.isfinite(c).all():
        values, vectors = np.linalg.eigh(c)
        radii = scale * np.sqrt(np.clip(values, 0.0, None))
        t = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
        ring = (vectors @ (radii[:, None] * np.vstack((np.cos(t), np.sin(t))))).T + np.array([x, y])
        pts = [[round(float(a), 4), round(float(b), 4)] for a, b in ring]
        out.append({"shape": "polygon", "rgba": faint, "points": pts})
        out.append({"shape": "polyline", "rgba": solid, "points": [*pts, pts[0]], "width": 0.0})
    if math.isfinite(yaw_variance) and yaw_variance > 0.0:
        half = min(math.pi, scale * math.sqrt(yaw_variance))
        arc = np.linspace(yaw - half, yaw + half, 16)
        r = 0.6 * length
        wedge = [[x, y]] + [[x + r * math.cos(a), y + r * math.sin(a)] for a in arc]
        pts = [[round(float(a), 4), round(float(b), 4)] for a, b in wedge]
        out.append({"shape": "polygon", "rgba": faint, "points": pts})
    out.append({"shape": "arrow", "rgba": solid, "points": [[round(x, 4), round(y, 4)]],
                "yaw": round(yaw, 4), "length": round(float(length), 4),
                "width": round(0.04 * float(length), 4)})  # fmt: skip
    return out


@dataclass
class PoseTrail:
    """rviz's Odometry display: the last ``keep`` poses, a new one kept only when it moved
    more than ``position_tolerance_m`` or turned more than ``angle_tolerance_rad``.

    ``keep`` 0 keeps every pose (rviz: unlimited). Poses are ``(x, y, yaw)``, or full
    ``(x, y, z, qx, qy, qz, qw)`` rows given as ``full`` (then :meth:`array3` has them).
    """

    keep: int = 100
    position_tolerance_m: float = 0.1
    angle_tolerance_rad: float = 0.1
    poses: list[tuple[float, float, float]] = field(default_factory=list)
    full: list[tuple[float, ...]] = field(default_factory=list)

    def add(self, x: float, y: float, yaw: float, full: Sequence[float] | None = None) -> bool:
        """Consider a pose; True if it was kept."""
        if self.poses:
            lx, ly, lyaw = self.poses[-1]
            moved = math.hypot(x - lx, y - ly) > self.position_tolerance_m
            if full is not None and self.full:
                moved = moved or abs(float(full[2]) - self.full[-1][2]) > self.position_tolerance_m
            turned = abs(wrap_angle(yaw - lyaw)) > self.angle_tolerance_rad
            if not (moved or turned):
                return False
        self.poses.append((x, y, yaw))
        self.full.append(tuple(float(v) for v in full) if full is not None else
                         (x, y, 0.0, 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))  # fmt: skip
        if self.keep > 0 and len(self.poses) > self.keep:
            del self.poses[: len(self.poses) - self.keep]
            del self.full[: len(self.full) - self.keep]
        return True

    def array(self) -> NDArray[np.float64]:
        """The kept poses, ``(N, 3)`` ``(x, y, yaw)``."""
        return np.array(self.poses, dtype=np.float64).reshape(-1, 3)

    def array3(self) -> NDArray[np.float64]:
        """The kept poses, ``(N, 7)`` ``(x, y, z, qx, qy, qz, qw)``."""
        return np.array(self.full, dtype=np.float64).reshape(-1, 7)


# ------------------------------------------------------------------------- map
def map_change(
    old: NDArray[np.int8], new: NDArray[np.int8]
) -> tuple[int, int, NDArray[np.int8]] | None:
    """``(x0, y0, window)``: the smallest window of ``new`` holding every changed cell
    (``None``: nothing changed). Both grids must have the same shape."""
    diff = old != new
    rows = np.flatnonzero(diff.any(axis=1))
    if rows.size == 0:
        return None
    cols = np.flatnonzero(diff[rows[0] : rows[-1] + 1].any(axis=0))
    y0, y1, x0, x1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
    return x0, y0, np.ascontiguousarray(new[y0:y1, x0:x1])


# --------------------------------------------------------------------- markers
def _rgba(color: Any) -> list[float]:
    return [
        round(float(color.r), 3),
        round(float(color.g), 3),
        round(float(color.b), 3),
        round(float(color.a), 3),
    ]


def _points(pts: Any) -> NDArray[np.float64]:
    return np.array([(p.x, p.y, p.z) for p in pts], dtype=np.float64).reshape(-1, 3)


def _xy(arr: NDArray[np.float64]) -> list[list[float]]:
    out: list[list[float]] = np.round(arr[:, :2], 4).tolist()
    return out


def _solid(kind: int, sx: float, sy: float, sz: float) -> NDArray[np.float64]:
    if kind == MARKER_CUBE:
        return np.array(
            [(x, y, z) for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)],
            dtype=np.float64,
        )
    ring = np.linspace(0.0, 2.0 * math.pi, _RING, endpoint=False)
    c, s = np.cos(ring), np.sin(ring)
    if kind == MARKER_SPHERE:  # an ellipsoid: its three principal ellipses bound the view
        zeros = np.zeros_like(ring)
        return np.vstack(
            (
                np.column_stack((sx * c, sy * s, zeros)),
                np.column_stack((sx * c, zeros, sz * s)),
                np.column_stack((zeros, sy * c, sz * s)),
            )
        )
    rim = np.column_stack((sx * c, sy * s))  # cylinder: axis along z
    return np.vstack(
        (
            np.column_stack((rim, np.full(_RING, -sz))),
            np.column_stack((rim, np.full(_RING, sz))),
        )
    )


def marker_primitives(marker: Any, fixed_from_frame: Transform3) -> list[dict[str, Any]]:
    """A marker as top-view primitives in the fixed frame (empty for unsupported types).

    Each primitive is ``{"shape": "polygon" | "polyline" | "lines" | "points" | "text" |
    "arrow", "rgba": [r, g, b, a], ...}`` with ``points`` ``[[x, y], ...]`` (m), plus
    ``width`` (m) for lines, ``size`` (m) for points, ``text`` and ``height`` (m) for text,
    ``colors`` (one RGBA per point) when the marker has per-point colours.
    """
    p, q = marker.pose.position, marker.pose.orientation
    pose = fixed_from_frame * Transform3(
        (float(p.x), float(p.y), float(p.z)),
        (float(q.x), float(q.y), float(q.z), float(q.w)),
    )
    sx, sy, sz = float(marker.scale.x), float(marker.scale.y), float(marker.scale.z)
    rgba = _rgba(marker.color)
    kind = int(marker.type)
    prim: dict[str, Any]
    if kind == MARKER_ARROW:
        pts = _points(marker.points)
        if len(pts) >= 2:  # from points[0] to points[1]; scale.x is the shaft diameter
            ends = pose.apply(pts[:2])
            tail, tip = ends[0, :2], ends[1, :2]
            width = sx
        else:  # along the pose's x axis, scale.x long
            tail = np.array(pose.translation[:2])
            tip = pose.apply(np.array([[sx, 0.0, 0.0]]))[0, :2]
            width = sy
        yaw = math.atan2(tip[1] - tail[1], tip[0] - tail[0])
        length = float(np.hypot(*(tip - tail)))
        return [
            {
                "shape": "arrow",
                "rgba": rgba,
                "points": [_xy(tail[None, :])[0]],
                "yaw": round(yaw, 4),
                "length": round(length, 4),
                "width": round(max(width, 0.0), 4),
            }
        ]
    if kind in (MARKER_CUBE, MARKER_SPHERE, MARKER_CYLINDER):
        world = pose.apply(_solid(kind, sx / 2.0, sy / 2.0, sz / 2.0))
        hull = convex_hull([(float(x), float(y)) for x, y in np.round(world[:, :2], 5)])
        return [{"shape": "polygon", "rgba": rgba, "points": [list(h) for h in hull]}]
    if kind in (MARKER_LINE_STRIP, MARKER_LINE_LIST):
        pts = pose.apply(_points(marker.points))
        if kind == MARKER_LINE_LIST:
            pts = pts[: len(pts) // 2 * 2]
        prim = {
            "shape": "polyline" if kind == MARKER_LINE_STRIP else "lines",
            "rgba": rgba,
            "points": _xy(pts),
            "width": round(sx, 4),
        }
    elif kind in (MARKER_POINTS, MARKER_CUBE_LIST, MARKER_SPHERE_LIST):
        pts = pose.apply(_points(marker.points))
        prim = {
            "shape": "points",
            "rgba": rgba,
            "points": _xy(pts),
            "size": round(max(sx, sy), 4),
            "round": kind == MARKER_SPHERE_LIST,
        }
    elif kind == MARKER_TEXT:
        return [
            {
                "shape": "text",
                "rgba": rgba,
                "points": [_xy(np.array([pose.translation]))[0]],
                "text": str(marker.text),
                "height": round(sz, 4),
            }
        ]
    else:
        return []
    if len(marker.colors) == len(marker.points) and len(marker.colors) > 0:
        colors = [_rgba(c) for c in marker.colors]
        if prim["shape"] == "lines":
            colors = colors[: len(prim["points"])]
        prim["colors"] = colors
    return [prim]


MARKER_TRIANGLE_LIST: Final = 11


def marker_3d(marker: Any, fixed_from_frame: Transform3) -> dict[str, Any]:
    """A marker as the 3D view draws it: its type, pose in the fixed frame (``[x, y, z,
    qx, qy, qz, qw]``, the orientation in full), scale, colour, and its ``points`` /
    ``colors`` (in the marker's own pose) and ``text`` when it has them."""
    p, q = marker.pose.position, marker.pose.orientation
    pose = poses3_in_fixed(
        fixed_from_frame,
        np.array([[p.x, p.y, p.z]], dtype=np.float64),
        np.array([[q.x, q.y, q.z, q.w]], dtype=np.float64),
    )[0]
    out: dict[str, Any] = {
        "ns": str(marker.ns),
        "id": int(marker.id),
        "type": int(marker.type),
        "pose": [round(float(v), 6) for v in pose],
        "scale": [round(float(v), 6) for v in (marker.scale.x, marker.scale.y, marker.scale.z)],
        "rgba": _rgba(marker.color),
    }
    if len(marker.points):
        out["points"] = np.round(_points(marker.points), 6).tolist()
        if len(marker.colors) == len(marker.points):
            out["colors"] = [_rgba(c) for c in marker.colors]
    if int(marker.type) == MARKER_TEXT:
        out["text"] = str(marker.text)
    return out


@dataclass
class _Entry:
    marker: Any
    frame: str
    expires_ns: int | None
    primitives: list[dict[str, Any]]
    solid: dict[str, Any]


class MarkerStore:
    """The markers a Marker / MarkerArray display shows, keyed by ``(ns, id)`` as rviz.

    ``ADD`` / ``MODIFY`` replace, ``DELETE`` removes one, ``DELETEALL`` removes all (of the
    display); a non-zero ``lifetime`` expires a marker that long after it arrived;
    ``frame_locked`` markers are moved with their frame on every :meth:`refresh`.

    Args:
        lookup: ``frame -> fixed_from_frame`` (None when TF cannot say).
    """

    def __init__(self, lookup: Callable[[str], Transform3 | None]) -> None:
        self._lookup = lookup
        self._entries: dict[tuple[str, int], _Entry] = {}
        self.errors: dict[str, str] = {}

    def __len__(self) -> int:
        return len(self._entries)

    def add(self, marker: Any, now_ns: int) -> bool:
        """Apply one marker message; True if what is drawn changed."""
        action = int(marker.action)
        key = (str(marker.ns), int(marker.id))
        if action == ACTION_DELETEALL:
            changed = bool(self._entries)
            self._entries.clear()
            return changed
        if action == ACTION_DELETE:
            return self._entries.pop(key, None) is not None
        frame = str(marker.header.frame_id).lstrip("/")
        tf = self._lookup(frame)
        if tf is None:
            self.errors[f"{key[0]}/{key[1]}"] = f"no transform from [{frame}]"
            return False
        self.errors.pop(f"{key[0]}/{key[1]}", None)
        life = int(marker.lifetime.sec) * 1_000_000_000 + int(marker.lifetime.nanosec)
        expires = now_ns + life if life > 0 else None
        self._entries[key] = _Entry(
            marker, frame, expires, marker_primitives(marker, tf), marker_3d(marker, tf)
        )
        return True

    def refresh(self, now_ns: int) -> bool:
        """Drop expired markers and move frame-locked ones; True if anything changed."""
        changed = False
        for key, entry in list(self._entries.items()):
            if entry.expires_ns is not None and now_ns >= entry.expires_ns:
                del self._entries[key]
                changed = True
            elif bool(entry.marker.frame_locked):
                tf = self._lookup(entry.frame)
                if tf is not None:
                    entry.primitives = marker_primitives(entry.marker, tf)
                    entry.solid = marker_3d(entry.marker, tf)
                    changed = True
        return changed

    def primitives(self) -> list[dict[str, Any]]:
        """Everything to draw, in ``(ns, id)`` order."""
        out: list[dict[str, Any]] = []
        for key in sorted(self._entries):
            out.extend(self._entries[key].primitives)
        return out

    def solids(self) -> list[dict[str, Any]]:
        """Every marker as :func:`marker_3d` gives it, in ``(ns, id)`` order."""
        return [self._entries[key].solid for key in sorted(self._entries)]


def yaw_of(q: Any) -> float:
    """Yaw of a ``geometry_msgs/Quaternion``."""
    return yaw_from_quat((float(q.x), float(q.y), float(q.z), float(q.w)))
