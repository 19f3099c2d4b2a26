"""move_base's parameters, recovery list and plugins (pure)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.costmap import CostmapParams, make_layered_costmap
from roverlab.navigation.errors import NavigationParamsError
from roverlab.navigation.move_base import (
    ClearCostmapRecovery,
    MoveBaseParams,
    RecoverySpec,
    RotateRecovery,
    RotateRecoveryParams,
    default_recoveries,
)
from roverlab.navigation.move_base.plugins import (
    LocalPlannerLimits,
    make_global_planner,
    make_local_planner,
    make_recovery,
)


def test_defaults_are_move_base_s() -> None:
    p, warnings = MoveBaseParams.from_ros({})
    assert warnings == ()
    assert p.base_global_planner == "navfn/NavfnROS"
    assert p.base_local_planner == "base_local_planner/TrajectoryPlannerROS"
    assert (p.controller_frequency, p.planner_patience, p.controller_patience) == (20.0, 5.0, 15.0)
    assert (p.oscillation_timeout, p.oscillation_distance, p.planner_frequency) == (0.0, 0.5, 0.0)
    assert p.max_planning_retries == -1 and p.conservative_reset_dist == 3.0
    assert [r.name for r in p.recoveries] == [
        "conservative_reset",
        "rotate_recovery",
        "aggressive_reset",
        "rotate_recovery",
    ]
    no_rotation, _ = MoveBaseParams.from_ros({"clearing_rotation_allowed": False})
    assert [r.name for r in no_rotation.recoveries] == ["conservative_reset", "aggressive_reset"]
    assert default_recoveries(False) == no_rotation.recoveries


def test_launch_values_and_plugin_names() -> None:
    p, _ = MoveBaseParams.from_ros(
        {
            "base_global_planner": "global_planner/GlobalPlanner",
            "base_local_planner": "dwa_local_planner/DWAPlannerROS",
            "controller_frequency": "10",  # a launch file's <param value="10"/>
            "shutdown_costmaps": "true",
            "max_planning_retries": 3.0,
            "recovery_behaviors": [
                {"name": "reset", "type": "clear_costmap_recovery/ClearCostmapRecovery"},
                {"name": "spin", "type": "rotate_recovery/RotateRecovery"},
            ],
            "DWAPlannerROS/max_vel_x": 0.3,  # a plugin's: left to it
        }
    )
    assert p.controller_frequency == 10.0 and p.shutdown_costmaps is True
    assert p.max_planning_retries == 3
    assert p.recoveries == (
        RecoverySpec("reset", "clear_costmap_recovery/ClearCostmapRecovery"),
        RecoverySpec("spin", "rotate_recovery/RotateRecovery"),
    )


@pytest.mark.parametrize(
    ("values", "needle"),
    [
        ({"base_global_planner": "carrot_planner/CarrotPlanner"}, "base_global_planner"),
        ({"base_local_planner": "mpc/MPC"}, "roverlab has dwa_local_planner/DWAPlannerROS"),
        ({"controller_frequency": 0}, "controller_frequency must be > 0"),
        ({"planner_patience": -1}, "planner_patience must be >= 0"),
        ({"shutdown_costmaps": "maybe"}, "must be true or false"),
        ({"recovery_behaviors": [{"name": "x"}]}, "needs a name and a type"),
        ({"recovery_behaviors": [{"name": "x", "type": "a/B"}]}, "which is not available"),
    ],
)
def test_bad_parameters_are_one_clear_error(values: dict, needle: str) -> None:
    with pytest.raises(NavigationParamsError, match=needle):
        MoveBaseParams.from_ros(values)


def test_an_unknown_name_is_warned_about_by_name_and_ignored() -> None:
    p, warnings = MoveBaseParams.from_ros(
        {"controler_frequency": 5, "make_plan_clear_costmap": False}
    )
    assert p.controller_frequency == 20.0 and p.make_plan_clear_costmap is False
    assert warnings == (
        "move_base: unknown parameter 'controler_frequency' (did you mean "
        "controller_frequency?) is ignored",
    )


def test_plugins_by_ros_name() -> None:
    planner, _ = make_global_planner("navfn/NavfnROS", {"allow_unknown": False})
    assert type(planner).__name__ == "NavfnPlanner"
    gp, _ = make_global_planner("global_planner/GlobalPlanner", {"use_dijkstra": False})
    assert type(gp).__name__ == "GlobalPlanner"
    ctrl, limits, _ = make_local_planner(
        "dwa_local_planner/DWAPlannerROS",
        {"max_vel_theta": 1.2, "acc_lim_theta": 2.0},
        footprint=np.zeros((4, 2)),
        controller_frequency=10.0,
    )
    assert type(ctrl).__name__ == "DWAPlanner"
    assert ctrl.params.controller_frequency == 10.0  # type: ignore[attr-defined]
    assert (limits.max_rotational_vel, limits.acc_lim_th) == (1.2, 2.0)
    teb, _, _ = make_local_planner(
        "teb_local_planner/TebLocalPlannerROS", {}, footprint=(), controller_frequency=5.0
    )
    assert type(teb).__name__ == "TebPlanner"
    navfn, warnings = make_global_planner("navfn/NavfnROS", {"allow_unknwn": False})
    assert navfn.params.allow_unknown is True  # type: ignore[attr-defined]
    assert warnings == (
        "navfn: unknown parameter 'allow_unknwn' (did you mean allow_unknown?) is ignored",
    )


def test_recovery_plugins() -> None:
    limits = LocalPlannerLimits(2.0, 0.8, 0.3, 0.15)
    clear, _ = make_recovery(
        "conservative_reset",
        "clear_costmap_recovery/ClearCostmapRecovery",
        {},
        default_reset_distance=3.0,
        limits=limits,
        trajectory_planner={},
        footprint=(),
    )
    assert isinstance(clear, ClearCostmapRecovery) and clear.reset_distance == 3.0
    rot, _ = make_recovery(
        "rotate_recovery",
        "rotate_recovery/RotateRecovery",
        {"frequency": 10.0},
        default_reset_distance=0.0,
        limits=limits,
        trajectory_planner={"max_rotational_vel": 0.5},  # ~TrajectoryPlannerROS/ wins
        footprint=(),
    )
    assert isinstance(rot, RotateRecovery)
    assert rot.params == RotateRecoveryParams(
        sim_granularity=0.017,
        frequency=10.0,
        acc_lim_th=2.0,
        max_rotational_vel=0.5,
        min_in_place_rotational_vel=0.3,
        tolerance=0.15,
    )
    misspelt, warnings = make_recovery(
        "r",
        "clear_costmap_recovery/ClearCostmapRecovery",
        {"reset_distanc": 1.0},
        default_reset_distance=3.0,
        limits=limits,
        trajectory_planner={},
        footprint=(),
    )
    assert misspelt.reset_distance == 3.0  # type: ignore[union-attr]
    assert warnings == (
        "r: unknown parameter 'reset_distanc' (did you mean reset_distance?) is ignored",
    )


def _costmap(obstacles: list[tuple[float, float]], rolling: bool = False):  # type: ignore[no-untyped-def]
    values = {
        "robot_radius": 0.15,
        "width": 4.0,
        "height": 4.0,
        "resolution": 0.05,
        "rolling_window": rolling,
        "plugins": [
            {"name": "obstacle_layer", "type": "costmap_2d::ObstacleLayer"},
            {"name": "inflation_layer", "type": "costmap_2d::InflationLayer"},
        ],
        "obstacle_layer": {"observation_sources": "scan", "scan": {"data_type": "LaserScan"}},
        "inflation_layer": {"inflation_radius": 0.3},
    }
    params, _ = CostmapParams.from_ros(values, name="local_costmap")
    lc = make_layered_costmap(params)
    lc.resize_map(80, 80, 0.05, -2.0, -2.0)
    layer = lc.plugin("obstacle_layer")
    pts = np.array([[x, y, 0.1] for x, y in obstacles]).reshape(-1, 3)
    layer.add_observation("scan", np.array([0.0, 0.0, 0.2]), pts, 0.0, 0.0)  # type: ignore[attr-defined]
    lc.update_map(0.0, 0.0, 0.0)
    return lc, layer


def test_clear_costmap_recovery_keeps_the_window_around_the_robot() -> None:
    lc, layer = _costmap([(0.5, 0.0), (1.2, 1.2)])
    lethal = lambda: {tuple(c) for c in np.argwhere(lc.costmap.costs == 254)}  # noqa: E731
    assert len(lethal()) == 2
    layer.buffers["scan"].clear()  # type: ignore[attr-defined]
    rec = ClearCostmapRecovery("conservative_reset", reset_distance=2.0)
    cleared = rec.run(
        global_costmap=None, global_pose=None, local_costmap=lc, local_pose=SE2(0.0, 0.0, 0.0)
    )
    assert cleared == ["local:obstacle_layer"]
    lc.update_map(0.0, 0.0, 0.0)
    (cell,) = lethal()  # the far obstacle is forgotten, the near one kept
    assert lc.costmap.map_to_world(cell[1], cell[0])[0] == pytest.approx(0.525)
    only_named = ClearCostmapRecovery("x", reset_distance=0.0, layer_names=("obstacles",))
    assert (
        only_named.run(global_costmap=None, global_pose=None, local_costmap=lc, local_pose=SE2())
        == []
    )


def test_rotate_recovery_turns_once_and_stops_when_blocked() -> None:
    lc, _ = _costmap([])
    fp = np.array([[-0.2, -0.1], [-0.2, 0.1], [0.2, 0.1], [0.2, -0.1]])
    rec = RotateRecovery("rotate_recovery", RotateRecoveryParams(), footprint=fp)
    pose = SE2(0.0, 0.0, 0.3)
    rec.start(pose)
    turned, dt = 0.0, 0.05
    for _ in range(400):
        w = rec.step(pose, lc.costmap)
        if w is None:
            break
        assert 0.4 <= w <= 1.0
        pose = SE2(0.0, 0.0, pose.theta + w * dt)
        turned += w * dt
    assert rec.finished and rec.blocked is None
    assert turned == pytest.approx(2 * math.pi, abs=0.15)
    blocked_map, _ = _costmap([(0.0, 0.21)])  # the corners reach 0.22 m when turning
    rec.start(SE2(0.0, 0.0, 0.0))
    assert rec.step(SE2(0.0, 0.0, 0.0), blocked_map.costmap) is None
    assert rec.blocked is not None and "potential collision" in rec.blocked
