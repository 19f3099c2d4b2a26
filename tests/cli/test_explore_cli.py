"""``roverlab explore``: a short headless episode writes the map, the plots and the summary;
bad arguments are one clear error line before anything runs."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest


def test_a_short_episode_writes_every_output(cli: Any, tmp_path: Path) -> None:
    out = tmp_path / "run"
    r = cli("explore", "--world", "maze", "--slam", "graph", "--duration", "20", "--seed", "2",
            "--out", str(out), timeout=240)  # fmt: skip
    assert r.returncode == 0, r.stderr
    (line,) = r.stdout.strip().splitlines()
    assert line.startswith("explore maze / mybot / graph (seed 2): time limit; explored ")
    assert re.search(r"\d+\.\d% of the reachable free area", line)
    assert re.search(r"0 contact\(s\)", line) and "20 s sim" in line
    for name in ("map.yaml", "map.pgm", "map.png", "coverage.png", "summary.json"):
        assert (out / name).stat().st_size > 0, name
    summary = json.loads((out / "summary.json").read_text())
    assert summary["reason"] == "time limit" and summary["seed"] == 2
    assert 0.0 < summary["coverage"] < 1.0 and summary["time_to_95_s"] is None
    assert "image: map.pgm" in (out / "map.yaml").read_text()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--slam", "karto"], "error: unknown --slam 'karto' (one of gmapping, hector, graph)"),
        (["--duration", "-3"], "error: --duration must be a positive number of seconds"),
        (["--rate", "fast"], "error: --rate must be a positive number or 'max'"),
        (["--world", "nowhere"], "error: unknown world 'nowhere'"),
        (["--robot", "nobot"], "error: unknown robot 'nobot'"),
    ],
)
def test_bad_arguments_are_one_error_line(
    cli: Any, tmp_path: Path, args: list[str], message: str
) -> None:
    r = cli("explore", *args, "--out", str(tmp_path / "o"), timeout=120)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(message), r.stderr
    assert not (tmp_path / "o").exists()


def test_an_out_path_that_is_a_file_is_refused_before_the_run(cli: Any, tmp_path: Path) -> None:
    target = tmp_path / "taken"
    target.write_text("x")
    r = cli("explore", "--out", str(target), timeout=60)
    assert r.returncode == 2
    assert r.stderr.strip() == f"error: --out {target}: not a folder"
    assert target.read_text() == "x"
