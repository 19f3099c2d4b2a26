"""The child's side of the multi-process test helpers (``node_proc.py``, ``nav_stack.py``,
``fake_move_base.py``, run as scripts: they import this module from their own folder)."""

from __future__ import annotations

from typing import Any

from roverlab.core.transport.daemon import connect_context
from roverlab.msgs import Twist

__all__ = ["echo_cmd_vel", "serve_ready"]


def echo_cmd_vel(node: Any) -> None:
    """Print every ``/cmd_vel`` a child node hears as ``cmd_vel <linear.x> <angular.z>``."""

    def show(msg: Any) -> None:
        print(f"cmd_vel {msg.linear.x:.3f} {msg.angular.z:.3f}", flush=True)

    node.create_subscription(Twist, "/cmd_vel", show, 10)


def serve_ready(ctx: Any) -> None:
    """A child process's main loop: join the daemon, print READY, spin until Ctrl-C."""
    connect_context(ctx)
    print("READY", flush=True)
    try:
        ctx.spin()
    except KeyboardInterrupt:
        pass
    finally:
        ctx.shutdown()
