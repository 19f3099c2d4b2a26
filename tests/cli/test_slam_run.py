"""``roverlab slam run`` on a slice of a real benchmark log, then ``slam eval``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "radish"


@pytest.mark.skipif(not (DATA / "intel.clf.bz2").is_file(), reason="shared/data/radish is absent")
def test_hector_on_an_intel_slice_writes_map_trajectory_and_scores(tmp_path: Path) -> None:
    out = tmp_path / "run"
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "run", str(DATA / "intel.clf.bz2"),
         "--method", "hector", "--first", "1500", "--param", "map_size:=2048", "--out", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    for name in ("map.yaml", "map.pgm", "map.png", "trajectory.tum"):
        assert (out / name).is_file()
    lines = (out / "trajectory.tum").read_text().splitlines()
    assert len(lines) == 1500 and lines[0].split()[0] == "976052857.337530"
    e = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "eval", str(out / "trajectory.tum"),
         str(DATA / "intel.relations")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert e.returncode == 0, e.stderr
    trans = float(e.stdout.split("translational error:")[1].split("+-")[0])
    assert trans < 0.05  # the slice's relations (the full log scores 0.021 m)


def test_unknown_method_is_one_line_exit_2(tmp_path: Path) -> None:
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "run", str(tmp_path / "x.clf"),
         "--method", "karto"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert r.returncode == 2
    assert r.stderr.strip() == "error: unknown method 'karto' (hector, gmapping or graph)"
