"""``roverlab map``: info, bad input, server + save."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from roverlab.cli.maps import app
from roverlab.maps import MapError, save_map
from tests.helpers.nodes import run_main
from tests.helpers.procs import Proc

runner = CliRunner()


def _run(*args: str, cwd: Path, timeout: float = 60.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "map", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
        env=dict(os.environ),
    )


@pytest.fixture
def office(tmp_path: Path) -> Path:
    data = np.full((40, 60), -1, dtype=np.int8)
    data[5:35, 5:55] = 0
    data[5, 5:55] = 100
    save_map(tmp_path / "office", data, resolution=0.05, origin=(-1.5, -1.0, 0.0))
    return tmp_path / "office.yaml"


def test_info(office: Path) -> None:
    result = runner.invoke(app, ["info", str(office)])
    assert result.exit_code == 0, result.output
    out = result.output
    assert "size:       60 x 40 cells (3.000 x 2.000 m)" in out
    assert "resolution: 0.05 m/cell" in out
    assert "origin:     [-1.5, -1, 0]" in out
    assert "mode:       trinary (negate 0, occupied_thresh 0.65, free_thresh 0.196)" in out
    assert f"cells:      {29 * 50} free, 50 occupied, {2400 - 30 * 50} unknown" in out


def test_info_bad_input_raises_map_error(tmp_path: Path) -> None:
    (tmp_path / "bad.yaml").write_text("image: m.pgm\nresolution: 0.05\n")
    result = runner.invoke(app, ["info", str(tmp_path / "bad.yaml")])
    assert isinstance(result.exception, MapError)
    assert "bad.yaml: missing key 'origin'" in str(result.exception)


def test_bad_input_is_one_line_and_exit_2(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    # one real process (its whole stderr is the line), the other cases in this process
    # (stdout and stderr captured at the file descriptors): each process costs an import
    proc = _run("info", "missing.yaml", cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stderr == "error: missing.yaml: map file not found\n"
    monkeypatch.chdir(tmp_path)
    assert run_main(["map", "save", "-f", "x", "--occ", "0"]) == 2
    err = capfd.readouterr().err
    assert err.strip() == "error: threshold_occupied must be between 1 and 100, got 0"
    assert run_main(["map", "server", "missing.yaml"]) == 2
    err = capfd.readouterr().err
    assert err.strip().splitlines()[-1] == "error: missing.yaml: map file not found"
    assert list(tmp_path.iterdir()) == []


def test_help_names_the_command() -> None:
    result = runner.invoke(app, ["--help"], prog_name="roverlab map")
    assert result.exit_code == 0
    assert "roverlab map" in result.output
    for command in ("server", "save", "info"):
        assert command in result.output


@pytest.mark.zenoh
def test_server_and_save_in_two_processes(daemon: str, office: Path, tmp_path: Path) -> None:
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    server = Proc([sys.executable, "-m", "roverlab.cli", "map", "server", str(office)])
    try:
        line = server.wait_line(lambda s: s.startswith("map_server:"), timeout=60)
        assert "publishing a 60 X 40 map @ 0.050 m/cell" in line and "/map" in line
        proc = _run("save", "-f", "saved", "--timeout", "30", cwd=out_dir)
    finally:
        server.stop()
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines() == [
        "Waiting for the map",
        "Received a 60 X 40 map @ 0.050 m/pix",
        "Writing map occupancy data to saved.pgm",
        "Writing map occupancy data to saved.yaml",
        "Done",
    ]
    assert (out_dir / "saved.pgm").read_bytes() == (tmp_path / "office.pgm").read_bytes()
    expected = (tmp_path / "office.yaml").read_text().replace("office.pgm", "saved.pgm")
    assert (out_dir / "saved.yaml").read_text() == expected


@pytest.mark.zenoh
def test_save_times_out_without_a_map(daemon: str, tmp_path: Path) -> None:
    proc = _run("save", "-f", "never", "--topic", "/no_map_here", "--timeout", "1", cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stdout == "Waiting for the map\n"
    assert proc.stderr == "error: no map received on /no_map_here within 1 s\n"
    assert list(tmp_path.iterdir()) == []
