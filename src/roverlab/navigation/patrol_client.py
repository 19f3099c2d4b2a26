"""The patrol's runner: seed 002's slam.py loop over the move_base action (node side).

:class:`Patroller` sends the places of a :class:`~roverlab.navigation.patrol.PatrolSequence`
one after the other, waits for each result (with the per-goal timeout and a cancel), and
logs slam.py's lines through a callback. Its waits follow the node's clock and spin the
executor themselves when nothing else does, so the same code serves ``roverlab patrol``
(a CLI joined to another process's clock) and ``roverlab demo`` (one process).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Any

import numpy as np

from roverlab.actionlib import GoalStatus, SimpleActionClient, SimpleGoalState, status_name
from roverlab.core import Node
from roverlab.core.errors import GraphError
from roverlab.msgs import pose_from_xytheta
from roverlab.navigation.patrol import PatrolSequence, PatrolStats, Place

__all__ = ["Patroller"]


class Patroller:
    """Patrol ``places`` through ``action`` (move_base) from ``node``.

    Args:
        node: the node that owns the action client.
        places: the places; ``frame``: their frame.
        rng: the random order's source.
        rest_time: seconds to rest at each place.
        timeout: seconds per goal before it is canceled.
        log: called with each of slam.py's lines.
        action: the move_base action's name.
    """

    def __init__(
        self,
        node: Node,
        places: list[Place],
        frame: str,
        *,
        rng: np.random.Generator,
        rest_time: float = 2.0,
        timeout: float = 300.0,
        log: Callable[[str], Any],
        action: str = "move_base",
    ) -> None:
        self.node = node
        self.context = node.context
        self.frame = frame
        self.sequence = PatrolSequence(places, rng)
        self.rest_time = rest_time
        self.timeout = timeout
        self.log = log
        self.action = action
        self.client = SimpleActionClient(node, action, "move_base_msgs/MoveBaseAction")
        self.stats = PatrolStats()
        self.stop = threading.Event()

    def _done(self) -> bool:
        return self.client.simple_state == SimpleGoalState.DONE

    def wait_for_server(self, timeout_s: float = 60.0) -> None:
        """slam.py's start: wait for move_base (GraphError when it does not come)."""
        self.log("Waiting for move_base action server...")
        ready = self.client.action_client.server_is_ready
        self.context.wait_for(lambda: ready() or self.stop.is_set(), timeout_s)
        if not ready() and not self.stop.is_set():
            raise GraphError(
                f"no '{self.action}' action server within {timeout_s:g} s (is move_base running?)"
            )
        self.log("Connected to move base server")

    def run(self, goals: int) -> PatrolStats:
        """Patrol ``goals`` places (0: until :attr:`stop` is set); the statistics."""
        self.log("Starting navigation test")
        start = self.context.executor.clock_now_ns() / 1e9
        prev = (0.0, 0.0)  # slam.py measures its first leg from the origin
        stats = self.stats
        while not self.stop.is_set() and (goals == 0 or stats.goals < goals):
            place = self.sequence.next()
            distance = math.hypot(place.x - prev[0], place.y - prev[1])
            prev = (place.x, place.y)
            stats.goals += 1
            self.log(f"Going to: {place.name}")
            q = pose_from_xytheta(place.x, place.y, place.yaw).orientation
            self.client.send_goal(
                {
                    "target_pose": {
                        "header": {"frame_id": self.frame},
                        "pose": {
                            "position": {"x": place.x, "y": place.y},
                            "orientation": {"x": q.x, "y": q.y, "z": q.z, "w": q.w},
                        },
                    }
                }
            )
            self.context.wait_for(lambda: self._done() or self.stop.is_set(), self.timeout or None)
            if self.stop.is_set():
                break
            if not self._done():
                self.client.cancel_goal()
                self.log("Timed out achieving goal")
            else:
                state = self.client.get_state()
                if state == GoalStatus.SUCCEEDED:
                    self.log("Goal succeeded!")
                    stats.successes += 1
                    stats.distance_m += distance
                    self.log(f"State:{state}")
                else:
                    self.log(f"Goal failed with error code: {status_name(state)}")
            running = self.context.executor.clock_now_ns() / 1e9 - start
            self.log(stats.success_line())
            self.log(stats.time_line(running))
            more = goals == 0 or stats.goals < goals
            if self.rest_time > 0 and more and not self.stop.is_set():
                self.context.wait_for(self.stop.is_set, self.rest_time)
        return stats

    def shutdown(self, publish_zero: Callable[[], Any]) -> None:
        """Cancel the goal and stop the robot (slam.py's shutdown hook)."""
        if self.stop.is_set():
            self.log("Stopping the robot...")
        self.client.cancel_goal()
        publish_zero()
