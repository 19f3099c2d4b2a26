"""Never wedged, live (issue 28): move_base + the simulator, a Jackal-sized robot on
odometry alone with BARN's TrajectoryPlannerROS parameters (footprint padded by 0.1 m).
The robot starts stopped with a pillar just ahead, inside its padded footprint's
circumscribed radius (its body 11 cm clear): it can neither turn in place nor take any
sample with the padded footprint. A first goal on a wall is
ABORTED (no plan, recoveries off); the next goal, from that same wedged pose, must drive
and be reached: a goal never ends with 0 m driven while a way out exists."""

from __future__ import annotations

import math
from pathlib import Path

from roverlab.actionlib import GoalStatus, SimpleActionClient
from roverlab.core import Context
from roverlab.launch import build_launch
from roverlab.navigation.move_base.node import MoveBase
from roverlab.navigation.move_base.recovery import RotateRecovery
from roverlab.sim.app import Simulation
from roverlab.sim.node import SpawnPose
from roverlab.world import load_world
from tests.helpers.barn_layout import write_barn_layout

#: ahead and to the left: its surface 0.325 m ahead (the body ends at 0.21, the padded
#: footprint at 0.31), within the padded footprint's circumscribed radius (0.41 m)
PILLAR = (0.40, 0.20)
# BARN's base_local_planner_params.yaml (TrajectoryPlannerROS, dwa: true)
_PLANNER = """\
TrajectoryPlannerROS: {acc_lim_x: 10.0, acc_lim_theta: 20.0, max_vel_x: 0.5, min_vel_x: 0.1,
  max_vel_theta: 1.57, min_in_place_vel_theta: 0.314, holonomic_robot: false,
  escape_vel: -0.5, yaw_goal_tolerance: 0.157, xy_goal_tolerance: 0.25, sim_time: 2.0,
  sim_granularity: 0.02, angular_sim_granularity: 0.02, vx_samples: 6, vtheta_samples: 20,
  controller_frequency: 20.0, meter_scoring: true, occdist_scale: 0.1, pdist_scale: 0.75,
  gdist_scale: 1.0, dwa: true, oscillation_reset_dist: 0.05, escape_reset_dist: 0.1,
  escape_reset_theta: 0.1}
"""
_LAUNCH = """\
<launch>
  <param name="/use_sim_time" value="true"/>
  <node pkg="move_base" type="move_base" name="move_base">
    <rosparam file="{d}/costmap_common_params.yaml" command="load" ns="global_costmap"/>
    <rosparam file="{d}/costmap_common_params.yaml" command="load" ns="local_costmap"/>
    <rosparam file="{d}/global_costmap_params.yaml" command="load"/>
    <rosparam file="{d}/local_costmap_params.yaml" command="load"/>
    <rosparam file="{d}/base_local_planner_params.yaml" command="load"/>
    <param name="base_global_planner" value="navfn/NavfnROS"/>
    <param name="base_local_planner" value="base_local_planner/TrajectoryPlannerROS"/>
    <param name="planner_patience" value="1.0"/>
    <param name="recovery_behavior_enabled" value="false"/>
    <remap from="odom" to="{odom}"/>
    <remap from="cmd_vel" to="{cmd}"/>
  </node>
</launch>
"""


def _goal(x: float, y: float) -> dict[str, object]:
    pose = {"position": {"x": x, "y": y}, "orientation": {"w": 1.0}}
    return {"target_pose": {"header": {"frame_id": "odom"}, "pose": pose}}


def test_after_an_abort_a_wedged_robot_gets_out_and_reaches_the_next_goal(
    tmp_path: Path,
) -> None:
    write_barn_layout(tmp_path, _PLANNER, padding=0.1, global_hz=10, global_size_m=8.0, local_hz=20)
    world = tmp_path / "pillar.yaml"
    world.write_text(
        "name: pillar\nwalls:\n- points: [[-1.5, -1.5], [3.5, -1.5], [3.5, 1.5], [-1.5, 1.5]]\n"
        f"  closed: true\ncylinders:\n- {{center: [{PILLAR[0]}, {PILLAR[1]}], radius: 0.075, "
        "height: 0.5}\n"
    )
    ctx = Context()
    try:
        sim = Simulation(
            ctx, world=load_world(str(world)), robot="jackal", spawn=SpawnPose(0.0, 0.0, 0.0),
            seed=0, cameras=False,
        )  # fmt: skip
        drive = sim.config.drive
        assert drive is not None
        cmd_topic, odom_topic = drive.command_topic, drive.odometry_topic
        launch = tmp_path / "move_base.launch"
        launch.write_text(_LAUNCH.format(d=tmp_path, odom=odom_topic, cmd=cmd_topic))
        built = build_launch(launch, {}, context=ctx, seed=0)
        (mb,) = [n for n in built.nodes if isinstance(n, MoveBase)]
        s = sim.simulator
        node = ctx.create_node("client")
        client = SimpleActionClient(node, "move_base", "move_base_msgs/MoveBaseAction")
        assert client.wait_for_server(10.0)
        assert ctx.wait_for(lambda: mb.local_costmap.get_robot_pose() is not None, 30.0)
        ctx.spin_for(0.5)  # a few scans into the costmaps
        # wedged: ROS's rotate_recovery cannot turn (the padded corner sweeps the pillar)
        # and the pillar is too close ahead for any forward sample with the padding
        pose = mb.local_costmap.get_robot_pose()
        assert pose is not None
        rot = RotateRecovery("rotate_recovery", footprint=mb.local_costmap.footprint)
        rot.start(pose)
        assert rot.step(pose, mb.local_costmap.costmap) is None and rot.blocked
        # 1. a goal on the wall: no plan, recoveries off -> ABORTED, the robot still wedged
        client.send_goal(_goal(1.0, 1.5))
        assert client.wait_for_result(30.0)
        assert client.get_state() == GoalStatus.ABORTED, client.get_goal_status_text()
        assert math.hypot(s.x, s.y) < 0.05
        # 2. the next goal, behind the pillar, from there: driven and reached, no contact
        client.send_goal(_goal(2.5, 0.0))
        assert client.wait_for_result(60.0)
        assert client.get_state() == GoalStatus.SUCCEEDED, client.get_goal_status_text()
        end = mb.local_costmap.get_robot_pose()  # odometry's (skid steer slips in turns)
        assert end is not None and math.hypot(end.x - 2.5, end.y) < 0.3
        assert math.hypot(s.x, s.y) > 1.5 and s.contacts == 0
    finally:
        ctx.shutdown()
