"""Shared ray casting: one compiled kernel set for lidar, camera, depth and map sensors."""

from roverlab.raycast.scene import Scene

__all__ = ["Scene"]
