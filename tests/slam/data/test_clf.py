"""CARMEN log reading: FLASER / ROBOTLASER1 / RAWLASER1 / ODOM lines, compression, errors."""

from __future__ import annotations

import bz2
import gzip
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.slam.data import LaserLog, LogError, carmen_beam_geometry, iter_log, load_log


def flaser(ranges: list[float], laser: SE2, odom: SE2, stamp: str) -> str:
    vals = " ".join(f"{r:.2f}" for r in ranges)
    poses = " ".join(f"{v:.6f}" for v in (*laser.as_array(), *odom.as_array()))
    return f"FLASER {len(ranges)} {vals} {poses} {stamp} nohost 0.000246"


def robot_odom_laser(k: int) -> tuple[SE2, SE2]:
    """Odometry pose k and the laser 0.04 m behind the robot centre, as in fr079."""
    odom = SE2(1.0 + 0.5 * k, -2.0 + 0.25 * k, math.remainder(2.5 + 0.4 * k, 2 * math.pi))
    return odom, odom * SE2(-0.04, 0.0, 0.0)


STAMPS = ("976052857.337530", "976052857.348896", "976052857.542230")


def sample_log() -> str:
    lines = [
        "# CARMEN Logfile",
        "# message_name [message contents] ipc_timestamp ipc_hostname logger_timestamp",
        "PARAM robot_frontlaser_offset 0.0 nohost 0",
        "ODOM 0.000000 0.000000 -0.002458 0.000000 0.000000 0.000000 976052857.337284 nohost 0.0",
    ]
    for k, stamp in enumerate(STAMPS):
        odom, laser = robot_odom_laser(k)
        lines.append(flaser([1.0 + 0.01 * i for i in range(180)], laser, odom, stamp))
        lines.append("RLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 976052857.6 nohost 0.1")  # rear: skipped
    lines.append("TRUEPOS 0 0 0 0 0 0 976052858.0 nohost 0.7")
    return "\n".join(lines) + "\n"


@pytest.fixture(params=["plain", "gz", "bz2"])
def clf_file(request: pytest.FixtureRequest, tmp_path: Path) -> Path:
    data = sample_log().encode()
    path = tmp_path / f"log.clf.{request.param}"
    if request.param == "gz":
        path.write_bytes(gzip.compress(data))
    elif request.param == "bz2":
        path.write_bytes(bz2.compress(data))
    else:
        path = tmp_path / "log.clf"
        path.write_bytes(data)
    return path


def test_flaser_records_from_plain_and_compressed_files(clf_file: Path) -> None:
    log = load_log(clf_file)
    assert isinstance(log, LaserLog)
    assert len(log) == 3
    assert log.timestamp_texts == STAMPS  # the text exactly, trailing zero included
    assert log.timestamps[0] == 976052857.337530
    for k, rec in enumerate(log):
        odom, laser = robot_odom_laser(k)
        assert rec.ranges.dtype == np.float32 and rec.ranges.shape == (180,)
        assert rec.ranges[0] == np.float32(1.0) and rec.ranges[-1] == np.float32(2.79)
        assert not rec.ranges.flags.writeable
        assert rec.odom_pose.x == pytest.approx(odom.x, abs=1e-6)
        assert rec.odom_pose.theta == pytest.approx(odom.theta, abs=1e-6)
        # offset = odom^-1 * laser: the laser sits 4 cm behind the robot centre
        assert rec.laser_offset.x == pytest.approx(-0.04, abs=1e-5)
        assert rec.laser_offset.y == pytest.approx(0.0, abs=1e-5)
        assert rec.laser_offset.theta == pytest.approx(0.0, abs=1e-6)
        assert rec.laser_pose.x == pytest.approx(laser.x, abs=1e-6)
        assert rec.laser_pose.y == pytest.approx(laser.y, abs=1e-6)
        assert rec.range_min == 0.0 and rec.range_max == 80.0
    np.testing.assert_allclose(
        log.laser_poses()[:, :2], [[r.laser_pose.x, r.laser_pose.y] for r in log]
    )
    assert log.ranges_matrix().shape == (3, 180)


def test_reader_is_a_generator(clf_file: Path) -> None:
    stream = iter_log(clf_file)
    first = next(stream)
    assert first.timestamp_text == STAMPS[0]
    assert [r.timestamp_text for r in stream] == list(STAMPS[1:])


@pytest.mark.parametrize(
    ("n", "increment_deg", "last_deg"),
    [(180, 1.0, 89.0), (181, 1.0, 90.0), (360, 0.5, 89.5), (361, 0.5, 90.0), (2, 90.0, 0.0)],
)
def test_flaser_beam_geometry_follows_carmen(n: int, increment_deg: float, last_deg: float) -> None:
    a0, inc = carmen_beam_geometry(n)
    assert a0 == pytest.approx(-math.pi / 2)
    assert math.degrees(inc) == pytest.approx(increment_deg)
    assert math.degrees(a0 + (n - 1) * inc) == pytest.approx(last_deg)


