"""explore_lite live: mybot maps seed 003's maze on its own (slam_gmapping + move_base +
explore, robot_navigation's explore.launch) and stops when no frontier is left."""

from __future__ import annotations

import numpy as np
import pytest

from roverlab.core import Context
from roverlab.description import find_package
from roverlab.launch import build_launch
from roverlab.maps import load_map
from roverlab.navigation.explore.node import Explore


def test_the_maze_is_explored_and_exploration_stops(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("BASE_TYPE", "NanoRobot")
    ctx = Context()
    sim = build_launch(
        find_package("bingda_tutorials") / "launch" / "simulation_robot.launch", context=ctx
    ).simulator
    nav = build_launch(
        find_package("robot_navigation") / "launch" / "explore.launch",
        {"simulation": "true"},
        context=ctx,
    )
    (explore,) = [n for n in nav.nodes if isinstance(n, Explore)]
    (gmapping,) = [n for n in nav.nodes if n.get_name() == "slam_gmapping"]
    markers: list = []
    ctx.create_node("spy").create_subscription(
        "visualization_msgs/MarkerArray", "/explore/frontiers", markers.append, 10
    )
    assert sim is not None
    try:
        assert ctx.wait_for(lambda: not explore.exploring, 600.0), "still exploring"
        assert explore.goals_sent >= 3 and not sim.contact
        reference = load_map(find_package("robot_navigation") / "maps" / "mazemap.yaml")
        reachable_m2 = np.count_nonzero(np.asarray(reference.data) == 0) * 0.0025
        m = gmapping.map_msg
        free_m2 = np.count_nonzero(np.asarray(m.data) == 0) * float(m.info.resolution) ** 2
        assert free_m2 >= 0.95 * reachable_m2, (free_m2, reachable_m2)
        assert markers and any(len(a.markers) for a in markers)  # frontiers were shown
        assert ctx.now().seconds < 600.0
    finally:
        ctx.shutdown()
