"""Atomic writes: whole files or none, with the permissions a plain open() gives."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from roverlab.fileio import atomic_write, atomic_write_text


def test_new_file_gets_the_umask_mode_and_a_replaced_file_keeps_its_own(tmp_path: Path) -> None:
    old = os.umask(0o027)
    try:
        p = tmp_path / "calib.yaml"
        atomic_write_text(p, "a: 1\n")
        assert p.read_text() == "a: 1\n"
        assert p.stat().st_mode & 0o777 == 0o640  # 0o666 & ~0o027, not mkstemp's 0o600
        os.chmod(p, 0o604)
        atomic_write_text(p, "a: 2\n")
        assert p.read_text() == "a: 2\n" and p.stat().st_mode & 0o777 == 0o604
    finally:
        os.umask(old)


def test_a_failed_write_leaves_the_target_and_no_temporary_file(tmp_path: Path) -> None:
    p = tmp_path / "map.png"
    p.write_bytes(b"old")

    def boom(fh: object) -> None:
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        atomic_write(p, boom)
    assert p.read_bytes() == b"old"
    assert [q.name for q in tmp_path.iterdir()] == ["map.png"]
