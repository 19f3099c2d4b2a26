"""The dashboard's tools, as rviz's tool bar and panels: 2D Nav Goal, 2D Pose Estimate,
Publish Point, the drive keys of teleop_twist_keyboard and map_saver's Save map.

:class:`ToolPanel` is a base class of :class:`~roverlab.viz.bridge.VizBridge`, which makes
the publishers and holds the displays; what each tool publishes or writes is here.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, Final

import numpy as np

from roverlab.core import Context
from roverlab.errors import RoverlabError
from roverlab.maps import save_map
from roverlab.msgs import (
    PointStamped,
    PoseStamped,
    PoseWithCovarianceStamped,
    occupancy_grid_to_array,
    pose_from_xytheta,
    stamp_to_msg,
    yaw_from_quaternion,
)
from roverlab.teleop import SPEED_BINDINGS, twist_for_key
from roverlab.teleop.node import command_to_twist
from roverlab.viz.errors import DashboardError
from roverlab.viz.handlers import DisplayState
from roverlab.viz.protocol import INITIALPOSE_COVARIANCE

__all__ = ["ToolPanel"]

_MAP_NAME: Final = re.compile(r"^[A-Za-z0-9_.-]{1,100}$")


class ToolPanel:
    """What the page's tools publish; the subclass provides the publishers below, the
    context, the fixed frame and the displays."""

    context: Context
    speed_mps: float
    turn_radps: float
    map_dir: Path
    displays: list[DisplayState]
    goal_pub: Any
    initialpose_pub: Any
    point_pub: Any
    cmd_vel_pub: Any

    @property
    def fixed_frame(self) -> str:
        raise NotImplementedError

    def _header(self) -> dict[str, Any]:
        return {"frame_id": self.fixed_frame, "stamp": stamp_to_msg(self.context.now())}

    def publish_goal(self, x: float, y: float, yaw: float) -> None:
        """2D Nav Goal: a PoseStamped in the fixed frame on ``/move_base_simple/goal``."""
        self.goal_pub.publish(PoseStamped(header=self._header(), pose=pose_from_xytheta(x, y, yaw)))

    def publish_initialpose(self, x: float, y: float, yaw: float) -> None:
        """2D Pose Estimate: ``/initialpose`` with rviz's default covariance."""
        msg = PoseWithCovarianceStamped(
            header=self._header(),
            pose={
                "pose": pose_from_xytheta(x, y, yaw),
                "covariance": np.array(INITIALPOSE_COVARIANCE, dtype=np.float64),
            },
        )
        self.initialpose_pub.publish(msg)

    def publish_point(self, x: float, y: float) -> None:
        """Publish Point: a PointStamped in the fixed frame on ``/clicked_point``."""
        self.point_pub.publish(
            PointStamped(header=self._header(), point={"x": float(x), "y": float(y)})
        )

    def drive_key(self, key: str) -> bool:
        """A teleop key: ``i j l , k u o m .`` (and the holonomic capitals) publish their
        Twist on ``/cmd_vel``; ``q z w x e c`` scale the speeds by 10 % as
        teleop_twist_keyboard does. False if the key means nothing."""
        if key in SPEED_BINDINGS:
            fs, ft = SPEED_BINDINGS[key]
            self.speed_mps *= fs
            self.turn_radps *= ft
            return True
        cmd = twist_for_key(key, self.speed_mps, self.turn_radps)
        if cmd is None:
            return False
        self.cmd_vel_pub.publish(command_to_twist(cmd))
        return True

    def set_speeds(self, speed_mps: float, turn_radps: float) -> None:
        """The drive panel's speed controls (``~speed`` and ``~turn``).

        Raises:
            DashboardError: a speed that is negative or not finite.
        """
        for name, v in (("speed", speed_mps), ("turn", turn_radps)):
            if not (math.isfinite(v) and v >= 0):
                raise DashboardError(f"{name} must be a finite number >= 0, got {v}")
        self.speed_mps, self.turn_radps = speed_mps, turn_radps

    def save_map(self, name: str = "map") -> Path:
        """map_saver of the newest map: ``map_dir/NAME.pgm`` + ``NAME.yaml``.

        The map comes from the first map display on ``/map`` (else the first map display
        with data).

        Raises:
            DashboardError: a bad name, no map received yet, or the files cannot be written.
        """
        if not _MAP_NAME.match(name) or name.startswith("."):
            raise DashboardError(f"bad map name {name!r}: use letters, digits, '_', '-', '.'")
        maps = [d for d in self.displays if d.kind == "map" and d.map_msg is not None]
        maps.sort(key=lambda d: d.config.topic != "/map")
        if not maps:
            raise DashboardError("no map received yet: nothing to save")
        msg = maps[0].map_msg
        o = msg.info.origin
        try:
            saved = save_map(
                self.map_dir / name,
                occupancy_grid_to_array(msg),
                resolution=float(msg.info.resolution),
                origin=(
                    float(o.position.x),
                    float(o.position.y),
                    yaw_from_quaternion(o.orientation),
                ),
            )
        except RoverlabError as err:
            raise DashboardError(f"cannot save the map: {err}") from err
        return saved.yaml_path
