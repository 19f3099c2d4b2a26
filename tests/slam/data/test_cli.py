"""``roverlab slam``: eval, graph, odometry through the root command."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from roverlab.cli.slam import app, main
from roverlab.geometry import SE2
from roverlab.slam.data import read_g2o, read_tum, write_tum

RUNNER = CliRunner()

RELATIONS = "1.000000 2.000000 1.0 0.0 0 0 0 0.0\n2.000000 3.000000 1.0 0.0 0 0 0 0.1\n"


def test_eval_prints_the_metric(tmp_path: Path) -> None:
    traj = tmp_path / "t.tum"
    write_tum(traj, ["1.000000", "2.000000", "3.000000"], [SE2(), SE2(1.0, 0, 0), SE2(2.5, 0, 0)])
    rel = tmp_path / "r.relations"
    rel.write_text(RELATIONS)
    result = RUNNER.invoke(app, ["eval", str(traj), str(rel)])
    assert result.exit_code == 0, result.output
    assert result.output.splitlines() == [
        "translational error: 0.2500 +- 0.2500 m",
        "rotational error: 2.86 +- 2.86 deg",
        "relations matched: 2 / 2",
    ]


def test_graph_optimises_and_writes(tmp_path: Path) -> None:
    g2o = tmp_path / "g.g2o"
    g2o.write_text(
        "EDGE_SE2 0 1 1.0 0.0 1.5707963267948966 10 0 0 10 0 100\n"
        "EDGE_SE2 1 2 1.0 0.0 1.5707963267948966 10 0 0 10 0 100\n"
        "EDGE_SE2 2 3 1.0 0.0 1.5707963267948966 10 0 0 10 0 100\n"
        "EDGE_SE2 3 0 1.1 0.0 1.5707963267948966 10 0 0 10 0 100\n"
    )
    out = tmp_path / "opt.g2o"
    result = RUNNER.invoke(app, ["graph", str(g2o), "--out", str(out)])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0].startswith("graph: 4 vertices, 4 edges")
    assert "start: chained odometry edges" in lines[0]
    assert lines[1] == "initial chi2: 0.1000"
    final = float(lines[2].removeprefix("final chi2: "))
    assert 0.0 < final < 0.1
    assert lines[-2].startswith("time: ") and lines[-1] == f"wrote {out}"
    assert read_g2o(out).vertices_given


def test_odometry_command_writes_tum(tmp_path: Path) -> None:
    log = tmp_path / "log.clf"
    log.write_text("FLASER 2 1.0 1.0 0.5 0.0 0.1 0.5 0.0 0.1 976052857.337530 host 0.1\n")
    out = tmp_path / "odom.tum"
    result = RUNNER.invoke(app, ["odometry", str(log), "--out", str(out)])
    assert result.exit_code == 0, result.output
    traj = read_tum(out)
    assert traj.timestamp_texts == ("976052857.337530",)
    assert traj.poses[0].tolist() == pytest.approx([0.5, 0.0, 0.1])


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["eval", "absent.tum", "absent.relations"], "error: absent.tum: cannot read"),
        (["graph", "absent.g2o"], "error: absent.g2o: cannot read"),
        (["graph", "{g2o}", "--init", "magic"], "error: unknown initialisation 'magic'"),
        (["odometry", "absent.clf", "-o", "x.tum"], "error: absent.clf: no such file"),
        (["odometry", "{g2o}", "-o", "x.tum", "--frame", "map"], "error: unknown --frame 'map'"),
    ],
)
def test_user_errors_are_one_line_and_exit_2(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    args: list[str],
    message: str,
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "g.g2o").write_text("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n")
    with pytest.raises(SystemExit) as exc:
        main([a.replace("{g2o}", "g.g2o") for a in args])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(message), err
    assert err.count("\n") == 1


def test_roverlab_slam_through_the_root_command() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "--help"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0
    assert "roverlab slam" in done.stdout and "graph" in done.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "eval", "nope.tum", "nope.relations"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert bad.returncode == 2
    assert bad.stderr.startswith("error: nope.tum: cannot read")
