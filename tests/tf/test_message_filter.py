"""TfMessageFilter: messages wait for their transform, and ones whose data is gone for good
are dropped (tf2_ros' MessageFilter), even when the lookup fails on an edge above the
target frame."""

from __future__ import annotations

from typing import Any

from roverlab.core import Context, Time
from roverlab.geometry import Transform3
from roverlab.msgs import LaserScan
from roverlab.tf import Buffer, TfMessageFilter

IDENTITY = Transform3((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def _scan(seconds: float) -> Any:
    t = Time.from_seconds(seconds).to_msg()
    return LaserScan(header={"stamp": t, "frame_id": "base_scan"}, ranges=[1.0])


def _filter() -> tuple[Context, Buffer, TfMessageFilter, list[float]]:
    ctx = Context()
    node = ctx.create_node("amcl")
    buffer = Buffer()  # filled directly: the filter only reads it
    passed: list[float] = []
    filt = TfMessageFilter(
        node, buffer, ["odom"], 5, lambda m: passed.append(Time.from_msg(m.header.stamp).seconds)
    )
    buffer.set_transform("base_footprint", "base_scan", Time(0), IDENTITY, is_static=True)
    return ctx, buffer, filt, passed


def test_a_message_older_than_the_kept_odometry_is_dropped_not_kept_waiting() -> None:
    # amcl after its process stalled: odometry kept for the last 10 s (90-100 s), its own
    # map -> odom last sent at 54.5 s. A scan stamped 60 s can never be transformed; its
    # lookup fails on map -> odom above the target 'odom' ("extrapolation into the
    # future"), which only amcl itself could fill, after this very scan.
    ctx, buffer, filt, passed = _filter()
    for k in range(900, 1001):
        buffer.set_transform("odom", "base_footprint", Time.from_seconds(k / 10), IDENTITY)
    for k in range(445, 546):
        buffer.set_transform("map", "odom", Time.from_seconds(k / 10), IDENTITY)
    filt.add(_scan(60.0))
    assert filt.waiting == 0 and filt.dropped == 1  # it used to wait for ever
    filt.add(_scan(99.5))  # and to block every newer scan behind it
    assert passed == [99.5]
    ctx.shutdown()


def test_a_message_newer_than_the_odometry_waits_for_it() -> None:
    ctx, buffer, filt, passed = _filter()
    for k in range(900, 1001):
        buffer.set_transform("odom", "base_footprint", Time.from_seconds(k / 10), IDENTITY)
    filt.add(_scan(100.5))
    assert filt.waiting == 1 and filt.dropped == 0 and passed == []
    buffer.set_transform("odom", "base_footprint", Time.from_seconds(101.0), IDENTITY)
    filt._on_tf(None)  # what the next /tf message does
    assert passed == [100.5] and filt.waiting == 0
    ctx.shutdown()
