"""The real C++ move_base (ros-planning/navigation noetic-devel, built by
``scripts/build-ros1-navigation.sh``) drives roverlab's simulator over ROS 1: BARN's world 61
with BARN's launch and parameter files, run by ``benchmarks/barn_ros1_baseline.py``.

Slow (about 30 s):
``ROS1_NAVIGATION_WS=WS pytest -m slow tests/core/ros1/test_move_base_cpp_ros1.py``.
Skips with one line when ``$ROS1_NAVIGATION_WS`` is unset or holds no built move_base, or
when BARN's data is not beside the repository."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.core.ros1.conftest import HAVE_ROS1

ROOT = Path(__file__).resolve().parents[3]
WS = os.environ.get("ROS1_NAVIGATION_WS", "")
BARN = ROOT.parent / "shared" / "data" / "barn"
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not HAVE_ROS1, reason="Debian's ROS 1 (/usr/bin/roscore) is not installed"),
    pytest.mark.skipif(
        not (WS and (Path(WS) / "devel/lib/move_base/move_base").is_file()),
        reason="no real move_base: set ROS1_NAVIGATION_WS to a workspace built by "
        "scripts/build-ros1-navigation.sh",
    ),
    pytest.mark.skipif(not (BARN / "worlds").is_dir(), reason=f"{BARN}: BARN's data not found"),
]


def test_real_move_base_reaches_barn_goal_on_roverlab_sim(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks/barn_ros1_baseline.py"), "--ws", WS,
         "--worlds", str(BARN / "worlds"), "--out", str(out), "--only", "61", "--rate", "2"],
        capture_output=True, text=True, timeout=240,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    row = json.loads((out / "world_61.json").read_text())
    assert row["status"] == "succeeded", row
    assert row["contacts"] == 0
    assert 0.0 < row["score"] <= 0.5
    assert row["driven_m"] > 9.0  # the start is 10 m from the goal; success within 1 m
    assert row["move_base_cpu_s"] > 0.0  # move_base ran (and planned) in its own process
    summary = json.loads((out / "summary.json").read_text())
    assert summary["worlds"] == 1 and summary["success_rate"] == 1.0
    assert (out / "world_61.png").stat().st_size > 0
