"""move_base live: seed 003's launch files (map_server + amcl + move_base) on mybot in the
simulated maze, goals through the action, as rviz and slam.py send them."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.actionlib import GoalStatus, SimpleActionClient
from roverlab.core import Context
from roverlab.description import find_package
from roverlab.launch import LaunchError, build_launch
from roverlab.navigation.move_base.node import MoveBase
from roverlab.sim.node import SimulatorNode

MOVE_BASE = "move_base_msgs/MoveBaseAction"
BUMPED = "This goal was canceled because another goal was received by the simple action server"


@dataclass
class Stack:
    ctx: Context
    sim: SimulatorNode
    move_base: MoveBase
    client: SimpleActionClient
    cmds: list[tuple[float, float]]
    feedback: list[Any]


def _goal(x: float, y: float, yaw: float = 0.0, frame: str = "map") -> dict[str, Any]:
    return {
        "target_pose": {
            "header": {"frame_id": frame},
            "pose": {
                "position": {"x": x, "y": y},
                "orientation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)},
            },
        }
    }


def _stack(monkeypatch: pytest.MonkeyPatch, **args: str) -> Stack:
    monkeypatch.setenv("BASE_TYPE", "NanoRobot")
    ctx = Context()
    sim = build_launch(
        find_package("bingda_tutorials") / "launch" / "simulation_robot.launch", context=ctx
    )
    nav = build_launch(
        find_package("robot_navigation") / "launch" / "navigation_stack.launch",
        {"simulation": "true", **args},
        context=ctx,
    )
    assert nav.warnings == [], nav.warnings
    (mb,) = [n for n in nav.nodes if isinstance(n, MoveBase)]
    assert sim.simulator is not None
    node = ctx.create_node("test_client")
    cmds: list[tuple[float, float]] = []
    node.create_subscription(
        "geometry_msgs/Twist", "/cmd_vel", lambda m: cmds.append((m.linear.x, m.angular.z)), 100
    )
    feedback: list[Any] = []
    client = SimpleActionClient(node, "move_base", MOVE_BASE)
    assert client.wait_for_server(10.0)
    return Stack(ctx, sim.simulator, mb, client, cmds, feedback)


@pytest.fixture
def stack(monkeypatch: pytest.MonkeyPatch) -> Iterator[Stack]:
    s = _stack(monkeypatch)
    yield s
    s.ctx.shutdown()


def _at(s: Stack, x: float, y: float, yaw: float, tol: float = 0.15) -> bool:
    return (
        math.hypot(s.sim.x - x, s.sim.y - y) < tol
        and abs(math.remainder(s.sim.yaw - yaw, 2 * math.pi)) < 0.25
    )


def test_goal_reached_with_feedback_plans_and_costmaps(stack: Stack) -> None:
    s = stack
    seen: dict[str, list[Any]] = {}
    spy = s.ctx.create_node("spy")
    for topic, typ in (
        ("/move_base/GlobalPlanner/plan", "nav_msgs/Path"),
        ("/move_base/DWAPlannerROS/local_plan", "nav_msgs/Path"),
        ("/move_base/global_costmap/costmap", "nav_msgs/OccupancyGrid"),
        ("/move_base/local_costmap/costmap", "nav_msgs/OccupancyGrid"),
        ("/move_base/local_costmap/footprint", "geometry_msgs/PolygonStamped"),
        ("/move_base/current_goal", "geometry_msgs/PoseStamped"),
    ):
        spy.create_subscription(typ, topic, lambda m, t=topic: seen.setdefault(t, []).append(m), 10)
    s.client.send_goal(_goal(2.0, 0.0, 0.0), feedback_cb=s.feedback.append)
    assert s.client.wait_for_result(120.0)
    assert s.client.get_state() == GoalStatus.SUCCEEDED
    assert s.client.get_goal_status_text() == "Goal reached."
    assert _at(s, 2.0, 0.0, 0.0)
    assert s.feedback and s.feedback[-1].base_position.header.frame_id == "map"
    assert len(seen) == 6, set(seen)
    plan = seen["/move_base/GlobalPlanner/plan"][0]
    assert plan.header.frame_id == "map" and len(plan.poses) > 20
    # every pose of the plan is off the walls and their inscribed inflation
    grid = s.move_base.global_costmap.costmap
    costs = [
        grid.get_cost(*grid.world_to_map(p.pose.position.x, p.pose.position.y)) for p in plan.poses
    ]
    assert max(costs) < 253
    assert s.cmds[-1] == (0.0, 0.0)  # stopped at the goal
    assert not s.sim.contact
    # the plan's footprint check looks at the static layer's map (the walls), which
    # covers the global costmap cell for cell
    static = s.move_base.global_costmap.layered.plugin("static_layer")
    assert s.move_base._walls(grid) is static.grid  # type: ignore[attr-defined]


def test_a_new_goal_preempts_the_current_one(stack: Stack) -> None:
    s = stack
    other = SimpleActionClient(s.ctx.create_node("other"), "move_base", MOVE_BASE)
    assert other.wait_for_server(5.0)
    ends: list[tuple[int, str]] = []
    s.client.send_goal(_goal(-2.0, -2.0, math.pi), done_cb=lambda st, r: ends.append((st, "first")))
    s.ctx.spin_for(3.0)
    other.send_goal(_goal(-0.5, -0.5, 0.0))
    assert other.wait_for_result(120.0) and other.get_state() == GoalStatus.SUCCEEDED
    assert ends == [(GoalStatus.PREEMPTED, "first")]
    assert s.client.get_goal_status_text() == BUMPED
    assert _at(s, -0.5, -0.5, 0.0)


def test_cancel_stops_the_robot(stack: Stack) -> None:
    s = stack
    s.client.send_goal(_goal(-2.0, 2.0, 1.57))
    s.ctx.spin_for(4.0)
    assert math.hypot(s.sim.x, s.sim.y) > 0.2  # under way
    s.client.cancel_goal()
    assert s.client.wait_for_result(5.0)
    assert s.client.get_state() == GoalStatus.PREEMPTED
    assert s.cmds[-1] == (0.0, 0.0)
    s.ctx.spin_for(2.0)
    assert abs(s.sim.v) < 0.01 and abs(s.sim.w) < 0.01


def test_bad_goals_are_aborted_with_a_clear_text(stack: Stack) -> None:
    s = stack
    cases = [
        (
            {"target_pose": {"header": {"frame_id": "map"}, "pose": {"orientation": {"w": 0.0}}}},
            "Aborting on goal because it was sent with an invalid quaternion",
        ),
        (_goal(1.0, 0.0, frame="no_such_frame"), "sent in frame 'no_such_frame'"),
        (_goal(20.0, 20.0), "outside the global costmap"),
    ]
    for g, needle in cases:
        s.client.send_goal(g)
        assert s.client.wait_for_result(10.0)
        assert s.client.get_state() == GoalStatus.ABORTED
        assert needle in s.client.get_goal_status_text()
        assert s.cmds and s.cmds[-1] == (0.0, 0.0)
    # move_base keeps serving
    s.client.send_goal(_goal(0.4, 0.0, 0.0))
    assert s.client.wait_for_result(60.0) and s.client.get_state() == GoalStatus.SUCCEEDED


def test_rviz_2d_nav_goal_make_plan_and_clear_costmaps(stack: Stack) -> None:
    s = stack
    node = s.ctx.create_node("rviz")
    pub = node.create_publisher("geometry_msgs/PoseStamped", "/move_base_simple/goal", 1)
    pub.publish(_pose_stamped(-0.5, 0.4, 0.0))
    s.ctx.wait_for(lambda: s.move_base.goals_succeeded == 1, 60.0)
    assert _at(s, -0.5, 0.4, 0.0)
    make_plan = node.create_client("nav_msgs/GetPlan", "/move_base/make_plan")
    req = make_plan.srv_type.Request(goal=_pose_stamped(2.0, 0.0, 0.0), tolerance=0.0)
    plan = make_plan.call(req).plan
    assert plan.header.frame_id == "map" and len(plan.poses) > 20
    end = plan.poses[-1].pose.position
    assert math.hypot(end.x - 2.0, end.y) < 0.05
    # a goal in the maze's middle wall, 0.5 m tolerance: the plan ends at a free place
    # near it, then the goal itself (make_plan_add_unreachable_goal, on by default)
    grid = s.move_base.global_costmap.costmap
    lethal = np.argwhere(grid.costs == 254)
    near = lethal[np.argmin(np.hypot(*(np.array(grid.world_to_map(0.7, 0.1))[::-1] - lethal).T))]
    wx, wy = grid.map_to_world(int(near[1]), int(near[0]))
    req = make_plan.srv_type.Request(goal=_pose_stamped(wx, wy, 0.0), tolerance=0.5)
    poses = [(p.pose.position.x, p.pose.position.y) for p in make_plan.call(req).plan.poses]
    assert len(poses) > 2 and poses[-1] == pytest.approx((wx, wy))
    assert grid.get_cost(*grid.world_to_map(*poses[-2])) < 253  # type: ignore[misc]
    clear = node.create_client("std_srvs/Empty", "/move_base/clear_costmaps")
    clear.call({})
    assert not (s.move_base.local_costmap.costmap.costs == 254).any()


def _pose_stamped(x: float, y: float, yaw: float) -> Any:
    from roverlab.msgs import PoseStamped, pose_from_xytheta

    return PoseStamped(header_frame_id="map", pose=pose_from_xytheta(x, y, yaw))


def test_goal_in_an_obstacle_ends_aborted_after_the_recoveries(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    s = _stack(monkeypatch)
    s.move_base.planner.params = _no_tolerance(s.move_base.planner.params)  # type: ignore[attr-defined]
    assert s.ctx.wait_for(lambda: s.move_base.global_costmap.ready, 5.0)
    grid = s.move_base.global_costmap.costmap
    lethal = np.argwhere(grid.costs == 254)  # (row, col)
    near = lethal[np.argmin(np.hypot(*(np.array(grid.world_to_map(0.7, 0.1))[::-1] - lethal).T))]
    wx, wy = grid.map_to_world(int(near[1]), int(near[0]))
    assert math.hypot(wx - 0.7, wy - 0.1) < 0.3  # the maze's middle wall
    try:
        s.client.send_goal(_goal(wx, wy))
        with caplog.at_level("INFO", logger="roverlab"):
            assert s.client.wait_for_result(200.0)
        assert s.client.get_state() == GoalStatus.ABORTED
        assert s.client.get_goal_status_text() == (
            "Failed to find a valid plan. Even after executing recovery behaviors."
        )
        assert s.cmds[-1] == (0.0, 0.0)
        ran = [r.getMessage() for r in caplog.records if "Executing recovery" in r.getMessage()]
        assert [m.rsplit(" ", 1)[1] for m in ran] == [
            "conservative_reset",
            "rotate_recovery",
            "aggressive_reset",
            "rotate_recovery",
        ]
    finally:
        s.ctx.shutdown()


def _no_tolerance(params: Any) -> Any:
    import dataclasses

    return dataclasses.replace(params, default_tolerance=0.0)


def test_unknown_planner_is_one_clear_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("BASE_TYPE", "NanoRobot")
    launch = tmp_path / "bad.launch"
    launch.write_text(
        '<launch><node pkg="move_base" type="move_base" name="move_base">'
        '<param name="base_local_planner" value="mpc_local_planner/MpcLocalPlannerROS"/>'
        "</node></launch>"
    )
    with pytest.raises(
        LaunchError, match=r"bad\.launch: .*move_base/move_base: .*base_local_planner"
    ):
        build_launch(launch, context=Context())


def test_a_seeded_run_is_reproducible(monkeypatch: pytest.MonkeyPatch) -> None:
    def run() -> tuple[float, float, float, float]:
        s = _stack(monkeypatch)
        try:
            s.client.send_goal(_goal(1.0, -0.9, -1.0))
            assert s.client.wait_for_result(60.0)
            assert s.client.get_state() == GoalStatus.SUCCEEDED, s.client.get_goal_status_text()
            assert _at(s, 1.0, -0.9, -1.0) and s.sim.contacts == 0
            return (s.sim.x, s.sim.y, s.sim.yaw, s.ctx.now().seconds)
        finally:
            s.ctx.shutdown()

    first = run()
    assert first == run() and first[3] > 1.0  # the same run, to the last bit


def test_teb_in_the_full_stack_reaches_goals_on_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """navigation_stack.launch planner:=teb: TebLocalPlannerROS under move_base with amcl,
    two goals across the maze (long bands through corridors), every control cycle timed."""
    s = _stack(monkeypatch, planner="teb")
    try:
        assert s.move_base.params.base_local_planner == "teb_local_planner/TebLocalPlannerROS"
        cpu: list[float] = []
        errors: list[str] = []

        def hook(kind: str, _wall: float, cpu_s: float, error: str | None) -> None:
            if kind == "control":
                cpu.append(cpu_s)
                if error is not None:
                    errors.append(error)

        s.move_base.timing_hook = hook
        seen: list[Any] = []
        s.ctx.create_node("spy").create_subscription(
            "nav_msgs/Path", "/move_base/TebLocalPlannerROS/local_plan", seen.append, 10
        )
        for x, y, yaw in ((2.0, 0.0, 0.0), (-1.9, 0.6, math.pi)):
            s.client.send_goal(_goal(x, y, yaw))
            assert s.client.wait_for_result(150.0)
            assert s.client.get_state() == GoalStatus.SUCCEEDED, s.client.get_goal_status_text()
            assert _at(s, x, y, yaw, tol=0.2)
        assert seen and s.sim.contacts == 0
        assert len(cpu) > 100 and len(errors) <= len(cpu) // 20
        # the band stays short: no control cycle near a second (it was seconds before the
        # banded solver); the 25 ms target is measured by `roverlab nav bench`. The first
        # cycle compiles TEB's kernels when no earlier test in this process did (10 s cold).
        assert max(cpu[1:]) < 0.5, max(cpu[1:])
    finally:
        s.ctx.shutdown()
