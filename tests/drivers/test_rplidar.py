"""rplidar: the protocol, scans as rplidar_ros builds them, and the node against an
emulated RPLIDAR A1 on a pty (rate, angles, ranges, silence, garbage, a missing port)."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest

from roverlab.core import Context
from roverlab.drivers.errors import DeviceError, DriverError
from roverlab.drivers.rplidar import (
    NODE_DTYPE,
    NodeDecoder,
    Revolutions,
    ScanData,
    build_scan,
    encode_nodes,
)
from roverlab.drivers.rplidar.node import RplidarNode
from roverlab.drivers.rplidar.protocol import (
    encode_descriptor,
    parse_descriptor,
    parse_info,
    request,
)
from roverlab.msgs import classes as mc
from tests.helpers.devices import RplidarEmulator

pytestmark = pytest.mark.timeout(120)


def room_mm(angle_deg: np.ndarray) -> np.ndarray:
    """1 m + 5 mm per degree; no return between 100 and 104 degrees."""
    r = 1000.0 + 5.0 * np.asarray(angle_deg)
    return np.where((angle_deg >= 100) & (angle_deg < 104), 0.0, r)


def expected_m(scan_angle: np.ndarray) -> np.ndarray:
    """rplidar_ros puts the device angle a at pi - a in the scan."""
    device_deg = np.degrees(math.pi - scan_angle) % 360.0
    return np.asarray(room_mm(device_deg)) / 1000.0


def revolution(n: int = 200) -> np.ndarray:
    nodes = np.zeros(n, NODE_DTYPE)
    angles = np.arange(n) * 360.0 / n
    nodes["start"][0] = True
    nodes["quality"] = 47
    nodes["angle_q6"] = np.round(angles * 64)
    nodes["dist_q2"] = np.round(room_mm(angles) * 4)
    return nodes


def a1_scan(*, angle_compensate: bool, inverted: bool) -> ScanData | None:
    """:func:`build_scan` of one :func:`revolution` at the A1's pace (500 us a sample,
    10 Hz, 12 m)."""
    return build_scan(
        revolution(),
        angle_compensate=angle_compensate,
        inverted=inverted,
        us_per_sample=500,
        scan_frequency_hz=10,
        max_distance_m=12,
    )


def test_requests_descriptors_and_info() -> None:
    assert request(0x20) == b"\xa5\x20"
    # SET_MOTOR_PWM 600: size 2, payload 58 02, checksum = xor of all bytes
    assert request(0xF0, b"\x58\x02") == bytes((0xA5, 0xF0, 2, 0x58, 2, 0xA5 ^ 0xF0 ^ 2 ^ 0x58 ^ 2))
    assert parse_descriptor(encode_descriptor(5, 1, 0x81)) == (5, 1, 0x81)
    with pytest.raises(DeviceError, match="bad response descriptor"):
        parse_descriptor(b"\x00" * 7)
    info = parse_info(bytes((0x18, 29, 1, 7)) + bytes(range(16)))
    assert (info.model_name, info.firmware, info.hardware) == ("A1M8", (1, 29), 7)


def test_decoder_any_chunking_and_garbage() -> None:
    nodes = np.concatenate([revolution(), revolution()])
    stream = encode_nodes(nodes)
    whole = NodeDecoder().feed(stream + stream[:2])  # the last node waits for the next
    assert np.array_equal(whole, nodes)
    dec = NodeDecoder()
    parts = [dec.feed(stream[i : i + 7]) for i in range(0, len(stream), 7)]
    assert np.array_equal(np.concatenate(parts), nodes[:-1])
    # garbage before the stream: dropped until the first start flag lines up
    dec = NodeDecoder()
    got = dec.feed(bytes((0x12, 0x44, 0xFF, 0x00)) + stream)
    assert dec.dropped_bytes > 0 and got[0]["start"] and len(got) >= len(nodes) - 1
    revs = Revolutions()
    done = revs.push(got[:250]) + revs.push(got[250:]) + revs.push(revolution()[:1])
    assert [len(r) for r in done] == [200, 199]  # (the last node waits for the next)


def test_scan_without_angle_compensation() -> None:
    scan = a1_scan(angle_compensate=False, inverted=False)
    assert scan is not None and len(scan.ranges) == 200
    assert scan.angle_max == pytest.approx(math.pi)
    assert scan.angle_min == pytest.approx(math.pi - math.radians(358.2), abs=1e-4)
    angles = scan.angle_min + np.arange(200) * scan.angle_increment
    want = expected_m(angles)
    finite = want > 0
    assert np.allclose(scan.ranges[finite], want[finite], atol=1e-3)
    assert np.isinf(scan.ranges[~finite]).all() and (~finite).sum() == 2
    assert (scan.intensities == 47).all() and scan.range_min == 0.15
    flipped = a1_scan(angle_compensate=False, inverted=True)
    assert flipped is not None and np.array_equal(flipped.ranges, scan.ranges[::-1])


def test_scan_with_angle_compensation() -> None:
    scan = a1_scan(angle_compensate=True, inverted=False)
    assert scan is not None
    # points_per_circle 200 -> multiple 200/360 + 1 -> 560 bins over [-pi, pi]
    assert len(scan.ranges) == 560
    assert (scan.angle_min, scan.angle_max) == pytest.approx((-math.pi, math.pi))
    check_ranges(scan.angle_min, scan.angle_increment, scan.ranges)


def check_ranges(angle_min: float, inc: float, ranges: np.ndarray, share: float = 1.0) -> None:
    angles = angle_min + np.arange(len(ranges)) * inc
    want = expected_m(angles)
    finite = np.isfinite(ranges) & (want > 0)
    assert finite.mean() > 0.6
    good = np.abs(ranges[finite] - want[finite]) < 0.015  # a bin is up to 1.8 degrees off
    assert good.mean() >= share


@pytest.fixture
def lidar() -> RplidarEmulator:
    dev = RplidarEmulator(room_mm, samples_per_rev=200, scan_hz=10.0, seed=1)
    dev.start()
    yield dev
    dev.close()


def start_node(
    contexts: list[Context], port: str
) -> tuple[Context, RplidarNode, list[mc.LaserScan]]:
    ctx = Context(clock="wall")
    contexts.append(ctx)
    node = RplidarNode(
        ctx,
        node_name="rplidarNode",
        parameter_overrides={
            "serial_port": port,
            "serial_baudrate": 115200,
            "frame_id": "base_laser_link",
            "angle_compensate": True,
        },
    )
    scans: list[mc.LaserScan] = []
    ctx.create_node("probe").create_subscription(mc.LaserScan, "/scan", scans.append, 100)
    return ctx, node, scans


def test_node_scans_at_the_device_rate(lidar: RplidarEmulator, contexts: list[Context]) -> None:
    ctx, _node, scans = start_node(contexts, lidar.port)
    ctx.spin_for(1.0)  # connect, info, health, samplerate, motor, scan
    first = len(scans)
    ctx.spin_for(3.0)
    rate = (len(scans) - first) / 3.0
    assert rate == pytest.approx(10.0, abs=1.5)
    s = scans[-1]
    assert s.header.frame_id == "base_laser_link" and len(s.ranges) == 560
    assert s.scan_time == pytest.approx(0.1, abs=0.03)
    check_ranges(s.angle_min, s.angle_increment, s.ranges)
    assert lidar.motor_pwm == 600
    assert lidar.commands[:5] == [0x25, 0x50, 0x52, 0x59, 0xF0]
    ctx.shutdown()


def test_device_goes_silent_then_comes_back(
    lidar: RplidarEmulator, caplog: pytest.LogCaptureFixture, contexts: list[Context]
) -> None:
    caplog.set_level(logging.INFO, logger="roverlab")
    ctx, _node, scans = start_node(contexts, lidar.port)
    ctx.spin_for(1.5)
    assert scans
    lidar.silent = True
    ctx.spin_for(0.3)
    during = len(scans)
    ctx.spin_for(2.5)
    assert len(scans) == during  # nothing while the device is silent
    errors = [
        r.getMessage()
        for r in caplog.records
        if r.levelname == "ERROR" and r.getMessage().startswith(f"{lidar.port}:")
    ]
    assert errors == [
        f"{lidar.port}: the device stopped answering (no data for 1 s); retrying every 1 s"
    ]
    lidar.silent = False
    ctx.spin_for(3.0)
    assert len(scans) > during + 10  # reconnected and scanning
    infos = [r.getMessage() for r in caplog.records if "answers again" in r.getMessage()]
    assert infos == [f"{lidar.port}: the device answers again"]
    check_ranges(scans[-1].angle_min, scans[-1].angle_increment, scans[-1].ranges)
    ctx.shutdown()


def test_garbage_on_the_line(lidar: RplidarEmulator, contexts: list[Context]) -> None:
    lidar.garbage_every = 20  # a noisy line: a burst of 1-11 random bytes every ~40 ms
    ctx, node, scans = start_node(contexts, lidar.port)
    ctx.spin_for(4.0)
    assert lidar.garbage_sent > 100 and node.dropped_bytes >= lidar.garbage_sent // 2
    assert len(scans) >= 25
    passed = 0
    for s in scans[-10:]:  # a misaligned node can pass the check bits: allow a few
        try:
            check_ranges(s.angle_min, s.angle_increment, s.ranges, share=0.95)
            passed += 1
        except AssertionError:
            pass
    assert passed >= 8
    ctx.shutdown()


def test_missing_port_and_bad_parameters(
    caplog: pytest.LogCaptureFixture, contexts: list[Context]
) -> None:
    ctx, _node, scans = start_node(contexts, "/dev/ttyUSB_roverlab_none")
    ctx.spin_for(2.5)
    errors = [
        r.getMessage()
        for r in caplog.records
        if r.levelname == "ERROR" and "roverlab_none" in r.getMessage()
    ]
    assert len(errors) == 1
    assert errors[0].startswith("/dev/ttyUSB_roverlab_none: cannot open the serial port")
    assert scans == []
    ctx.shutdown()
    with pytest.raises(DriverError, match="scan mode `Boost' is not supported"):
        RplidarNode(Context(), parameter_overrides={"scan_mode": "Boost"})
