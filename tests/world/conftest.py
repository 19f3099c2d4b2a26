"""World tests never see the developer's Gazebo model folders."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(autouse=True)
def _isolated_model_path(
    monkeypatch: pytest.MonkeyPatch, tmp_path_factory: pytest.TempPathFactory
) -> None:
    monkeypatch.delenv("ROVERLAB_MODEL_PATH", raising=False)
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    home: Path = tmp_path_factory.getbasetemp() / "empty_home"
    home.mkdir(exist_ok=True)
    monkeypatch.setenv("HOME", str(home))
