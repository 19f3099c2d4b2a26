"""move_base's CLEARING state: the recovery behaviours run in order, one per entry into
the state (move_base.cpp's ``recovery_index_``), each to its end before planning again.

Held by :class:`~roverlab.navigation.move_base.node.MoveBase` (the node's file holds the
action and the planning and control states). Behaviours that move the robot are
stepped once a control cycle; a rotate_recovery that cannot turn in place hands over to
backing up (the robot's real footprint checked), since a robot wedged with an obstacle
inside its padded footprint can neither turn nor be freed by clearing the costmaps.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from roverlab.geometry import SE2
from roverlab.msgs import Twist
from roverlab.navigation.controllers import Velocity2D
from roverlab.navigation.move_base.behaviors import BackUp, MoveSlowAndClear, Spin, Wait
from roverlab.navigation.move_base.recovery import ClearCostmapRecovery, RotateRecovery

if TYPE_CHECKING:
    from roverlab.navigation.move_base.node import MoveBase

__all__ = ["PLANNING", "Recovering"]

PLANNING = "PLANNING"
Stepper = RotateRecovery | BackUp | Spin | Wait


class Recovering:
    """The CLEARING state's steps of ``node`` (see the module docstring)."""

    def __init__(self, node: MoveBase, rotate_fallback: BackUp) -> None:
        self.node = node
        #: the moving recovery in progress
        self.running: Stepper | None = None
        #: backing up after a rotate_recovery that could not turn
        self._rotate_fallback = rotate_fallback
        #: a MoveSlowAndClear's speed cap in force
        self.speed_limit: MoveSlowAndClear | None = None

    def step_running(self, now: float) -> bool:
        """Step the moving recovery in progress; False once it is over."""
        running = self.running
        assert running is not None
        lpose = self.node.local_costmap.get_robot_pose()
        if lpose is None:
            return False
        cm = self.node.local_costmap.costmap
        cmd: Velocity2D | None
        if isinstance(running, RotateRecovery):
            speed = running.step(lpose, cm)
            cmd = None if speed is None else Velocity2D(0.0, 0.0, speed)
        else:
            cmd = running.step(lpose, cm, now)
        if cmd is not None:
            self.node.cmd_pub.publish(Twist(linear_x=cmd.vx, linear_y=cmd.vy, angular_z=cmd.wz))
            return True
        self.node.publish_zero_velocity()
        if running.blocked:
            self.node.get_logger().error(running.blocked)
            if isinstance(running, RotateRecovery):
                self.node.get_logger().info(
                    f"{running.name}: backing up {self._rotate_fallback.params.backup_dist:.2f}"
                    " m instead (the robot's footprint checked)"
                )
                self.start_running(self._rotate_fallback, lpose, now)
                return self.step_running(now)
        return False

    def start_running(self, rec: Stepper, pose: SE2, now: float) -> None:
        if isinstance(rec, RotateRecovery):
            rec.start(pose)
        else:
            rec.start(pose, now)
        self.running = rec

    def clear_step(self, now: float) -> None:
        if self.running is not None:
            if not self.step_running(now):
                self.recovery_done(now)
            return
        p = self.node.params
        if not (
            p.recovery_behavior_enabled and self.node.recovery_index < len(self.node.recoveries)
        ):
            self.node.get_logger().error(
                "All recovery behaviors have failed, locking the planner and disabling it."
            )
            self.node._abort(self.node.abort_text())
            return
        rec = self.node.recoveries[self.node.recovery_index]
        self.node.get_logger().info(f"Executing recovery behavior {rec.name}")
        if isinstance(rec, ClearCostmapRecovery | MoveSlowAndClear):
            self.clear_costmaps(rec)
            self.recovery_done(now)
            return
        lpose = self.node.local_costmap.get_robot_pose()
        if lpose is None:
            self.recovery_done(now)
            return
        self.start_running(rec, lpose, now)
        if not self.step_running(now):
            self.recovery_done(now)

    def clear_costmaps(self, rec: ClearCostmapRecovery | MoveSlowAndClear) -> None:
        clear = rec
        if isinstance(rec, MoveSlowAndClear):  # clears inside its window, then slows down
            clear = ClearCostmapRecovery(
                rec.name,
                reset_distance=2.0 * rec.params.clearing_distance,
                invert_area_to_clear=True,
            )
        assert isinstance(clear, ClearCostmapRecovery)
        cleared = clear.run(
            global_costmap=self.node.global_costmap.layered,
            global_pose=self.node.global_costmap.get_robot_pose(),
            local_costmap=self.node.local_costmap.layered,
            local_pose=self.node.local_costmap.get_robot_pose(),
        )
        where = "inside" if clear.invert_area_to_clear else "outside"
        self.node.get_logger().info(
            f"{rec.name}: cleared {', '.join(cleared) or 'nothing'} {where} a "
            f"{clear.reset_distance:.2f} m square around the robot"
        )
        if clear.force_updating:
            self.node.global_costmap.update_map()
            self.node.local_costmap.update_map()
        if isinstance(rec, MoveSlowAndClear):
            lpose = self.node.local_costmap.get_robot_pose()
            if lpose is not None:
                rec.engage(lpose)
                self.speed_limit = rec

    def clear_around_robot(self, radius: float) -> list[str]:
        """move_base's ``clearCostmapWindows``: forget the obstacle layers' marks within
        ``radius`` of the robot (a square), in both costmaps; the layers cleared."""
        clear = ClearCostmapRecovery(
            "make_plan", reset_distance=2.0 * radius, invert_area_to_clear=True
        )
        return clear.run(
            global_costmap=self.node.global_costmap.layered,
            global_pose=self.node.global_costmap.get_robot_pose(),
            local_costmap=self.node.local_costmap.layered,
            local_pose=self.node.local_costmap.get_robot_pose(),
        )

    def limited(self, cmd: Velocity2D, pose: SE2) -> Velocity2D:
        """``cmd`` under a MoveSlowAndClear's cap while it holds."""
        lim = self.speed_limit
        if lim is None:
            return cmd
        out = lim.limit(cmd, pose)
        if not lim.limiting:
            self.speed_limit = None
        return out

    def recovery_done(self, now: float) -> None:
        self.running = None
        self.node._last_oscillation_reset = now
        self.node._last_valid_plan = now
        self.node._planning_retries = 0
        self.node.state = PLANNING
        self.node.recovery_index += 1
