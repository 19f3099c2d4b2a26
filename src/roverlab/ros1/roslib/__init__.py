"""roslib for ROS 1 scripts: ``load_manifest`` (nothing to load without catkin) and the
message / package lookups scripts use."""

from __future__ import annotations

from roverlab.ros1.roslib import message, packages

__all__ = ["load_manifest", "message", "packages"]


def load_manifest(package_name: str, bootstrap_version: str = "0.7") -> None:
    """Nothing to do: roverlab's imports need no manifest (kept for old scripts)."""
    return None
