"""``note:`` lines fit a terminal line: bundled packages' files by package-relative path,
files below the working folder by relative path, one line per item."""

from __future__ import annotations

from pathlib import Path

import pytest

from roverlab.cli.common import report_notes
from roverlab.packages import BUNDLED_PACKAGES_DIR


def test_notes_name_files_short(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    xacro = BUNDLED_PACKAGES_DIR / "bingda_tutorials" / "urdf" / "mybot.xacro"
    report_notes([f"{xacro}: <gazebo reference> settings not simulated: mu1 on 3 links",
                  f"{tmp_path / 'worlds' / 'w.world'}: <physics> timing noted"])  # fmt: skip
    assert capsys.readouterr().err.splitlines() == [
        "note: bingda_tutorials/urdf/mybot.xacro: <gazebo reference> settings not simulated: "
        "mu1 on 3 links",
        "note: worlds/w.world: <physics> timing noted",
    ]
