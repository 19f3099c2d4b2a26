"""``roslib.packages.get_pkg_dir``: through roverlab's package path."""

from __future__ import annotations

from roverlab.description import find_package

__all__ = ["get_pkg_dir"]


def get_pkg_dir(package: str, required: bool = True, ros_root: str | None = None) -> str:
    return str(find_package(package))
