"""Seed 000's mbot with mbot_navigation's launch files: move_base on the saved map (amcl,
pre-hydro costmap parameters), and move_base in the map gmapping is still building
(seed 002's setup: unknown space allowed)."""

from __future__ import annotations

import math

import pytest

from roverlab.actionlib import GoalStatus, SimpleActionClient
from roverlab.core import Context
from roverlab.description import find_package
from roverlab.launch import build_launch


def _run(launch: str, goals: list[tuple[float, float]], **args: str) -> list[tuple[int, float]]:
    ctx = Context()
    sim = build_launch(
        find_package("mbot_description") / "launch" / "mbot_laser_nav_gazebo.launch", context=ctx
    ).simulator
    nav = build_launch(
        find_package("mbot_navigation") / "launch" / launch, {"rviz": "false", **args}, context=ctx
    )
    assert sim is not None and nav.warnings == [], nav.warnings
    client = SimpleActionClient(
        ctx.create_node("client"), "move_base", "move_base_msgs/MoveBaseAction"
    )
    assert client.wait_for_server(10.0)
    out = []
    try:
        for gx, gy in goals:
            pose = {"position": {"x": gx, "y": gy}, "orientation": {"w": 1.0}}
            client.send_goal({"target_pose": {"header": {"frame_id": "map"}, "pose": pose}})
            assert client.wait_for_result(240.0)
            out.append((client.get_state(), math.hypot(sim.x - gx, sim.y - gy)))
            assert not sim.contact
    finally:
        ctx.shutdown()
    return out


def test_exploring_slam_demo_navigates_in_the_map_being_built() -> None:
    # the second goal lies behind walls gmapping has not seen from the start
    results = _run("exploring_slam_demo.launch", [(3.0, 2.0), (-3.5, -2.5)])
    assert all(st == GoalStatus.SUCCEEDED and d < 0.25 for st, d in results), results


@pytest.mark.slow
@pytest.mark.parametrize("planner", ["dwa", "base"])
def test_nav_demo_on_the_saved_map(planner: str) -> None:
    results = _run("nav_demo.launch", [(3.0, 2.0), (-3.5, -2.5), (3.5, -3.0)], planner=planner)
    assert all(st == GoalStatus.SUCCEEDED and d < 0.25 for st, d in results), results
