"""TUM trajectory files: exact timestamps, exact round trip, atomic writes, errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.slam.data import Trajectory, TrajectoryError, format_timestamp, read_tum, write_tum

STAMPS = ["976052857.337530", "976052857.348896", "1700000000.123456789", "12.5"]


def poses() -> list[SE2]:
    return [
        SE2(0.0, 0.0, 0.0),
        SE2(1.25, -0.5, 3.0),
        SE2(-2.0, 7.123456789, -3.1),
        SE2(0.1, 0.2, 1e-9),
    ]


def test_round_trip_is_exact(tmp_path: Path) -> None:
    path = tmp_path / "traj.tum"
    write_tum(path, STAMPS, poses())
    lines = path.read_text().splitlines()
    assert [line.split()[0] for line in lines] == STAMPS  # the text, byte for byte
    assert lines[0] == "976052857.337530 0.0 0.0 0.0 0.0 0.0 0.0 1.0"
    fields = lines[1].split()
    assert len(fields) == 8 and fields[3] == "0.0"
    assert float(fields[6]) == pytest.approx(math.sin(1.5)) and float(fields[7]) == pytest.approx(
        math.cos(1.5)
    )
    traj = read_tum(path)
    assert traj.timestamp_texts == tuple(STAMPS)
    assert traj.timestamps[0] == 976052857.337530
    expected = np.array([p.as_array() for p in poses()])
    np.testing.assert_array_equal(traj.poses[:, :2], expected[:, :2])
    np.testing.assert_allclose(traj.poses[:, 2], expected[:, 2], atol=1e-15)
    # writing what was read repeats the timestamps and positions exactly
    again = tmp_path / "again.tum"
    write_tum(again, traj)
    new_lines = again.read_text().splitlines()
    assert [line.split()[:4] for line in new_lines] == [line.split()[:4] for line in lines]


def test_float_timestamps_and_arrays(tmp_path: Path) -> None:
    path = tmp_path / "f.tum"
    write_tum(path, [976052857.33753, 1.0], np.array([[1.0, 2.0, 0.5], [3.0, 4.0, -0.5]]))
    assert [line.split()[0] for line in path.read_text().splitlines()] == [
        "976052857.337530",
        "1.000000",
    ]
    traj = read_tum(path)
    np.testing.assert_allclose(traj.poses, [[1.0, 2.0, 0.5], [3.0, 4.0, -0.5]], atol=1e-15)


def test_trajectory_from_poses_keeps_texts() -> None:
    traj = Trajectory.from_poses(STAMPS, poses())
    assert traj.timestamp_texts == tuple(STAMPS)
    assert traj.se2(1) == SE2(1.25, -0.5, 3.0)
    floats = Trajectory.from_poses([1.0, 2.0], [SE2(), SE2(1.0, 0.0, 0.0)])
    assert floats.timestamp_texts is None and floats.texts() == ("1.000000", "2.000000")
    with pytest.raises(TrajectoryError, match="expected 2 poses"):
        Trajectory.from_poses([1.0, 2.0], [SE2()])


def test_write_is_atomic_and_errors_name_the_file(tmp_path: Path) -> None:
    path = tmp_path / "t.tum"
    path.write_text("old\n")
    with pytest.raises(TrajectoryError, match="not a number"):
        write_tum(path, ["12.x"], [SE2()])
    assert path.read_text() == "old\n"  # untouched by the failed write
    with pytest.raises(TrajectoryError, match="cannot write"):
        write_tum(tmp_path / "missing" / "t.tum", ["1.0"], [SE2()])
    write_tum(path, ["1.0"], [SE2()])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.tum"]  # no temporary file left


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("1.0 0 0 0 0 0 0\n", r"t\.tum:1: expected 8 values"),
        ("# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 x 1\n", r"t\.tum:3: not a number"),
        ("1.0 0 0 0 0 0 0 0\n", r"t\.tum:1: zero quaternion"),
        ("1.0 nan 0 0 0 0 0 1\n", r"t\.tum:1: non-finite"),
    ],
)
def test_read_errors(tmp_path: Path, text: str, match: str) -> None:
    path = tmp_path / "t.tum"
    path.write_text(text)
    with pytest.raises(TrajectoryError, match=match):
        read_tum(path)


def test_read_unnormalised_quaternion_and_comments(tmp_path: Path) -> None:
    path = tmp_path / "t.tum"
    half = 0.3
    path.write_text(
        f"# t x y z qx qy qz qw\n\n5.0 1 2 3 0 0 {2 * math.sin(half)} {2 * math.cos(half)}\n"
    )
    traj = read_tum(path)
    assert len(traj) == 1
    np.testing.assert_allclose(traj.poses[0], [1.0, 2.0, 0.6])


def test_format_timestamp() -> None:
    assert format_timestamp(" 976052857.337530 ") == "976052857.337530"
    assert format_timestamp(976052857.33753) == "976052857.337530"
    assert format_timestamp(1.5, decimals=9) == "1.500000000"
    for bad in ("", "1 2", "inf"):
        with pytest.raises(TrajectoryError):
            format_timestamp(bad)
    with pytest.raises(TrajectoryError, match="finite"):
        format_timestamp(math.nan)


def test_trajectory_validation() -> None:
    with pytest.raises(TrajectoryError, match=r"shape \(2, 3\)"):
        Trajectory(timestamps=np.zeros(2), poses=np.zeros((3, 3)))
    with pytest.raises(TrajectoryError, match="1 timestamp texts for 2 poses"):
        Trajectory(timestamps=np.zeros(2), poses=np.zeros((2, 3)), timestamp_texts=("0",))
