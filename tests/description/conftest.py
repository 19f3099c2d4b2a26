"""Fixtures of the description tests: bundled robot paths, tmp ROS packages, clean env."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from roverlab.packages import BUNDLED_PACKAGES_DIR

MYBOT_URDF = BUNDLED_PACKAGES_DIR / "bingda_tutorials" / "urdf" / "mybot.urdf"
MYBOT_XACRO = BUNDLED_PACKAGES_DIR / "bingda_tutorials" / "urdf" / "mybot.xacro"
MBOT_XACRO = BUNDLED_PACKAGES_DIR / "mbot_description" / "urdf" / "mbot_with_laser_gazebo.xacro"
MBOT_SEED_XACRO = (
    BUNDLED_PACKAGES_DIR
    / "mbot_description"
    / "urdf"
    / "xacro"
    / "gazebo"
    / "mbot_with_laser_gazebo.xacro"
)
MYCAR_XACRO = BUNDLED_PACKAGES_DIR / "mycar" / "urdf" / "xacro" / "car.urdf.xacro"


@pytest.fixture(autouse=True)
def _no_package_env(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Tests see only the bundled packages unless they set the variables themselves."""
    monkeypatch.delenv("ROVERLAB_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    yield


MakePackage = Callable[..., Path]


@pytest.fixture
def make_package(tmp_path: Path) -> MakePackage:
    """``make_package(name, {relpath: text}, root=..., folder=...)`` -> package folder."""

    def make(
        name: str,
        files: dict[str, str] | None = None,
        *,
        root: Path | None = None,
        folder: str | None = None,
    ) -> Path:
        pkg = (root or tmp_path / "ws") / (folder or name)
        pkg.mkdir(parents=True, exist_ok=True)
        (pkg / "package.xml").write_text(
            f'<?xml version="1.0"?>\n<package format="2"><name>{name}</name>'
            "<version>0.0.1</version></package>\n"
        )
        for rel, text in (files or {}).items():
            f = pkg / rel
            f.parent.mkdir(parents=True, exist_ok=True)
            f.write_text(text)
        return pkg

    return make


def robot(body: str, name: str = "r") -> str:
    """A URDF document around ``body``."""
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n{body}\n</robot>\n'


def xrobot(body: str, name: str = "r") -> str:
    """A xacro document around ``body``."""
    return (
        f'<?xml version="1.0"?>\n<robot name="{name}" '
        f'xmlns:xacro="http://www.ros.org/wiki/xacro">\n{body}\n</robot>\n'
    )
