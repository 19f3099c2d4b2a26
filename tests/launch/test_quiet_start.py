"""Seed 003's ``navigation_stack.launch`` following a simulator's ``/clock`` starts quietly.

The nodes of a launch without a simulator follow ``/clock`` from another process; the
simulator there has usually been running for a while. As with rospy's sim time, their timers
start from the first ``/clock``, so the first message is no jump of half a minute without a
laser scan; tf2_ros's MessageFilter says nothing of the few scans dropped while the TF
buffer fills (its first look is 15 s in, and only above 95% dropped), and the costmaps
wait quietly for their first robot pose, as Costmap2DROS does.

The simulator's launch (``simulation_robot.launch``) runs in the same context here, on the
same external clock, with ``/clock`` messages fed as Gazebo's would arrive: what the
navigation nodes see is what they see from another process, without the cost of two.
"""

from __future__ import annotations

import logging

import pytest

from roverlab.core import Context, Time
from roverlab.description import find_package
from roverlab.launch import build_launch
from roverlab.msgs import classes as mc

START_S = 30.0  # the simulator has been running for half a minute
RUN_S = 20.0
STEP_S = 0.01  # Gazebo's /clock period


def test_navigation_stack_prints_no_timeout_or_drop_warning_in_its_first_20_s(
    caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("BASE_TYPE", "NanoRobot")  # as seed 003's terminal has it
    ctx = Context(clock="external")
    try:
        sim = build_launch(
            find_package("bingda_tutorials") / "launch" / "simulation_robot.launch",
            context=ctx,
        )
        with caplog.at_level(logging.WARNING, logger="roverlab"):
            nav = build_launch(
                find_package("robot_navigation") / "launch" / "navigation_stack.launch",
                {"simulation": "true"},
                context=ctx,
            )
            names = {n.get_fully_qualified_name() for n in nav.nodes}
            assert {"/map_server", "/amcl", "/move_base"} <= names
            gazebo = ctx.create_node("gazebo_clock")
            clock = gazebo.create_publisher(mc.Clock, "/clock", 10)
            for k in range(round(RUN_S / STEP_S)):
                t = Time.from_seconds(START_S + k * STEP_S)
                clock.publish(mc.Clock(clock=t.to_msg()))
                ctx.executor.spin(wall_timeout_s=0.0)
        assert sim.nodes
        by_name = {n.get_name(): n for n in nav.nodes}
        assert by_name["amcl"].scan_filter.passed > 50  # localising on the simulator's scans
        assert by_name["move_base"].global_costmap.ready
    finally:
        ctx.shutdown()
    said = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    noisy = [
        s
        for s in said
        if "No laser scan" in s
        or "dropped" in s
        or "timeout" in s.lower()
        or "timed out" in s.lower()
        or "could not get robot pose" in s
    ]
    assert not noisy, noisy
    assert ctx.now().nanoseconds >= Time.from_seconds(START_S + RUN_S - 1).nanoseconds
