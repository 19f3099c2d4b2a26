"""rviz in the browser: the web dashboard.

* :mod:`.protocol` -- pure: the websocket's binary frames (map, scan, JPEG) and the
  top-view outline of a URDF's visuals;
* :mod:`.bridge` -- :class:`VizBridge`, the node: subscriptions (``/map``, ``/scan``,
  ``/odom``, ``/robot_description``, TF, images) and the tools' publishers
  (``/initialpose``, ``/move_base_simple/goal``, ``/clicked_point``, ``/cmd_vel``);
* :mod:`.server` -- :class:`DashboardServer` (FastAPI + uvicorn in a thread, one static
  page under ``static/``);
* :mod:`.cli` -- the ``roverlab dashboard`` command (import it on its own; needs typer).

Example::

    ctx = Context(clock="paced")
    sim = Simulation(context=ctx, world="maze", robot="mybot")
    server = DashboardServer(ctx, "127.0.0.1", 8080)
    ctx.spin_in_thread()
    server.start()          # open http://127.0.0.1:8080/
"""

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from roverlab.viz.bridge import VizBridge
    from roverlab.viz.errors import DashboardError
    from roverlab.viz.protocol import INITIALPOSE_COVARIANCE
    from roverlab.viz.server import DashboardServer, is_loopback

__all__ = [
    "INITIALPOSE_COVARIANCE",
    "DashboardError",
    "DashboardServer",
    "VizBridge",
    "is_loopback",
]

# Imported on first use: ``roverlab.viz.errors`` or ``.launcher`` must not load FastAPI
# and uvicorn (about a second) into every process that only might serve a dashboard.
_HOMES = {
    "INITIALPOSE_COVARIANCE": "roverlab.viz.protocol",
    "DashboardError": "roverlab.viz.errors",
    "DashboardServer": "roverlab.viz.server",
    "VizBridge": "roverlab.viz.bridge",
    "is_loopback": "roverlab.viz.server",
}


def __getattr__(name: str) -> Any:
    if name in _HOMES:
        return getattr(importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module 'roverlab.viz' has no attribute {name!r}")
