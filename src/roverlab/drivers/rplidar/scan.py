"""From measurement nodes to a LaserScan's numbers, as rplidar_ros builds them.

* nodes are grouped into revolutions at their start flags (:class:`Revolutions`) and
  sorted by angle (the SDK's ``ascendScanData``);
* ``angle_compensate``: the revolution is spread over a fixed grid of
  ``360 * m`` bins with ``m = points_per_circle / 360 + 1`` and
  ``points_per_circle = 1e6 / us_per_sample / scan_frequency``; a node at ``a`` degrees
  fills bins ``int(a * m)`` .. ``+ceil(m) - 1`` (later nodes win), empty bins read
  infinity; without it, the nodes from the first to the last valid one are published as
  they are;
* the scan runs from ``angle_min = pi - angle_max_dev`` to ``pi - angle_min_dev`` with the
  ranges in reverse order (unless ``inverted``): the device measures clockwise, a
  LaserScan counter-clockwise, and rplidar_ros's frame is turned half a turn from the
  device's zero, so a node at ``a`` degrees appears at ``pi - a`` in the scan;
* ranges are ``dist_q2 / 4000`` m (0 -> infinity), intensities the 6-bit quality.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.drivers.rplidar.protocol import NODE_DTYPE

__all__ = ["RANGE_MIN_M", "Revolutions", "ScanData", "build_scan", "points_per_circle"]

RANGE_MIN_M = 0.15
"""rplidar_ros's ``range_min``."""


@dataclass(frozen=True)
class ScanData:
    """The numbers of one sensor_msgs/LaserScan."""

    angle_min: float
    angle_max: float
    angle_increment: float
    ranges: NDArray[np.float32]
    intensities: NDArray[np.float32]
    range_min: float
    range_max: float


_MAX_STEP_Q6 = 20 * 64  # degrees between successive nodes beyond which a node is noise
_WRAP_Q6 = 180 * 64


@numba.njit(cache=True, nogil=True)
def _screen(
    angles: NDArray[np.int64], start: NDArray[np.bool_], last: int, rejected: int
) -> tuple[NDArray[np.bool_], NDArray[np.bool_], int, int]:
    """Keep nodes whose angle follows the last kept one (within 20 degrees, or a wrap
    past 360); three misfits in a row re-anchor on the newest. A start counts where the
    angle wraps by more than half a turn."""
    keep = np.zeros(angles.size, np.bool_)
    new_rev = np.zeros(angles.size, np.bool_)
    for i in range(angles.size):
        a = angles[i]
        if last < 0:
            keep[i] = True
        else:
            step = (a - last) % (360 * 64)
            keep[i] = step <= _MAX_STEP_Q6 or rejected >= 3
        if keep[i]:
            new_rev[i] = start[i] and (last < 0 or last - a > _WRAP_Q6)
            last = a
            rejected = 0
        else:
            rejected += 1
    return keep, new_rev, last, rejected


class Revolutions:
    """Collects nodes and hands out each revolution once the next one has started.

    Line noise can make a misread node pass the check bits: a node whose angle jumps
    more than 20 degrees from the previous one is dropped (counted in :attr:`dropped`),
    and a start flag counts only where the angle wraps past 360 degrees, so a stray
    start flag in mid-turn does not cut a revolution in two.
    """

    def __init__(self) -> None:
        self._parts: list[NDArray[np.void]] = []
        self._last = -1
        self._rejected = 0
        self.dropped = 0

    def push(self, nodes: NDArray[np.void]) -> list[NDArray[np.void]]:
        """Add decoded nodes; returns the revolutions they complete."""
        done: list[NDArray[np.void]] = []
        if len(nodes) == 0:
            return done
        keep, new_rev, self._last, self._rejected = _screen(
            nodes["angle_q6"].astype(np.int64),
            nodes["start"].astype(np.bool_),
            self._last,
            self._rejected,
        )
        self.dropped += int((~keep).sum())
        nodes = nodes[keep]
        starts = np.flatnonzero(new_rev[keep])
        prev = 0
        for s in starts:
            if s > prev:
                self._parts.append(nodes[prev:s])
            if self._parts:
                done.append(np.concatenate(self._parts))
            self._parts = []
            prev = int(s)
        if prev < len(nodes):
            self._parts.append(nodes[prev:])
        return done


def points_per_circle(us_per_sample: float, scan_frequency_hz: float) -> int:
    """rplidar_ros's ``points_per_circle``."""
    return int(1000 * 1000 / us_per_sample / scan_frequency_hz)


@numba.njit(cache=True, nogil=True)
def _compensate(
    angle_deg: NDArray[np.float64],
    dist_q2: NDArray[np.uint16],
    quality: NDArray[np.uint8],
    multiple: float,
    count: int,
) -> tuple[NDArray[np.uint16], NDArray[np.uint8]]:
    out_d = np.zeros(count, np.uint16)
    out_q = np.zeros(count, np.uint8)
    copies = int(math.ceil(multiple))
    for i in range(angle_deg.size):
        if dist_q2[i] == 0:
            continue
        base = int(angle_deg[i] * multiple)
        for j in range(copies):
            k = min(base + j, count - 1)
            out_d[k] = dist_q2[i]
            out_q[k] = quality[i]
    return out_d, out_q


def build_scan(
    nodes: NDArray[np.void],
    *,
    angle_compensate: bool,
    inverted: bool,
    us_per_sample: float,
    scan_frequency_hz: float,
    max_distance_m: float,
) -> ScanData | None:
    """One revolution's LaserScan numbers, or None when it has no valid node."""
    order = np.argsort(nodes["angle_q6"], kind="stable")
    nodes = np.asarray(nodes[order], dtype=NODE_DTYPE)
    valid = np.flatnonzero(nodes["dist_q2"])
    if valid.size == 0:
        return None
    angles = nodes["angle_q6"].astype(np.float64) / 64.0
    if angle_compensate:
        multiple = max(points_per_circle(us_per_sample, scan_frequency_hz) / 360.0 + 1, 1.0)
        count = int(360 * multiple)
        dist, quality = _compensate(angles, nodes["dist_q2"], nodes["quality"], multiple, count)
        dev_min, dev_max = 0.0, 2 * math.pi
    else:
        first, last = int(valid[0]), int(valid[-1])
        dist = nodes["dist_q2"][first : last + 1]
        quality = nodes["quality"][first : last + 1]
        dev_min, dev_max = math.radians(angles[first]), math.radians(angles[last])
        count = last - first + 1
    reversed_ = dev_max > dev_min
    if reversed_:
        angle_min, angle_max = math.pi - dev_max, math.pi - dev_min
    else:
        angle_min, angle_max = math.pi - dev_min, math.pi - dev_max
    increment = (angle_max - angle_min) / (count - 1) if count > 1 else 0.0
    ranges = dist.astype(np.float32) / np.float32(4000.0)
    ranges[dist == 0] = np.inf
    intensities = quality.astype(np.float32)
    if reversed_ != inverted:
        ranges, intensities = ranges[::-1].copy(), intensities[::-1].copy()
    return ScanData(
        angle_min, angle_max, increment, ranges, intensities, RANGE_MIN_M, max_distance_m
    )