def test_flaser_geometry_in_records(tmp_path: Path) -> None:
    path = tmp_path / "g.clf"
    odom, laser = robot_odom_laser(0)
    path.write_text(
        flaser([1.0] * 361, laser, odom, "1.000001")
        + "\n"
        + flaser([1.0] * 180, laser, odom, "2.5")
        + "\n"
    )
    a, b = load_log(path)
    assert math.degrees(a.angle_max) == pytest.approx(90.0)
    assert math.degrees(a.angle_increment) == pytest.approx(0.5)
    assert math.degrees(b.angle_max) == pytest.approx(89.0)
    assert a.angles()[0] == pytest.approx(-math.pi / 2)
    assert b.timestamp_text == "2.5"
    pts = a.points()
    assert pts.shape == (361, 2)
    np.testing.assert_allclose(pts[0], [0.0, -1.0], atol=1e-12)
    np.testing.assert_allclose(pts[180], [1.0, 0.0], atol=1e-12)


def test_beams_at_no_return_value_are_invalid(tmp_path: Path) -> None:
    path = tmp_path / "g.clf"
    odom, laser = robot_odom_laser(0)
    path.write_text(flaser([1.0, 81.83, 2.0, 81.91], laser, odom, "3.0") + "\n")
    (rec,) = load_log(path)
    assert rec.points().shape == (2, 2)
    (rec,) = load_log(path, range_max_m=100.0)
    assert rec.range_max == 100.0 and rec.points().shape == (4, 2)


def test_malformed_line_names_file_and_line(tmp_path: Path) -> None:
    good = sample_log().splitlines()
    bad = [*good[:6], "FLASER 180 1.0 2.0 3.0 0 0 0 0 0 0 976052858.0 nohost 0.1", *good[6:]]
    path = tmp_path / "bad.clf"
    path.write_text("\n".join(bad) + "\n")
    with pytest.raises(LogError, match=r"bad\.clf:7: malformed line"):
        load_log(path)
    path.write_text(good[4].replace(" 1.05 ", " x.yz ") + "\n")
    with pytest.raises(LogError, match=r"bad\.clf:1: "):
        load_log(path)
    path.write_text("ODOM 1 2 3\n")
    with pytest.raises(LogError, match=r"bad\.clf:1: .*ODOM"):
        load_log(path)


def test_truncated_compressed_file_is_a_log_error(tmp_path: Path) -> None:
    path = tmp_path / "cut.clf.bz2"
    path.write_bytes(bz2.compress(sample_log().encode())[:200])
    with pytest.raises(LogError, match=r"cut\.clf\.bz2"):
        load_log(path)


def test_missing_file_and_unknown_option(tmp_path: Path) -> None:
    with pytest.raises(LogError, match="no such file"):
        load_log(tmp_path / "absent.clf")
    path = tmp_path / "log.clf"
    path.write_text(sample_log())
    with pytest.raises(LogError, match=r"unknown option.*scan_topic"):
        load_log(path, scan_topic="/scan")
    with pytest.raises(LogError, match="unknown CARMEN laser message"):
        load_log(path, laser_message="LASER9")


def test_poseless_flaser_takes_interpolated_odom(tmp_path: Path) -> None:
    # the robot turns through +-pi between the two ODOM samples: interpolate the short way
    path = tmp_path / "old.clf"
    path.write_text(
        "PARAM robot_frontlaser_offset 0.12 nohost 0\n"
        "ODOM 0.0 0.0 3.0 0 0 0 10.000000 nohost 0\n"
        "FLASER 3 1.0 1.5 2.0 10.250000 nohost 0\n"
        "ODOM 2.0 -1.0 -3.0 0 0 0 11.000000 nohost 0\n"
        "FLASER 3 1.0 1.5 2.0 11.500000 nohost 0\n"
    )
    a, b = load_log(path)
    step = 2 * math.pi - 6.0  # from 3.0 up to -3.0 + 2 pi
    assert a.odom_pose.x == pytest.approx(0.5)
    assert a.odom_pose.y == pytest.approx(-0.25)
    assert a.odom_pose.theta == pytest.approx(3.0 + 0.25 * step)
    assert a.laser_offset == SE2(0.12, 0.0, 0.0)
    assert a.timestamp_text == "10.250000"
    # after the last ODOM line the pose is held
    assert (b.odom_pose.x, b.odom_pose.y, b.odom_pose.theta) == (2.0, -1.0, -3.0)


def robotlaser(n: int, laser: SE2, odom: SE2, stamp: str) -> str:
    ranges = " ".join("2.0" for _ in range(n))
    poses = " ".join(f"{v:.6f}" for v in (*laser.as_array(), *odom.as_array()))
    return (
        f"ROBOTLASER1 0 -2.094395 4.188790 0.006136 5.600000 0.010000 0 {n} {ranges} "
        f"2 0.5 0.6 {poses} 0.0 0.0 0.5 0.5 0.0 {stamp} host 0.1"
    )


