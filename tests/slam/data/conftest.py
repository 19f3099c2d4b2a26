"""Fixtures of the SLAM data tests: the shared benchmark data, skipped when absent."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from roverlab.slam.data import LaserLog, load_log

#: ``../shared/data`` relative to the repository root; never copied into the repository.
DATA = Path(__file__).resolve().parents[3].parent / "shared" / "data"


def _data_dir(name: str) -> Path:
    path = DATA / name
    if not path.is_dir():
        pytest.skip(f"shared benchmark data not found at {path} (see shared/data/README.md)")
    return path


@pytest.fixture(scope="session")
def radish() -> Path:
    """The Radish CARMEN logs and their relations."""
    return _data_dir("radish")


@pytest.fixture(scope="session")
def posegraphs() -> Path:
    """The g2o pose-graph benchmark problems."""
    return _data_dir("posegraphs")


_LOGS: dict[str, LaserLog] = {}


@pytest.fixture(scope="session")
def radish_log(radish: Path) -> Callable[[str], LaserLog]:
    """``radish_log("intel")``: the log, loaded once per test session."""

    def get(name: str) -> LaserLog:
        if name not in _LOGS:
            _LOGS[name] = load_log(radish / f"{name}.clf.bz2")
        return _LOGS[name]

    return get
