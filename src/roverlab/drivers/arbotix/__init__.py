"""``arbotix_python``: the ArbotiX driver's differential-drive controller.

:class:`DiffController` is ``diff_controller`` on a fake base (``sim: true``): the
controller's loop as on the real board (set-points in ticks per 1/30 s frame, the
acceleration ramp, the command timeout) driving ideal motors whose encoder counts feed
the controller's odometry. :mod:`roverlab.drivers.arbotix.node` is the ROS node.
"""

from __future__ import annotations

from roverlab.drivers.arbotix.diff_controller import (
    DiffController,
    DiffControllerParams,
    parse_controllers,
)

__all__ = ["DiffController", "DiffControllerParams", "parse_controllers"]