def rawlaser(n: int, stamp: str) -> str:
    ranges = " ".join("3.0" for _ in range(n))
    config = "0 -2.094395 4.188790 0.006136 5.600000 0.010000 0"
    return f"RAWLASER1 {config} {n} {ranges} 0 {stamp} host 0.1"


def test_robotlaser_and_the_first_laser_kind_wins(tmp_path: Path) -> None:
    odom, laser = robot_odom_laser(1)
    path = tmp_path / "new.clf"
    path.write_text(
        "ODOM 0.0 0.0 0.0 0 0 0 0.5 host 0\n"
        + rawlaser(4, "1.000000")
        + "\n"
        + robotlaser(4, laser, odom, "1.000000")
        + "\n"
        + flaser([1.0, 1.0], laser, odom, "1.000000")
        + "\n"
        + "ODOM 1.0 0.0 0.0 0 0 0 1.5 host 0\n"
    )
    (rec,) = load_log(path)  # ROBOTLASER1 came first of the posed kinds; RAWLASER1 skipped
    assert rec.ranges.shape == (4,)
    assert rec.angle_min == pytest.approx(-2.094395)
    assert rec.angle_increment == pytest.approx(0.006136)
    assert rec.range_max == pytest.approx(5.6)
    assert rec.odom_pose.x == pytest.approx(odom.x, abs=1e-6)
    assert rec.laser_offset.x == pytest.approx(-0.04, abs=1e-5)
    (raw,) = load_log(path, laser_message="RAWLASER1")
    assert float(raw.ranges[0]) == 3.0
    assert raw.odom_pose.x == pytest.approx(0.5)  # interpolated between the ODOM lines
    (fl,) = load_log(path, laser_message="FLASER")
    assert fl.ranges.shape == (2,)


def test_robotlaser_with_wrong_remission_count_is_rejected(tmp_path: Path) -> None:
    odom, laser = robot_odom_laser(0)
    path = tmp_path / "bad.clf"
    path.write_text(robotlaser(4, laser, odom, "1.0").replace(" 2 0.5 0.6 ", " 3 0.5 0.6 ") + "\n")
    with pytest.raises(LogError, match=r"bad\.clf:1: .*ROBOTLASER1"):
        load_log(path)


def test_log_slicing_index_and_odometry(clf_file: Path) -> None:
    log = load_log(clf_file)
    assert len(log[1:]) == 2 and log[1:][0].timestamp_text == STAMPS[1]
    assert log.index_of(STAMPS[2]) == 2
    assert log.index_of(976052857.3488962) == 1  # a float within 1 us
    with pytest.raises(ValueError, match="no scan"):
        log.index_of("1.0")
    traj = log.odometry()
    assert traj.timestamp_texts == STAMPS
    np.testing.assert_array_equal(traj.poses, log.odom_poses)
    np.testing.assert_allclose(log.odometry(frame="laser").poses, log.laser_poses())
    with pytest.raises(LogError, match="unknown frame"):
        log.odometry(frame="map")
    assert log.duration_s == pytest.approx(976052857.542230 - 976052857.337530)


# ------------------------------------------------------------------ the Radish logs


@pytest.mark.parametrize(
    ("name", "scans", "beams", "duration_s", "first_stamp"),
    [
        ("intel", 13631, 180, 2691, "976052857.337530"),
        ("fr079", 4934, 360, 1061, "1211.520329"),
        ("mit-csail", 1988, 361, 424, "1134864629.895182"),
    ],
)
def test_radish_logs(
    radish: Path, name: str, scans: int, beams: int, duration_s: float, first_stamp: str
) -> None:
    t0 = time.perf_counter()
    log = load_log(radish / f"{name}.clf.bz2")
    elapsed = time.perf_counter() - t0
    print(f"{name}: {len(log)} scans loaded in {elapsed:.2f} s")
    assert len(log) == scans
    assert log.ranges_matrix().shape == (scans, beams)
    assert log.duration_s == pytest.approx(duration_s, abs=1.0)
    assert log.timestamp_texts[0] == first_stamp
    assert len(set(log.timestamp_texts)) == scans
    assert elapsed < 30.0  # about 3 s for intel on a quiet machine


def test_fr079_laser_offset(radish_log: Callable[[str], LaserLog]) -> None:
    log = radish_log("fr079")
    # PARAM robot_frontlaser_offset -0.04: the laser 4 cm behind the centre, everywhere
    np.testing.assert_allclose(log.laser_offsets[:, 0], -0.04, atol=2e-5)
    np.testing.assert_allclose(log.laser_offsets[:, 1:], 0.0, atol=2e-5)
