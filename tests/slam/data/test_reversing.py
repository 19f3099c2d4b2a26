"""Repairing CARMEN odometry that moved forward while the robot reversed (fr079's fault)."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.slam.data import load_log
from roverlab.slam.data.reversing import ReversingRepair


def _true_path() -> list[tuple[SE2, float]]:
    """A robot that drives forward along an arc, then backs up turning, then goes forward:
    (true pose, tv of the step that led to it) every 0.1 s."""
    pose = SE2(1.0, 2.0, 0.3)
    out: list[tuple[SE2, float]] = [(pose, 0.5)]
    for k in range(1, 60):
        tv = -0.4 if 20 <= k < 40 else 0.5
        rv = 0.2 if k < 40 else -0.1
        pose = pose * SE2(0.1 * tv, 0.005 * tv, 0.1 * rv)
        out.append((pose, tv))
    return out


def _as_logged(path: list[tuple[SE2, float]]) -> list[SE2]:
    """What the faulty base logs: every step's translation taken forward (|tv|)."""
    logged = [path[0][0]]
    for (a, _), (b, _) in itertools.pairwise(path):
        step = ~a * b
        if step.x < 0.0:
            step = SE2(-step.x, -step.y, step.theta)
        logged.append(logged[-1] * step)
    return logged


def test_forward_steps_while_reversing_are_reversed() -> None:
    path = _true_path()
    logged = _as_logged(path)
    repair = ReversingRepair()
    fixed = [repair.odom(p, tv) for p, (_, tv) in zip(logged, path, strict=True)]
    assert repair.steps == 59 and repair.reversed_steps == 20
    for f, (truth, _) in zip(fixed, path, strict=True):
        assert f.x == pytest.approx(truth.x, abs=1e-9)
        assert f.y == pytest.approx(truth.y, abs=1e-9)
        assert math.remainder(f.theta - truth.theta, 2 * math.pi) == pytest.approx(0, abs=1e-9)
    # as logged, the robot ends far from where it is
    assert math.hypot(logged[-1].x - path[-1][0].x, logged[-1].y - path[-1][0].y) > 1.0


def test_a_scan_between_odom_lines_is_repaired_from_the_last_line() -> None:
    path = _true_path()
    logged = _as_logged(path)
    repair = ReversingRepair()
    for p, (_, tv) in zip(logged[:31], path[:31], strict=True):
        repair.odom(p, tv)
    # a scan half-way to the next (reversing) step
    half = ~logged[30] * logged[31]
    scan_logged = logged[30] * SE2(0.5 * half.x, 0.5 * half.y, 0.5 * half.theta)
    truth = path[30][0] * SE2(-0.5 * half.x, -0.5 * half.y, 0.5 * half.theta)
    got = repair.scan(scan_logged)
    assert got.x == pytest.approx(truth.x, abs=1e-9) and got.y == pytest.approx(truth.y, abs=1e-9)


def test_consistent_odometry_is_unchanged_bit_for_bit() -> None:
    path = _true_path()
    repair = ReversingRepair()  # this base integrates reversing correctly
    for truth, tv in path:
        got = repair.odom(truth, tv)
        assert got is truth
        assert repair.scan(truth) is truth
    assert repair.reversed_steps == 0


def test_read_clf_repairs_on_request(tmp_path: Path) -> None:
    path = _true_path()
    logged = _as_logged(path)
    lines = []
    for k, (p, (_, tv)) in enumerate(zip(logged, path, strict=True)):
        t = 100.0 + 0.1 * k
        lines.append(f"ODOM {p.x:.9f} {p.y:.9f} {p.theta:.9f} {tv} 0.0 0.0 {t:.6f} h {t:.6f}")
        if k % 5 == 0:
            pose = " ".join(f"{v:.9f}" for v in (p.x, p.y, p.theta) * 2)
            ranges = " ".join(["1.0"] * 5)
            lines.append(f"FLASER 5 {ranges} {pose} {t + 0.001:.6f} h {t + 0.001:.6f}")
    f = tmp_path / "rev.clf"
    f.write_text("\n".join(lines) + "\n")
    raw = load_log(f)
    repair = ReversingRepair()
    fixed = load_log(f, reversing=repair)
    assert repair.reversed_steps == 20
    truth = np.array([[p.x, p.y] for p, _ in path[::5]])
    assert np.abs(fixed.odom_poses[:, :2] - truth).max() < 1e-6
    assert np.abs(raw.odom_poses[:, :2] - truth).max() > 1.0
    np.testing.assert_array_equal(fixed.laser_offsets, raw.laser_offsets)
