"""dwa_local_planner: sampling, scoring, goal behaviour, closed loop, parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.controllers import DWAParams, DWAPlanner, Velocity2D
from roverlab.navigation.controllers.dwa import velocity_iterator
from roverlab.navigation.costmap import Costmap2D, footprint_from_radius
from roverlab.navigation.costmap.footprint_kernels import footprint_cost
from roverlab.navigation.errors import InvalidPathError, NavigationParamsError, NoValidControlError
from tests.navigation.controllers.conftest import DWA
from tests.navigation.controllers.sim import ROBOT_RADIUS, field_world, run

FOOT = footprint_from_radius(ROBOT_RADIUS)


def test_velocity_iterator_inserts_zero_between_signs() -> None:
    assert velocity_iterator(-0.2, 0.2, 3) == pytest.approx([-0.2, 0.0, 0.2])
    assert velocity_iterator(-0.3, 0.3, 4) == pytest.approx([-0.3, -0.1, 0.0, 0.1, 0.3])
    assert velocity_iterator(0.1, 0.1, 5) == [0.1]
    assert velocity_iterator(0.0, 0.4, 1) == pytest.approx([0.0, 0.4])


def _open(size: int = 60) -> Costmap2D:
    return Costmap2D(size_x=size, size_y=size, resolution=0.05)


def test_samples_stay_in_the_dynamic_window(dwa_params: DWAParams) -> None:
    dwa = DWAPlanner(dwa_params, footprint=FOOT)
    cm = _open()
    plan = np.array([[0.5, 1.5, 0.0], [2.5, 1.5, 0.0]])
    twist = Velocity2D(0.1, 0.0, 0.3)
    dwa.compute_velocity(SE2(0.5, 1.5, 0.0), twist, plan, cm)
    s = dwa.samples
    dt = 1.0 / dwa_params.controller_frequency
    assert s[:, 0].min() >= max(0.0, 0.1 - 2.5 * dt) - 1e-12
    assert s[:, 0].max() <= min(0.26, 0.1 + 2.5 * dt) + 1e-12
    assert s[:, 2].max() <= 0.3 + 3.2 * dt + 1e-12 and (s[:, 1] == 0).all()
    assert len(dwa.trajectory) > 1 and dwa.costs.shape == (len(s),)


def test_pruned_scoring_chooses_what_full_scoring_chooses(dwa_params: DWAParams) -> None:
    rng = np.random.default_rng(11)
    for trial in range(5):
        cm = _open()
        cells = rng.integers(0, 60, size=(40, 2))
        cm.costs[cells[:, 1], cells[:, 0]] = rng.choice([254, 200, 120], size=40)
        dwa = DWAPlanner(dwa_params, footprint=FOOT)
        pose = SE2(1.5, 1.5, float(rng.uniform(-3, 3)))
        plan = np.array([[1.5, 1.5, 0.0], [2.5, 2.0, 0.0], [2.9, 2.9, 0.0]])
        twist = Velocity2D(0.1, 0.0, 0.0)
        try:
            dwa.compute_velocity(pose, twist, plan, cm)
        except NoValidControlError:
            continue
        best_pruned = int(np.flatnonzero(dwa.costs == dwa.costs[dwa.costs >= 0].min())[0])
        best, full = dwa._score(pose, twist, dwa.samples, cm, dwa._only, prune=False)
        if best < 0:  # a lethal cell under the robot: the escape chose (tested below)
            continue
        assert best == best_pruned, trial
        assert full[best] == pytest.approx(dwa.costs[best])
        valid = full >= 0
        assert (dwa.costs[valid] <= full[valid] + 1e-9).all()  # pruned ones are lower bounds


def test_escape_from_a_lethal_cell_under_the_footprint(dwa_params: DWAParams) -> None:
    """Every rollout starts at the robot's pose, so a lethal cell under its outline (one
    CostmapModel's outline missed on the way in) refuses every sample: DWA drives to the
    cheapest pose clear of that cell, still refusing every other lethal cell."""
    fp = np.array([[-0.125, -0.1], [-0.125, 0.1], [0.125, 0.1], [0.125, -0.1]])
    plan = np.array([[1.5, 1.5, 0.0], [2.5, 1.5, 0.0], [2.9, 1.5, 0.0]])
    pose = SE2(1.5, 1.5, 0.0)
    cm = _open()
    cm.costs[int(1.6 / 0.05), int(1.5 / 0.05)] = 254  # under the left edge
    buf = np.empty((256, 2), dtype=np.int64)
    # every rollout's first pose is refused by the footprint check
    assert footprint_cost(cm.costs, 0.05, 0.0, 0.0, 1.5, 1.5, 0.0, fp, 1.0, buf) < 0
    dwa = DWAPlanner(dwa_params, footprint=fp)
    cmd = dwa.compute_velocity(pose, Velocity2D(), plan, cm)
    # on along the plan, away from the cell: forward within the dynamic window (2.5 m/s^2
    # for 0.1 s), its trajectory's last footprint clear of the cell and legal
    assert 0.05 <= cmd.vx <= 0.25 + 1e-9 and cmd.vy == 0.0 and abs(cmd.wz) <= 0.32 + 1e-9
    x, y, th = dwa.trajectory[-1]
    assert x > 1.5 + 0.5 * cmd.vx and not dwa.escaping
    assert footprint_cost(cm.costs, 0.05, 0.0, 0.0, x, y, th, fp, 1.0, buf) >= 0
    # walled in ahead and behind: no sample gets clear without crossing other lethal cells
    boxed = cm.copy()
    boxed.costs[:, int(1.75 / 0.05)] = 254
    boxed.costs[:, int(1.25 / 0.05)] = 254
    with pytest.raises(NoValidControlError):
        DWAPlanner(dwa_params, footprint=fp).compute_velocity(pose, Velocity2D(), plan, boxed)


def test_rotate_in_place_at_the_goal_then_reached(dwa_params: DWAParams) -> None:
    dwa = DWAPlanner(dwa_params, footprint=FOOT)
    cm = _open()
    plan = np.array([[0.5, 1.5, 0.0], [1.5, 1.5, 0.0], [1.52, 1.5, 1.2]])
    pose = SE2(1.5, 1.5, 0.0)
    cmd = dwa.compute_velocity(pose, Velocity2D(0.2, 0.0, 0.0), plan, cm)
    assert cmd.vx == pytest.approx(0.0) and cmd.wz == 0.0  # braking first
    cmd = dwa.compute_velocity(pose, Velocity2D(), plan, cm)
    # then turning towards the goal's yaw: from rest the acceleration allows 0.32 rad/s in
    # 0.1 s, raised to min_vel_theta (LatchedStopRotateController's order of clamps)
    assert cmd == Velocity2D(0.0, 0.0, pytest.approx(0.4))
    assert not dwa.is_goal_reached(pose, Velocity2D())
    at_goal = SE2(1.5, 1.5, 1.15)
    assert not dwa.is_goal_reached(at_goal, Velocity2D(0.0, 0.0, 0.5))  # still turning
    assert dwa.is_goal_reached(at_goal, Velocity2D())


def test_latch_xy_goal_tolerance(dwa_params: DWAParams) -> None:
    cm = _open()
    plan = np.array([[0.5, 1.5, 0.0], [1.5, 1.5, 1.0]])
    for latch, expected in ((True, True), (False, False)):
        p = DWAParams.from_ros({**DWA, "latch_xy_goal_tolerance": latch})[0]
        dwa = DWAPlanner(p, footprint=FOOT)
        dwa.compute_velocity(SE2(1.5, 1.5, 0.0), Velocity2D(), plan, cm)
        # drifted out of the tolerance while turning
        assert dwa.is_goal_reached(SE2(1.7, 1.5, 1.0), Velocity2D()) is expected


def test_boxed_in_robot_gets_no_valid_control(dwa_params: DWAParams) -> None:
    cm = _open()
    cm.costs[:, :] = 254
    cm.costs[28:32, 28:32] = 0
    dwa = DWAPlanner(dwa_params, footprint=FOOT)
    with pytest.raises(NoValidControlError, match="discarded all candidates"):
        dwa.compute_velocity(SE2(1.5, 1.5, 0.0), Velocity2D(), [[1.5, 1.5, 0], [2.5, 1.5, 0]], cm)
    with pytest.raises(InvalidPathError):
        dwa.compute_velocity(SE2(1.5, 1.5, 0.0), Velocity2D(), np.zeros((0, 3)), cm)


@pytest.mark.parametrize("seed", [0, 1])
def test_dwa_reaches_the_goal_through_a_cluttered_field(dwa_params: DWAParams, seed: int) -> None:
    r = run(
        DWAPlanner(dwa_params, footprint=FOOT), field_world(seed), SE2(1, 1, 0), SE2(5, 5, 1.57)
    )
    assert r.reached and not r.collided, (r.pose, r.steps)
    assert min(c.vx for c in r.commands) >= 0.0  # min_vel_x 0: move forward only
    assert math.hypot(r.pose.x - 5, r.pose.y - 5) <= 0.1


def test_dwa_is_deterministic(dwa_params: DWAParams) -> None:
    g = field_world(4)
    a = run(DWAPlanner(dwa_params, footprint=FOOT), g, SE2(1, 1, 0), SE2(5, 5, 0), max_steps=60)
    b = run(DWAPlanner(dwa_params, footprint=FOOT), g, SE2(1, 1, 0), SE2(5, 5, 0), max_steps=60)
    assert a.commands == b.commands


def test_parameters_renamed_and_validated() -> None:
    p, warnings = DWAParams.from_ros({"max_rot_vel": 2.0, "min_rot_vel": 0.3, "vy_samples": 0})
    assert (p.max_vel_theta, p.min_vel_theta, p.samples[1]) == (2.0, 0.3, 1)
    assert any("max_rot_vel has been renamed to max_vel_theta" in w for w in warnings)
    assert any("vy_samples" in w for w in warnings)
    with pytest.raises(NavigationParamsError, match="sim_time must be > 0"):
        DWAParams.from_ros({"sim_time": 0})
    unknown, warnings = DWAParams.from_ros({"max_vel_xx": 1.0})
    assert unknown == DWAParams()
    assert any("unknown parameter 'max_vel_xx' (did you mean max_vel_x?)" in w for w in warnings)
    with pytest.raises(NavigationParamsError, match="acc_lim_x must be a finite number"):
        DWAParams.from_ros({"acc_lim_x": "fast"})


def test_trajectory_planner_ros_names_map_onto_dwa() -> None:
    p, warnings = DWAParams.from_trajectory_planner_ros(
        {"max_vel_x": 0.3, "min_vel_x": 0.05, "acc_lim_th": 2.0, "holonomic_robot": False,
         "pdist_scale": 0.8, "gdist_scale": 0.6, "vtheta_samples": 30, "heading_lookahead": 0.3}
    )  # fmt: skip
    assert (p.max_vel_x, p.min_vel_x, p.acc_lim_theta, p.vth_samples) == (0.3, 0.05, 2.0, 30)
    assert p.y_limits == (0.0, 0.0) and not p.meter_scoring
    assert (p.path_distance_bias, p.goal_distance_bias, p.forward_point_distance) == (0.4, 0.3, 0.0)
    assert p.heading_lookahead == 0.3 and not p.in_place_samples  # roverlab's default
    assert not any("heading_lookahead" in w for w in warnings)
    ros, _ = DWAParams.from_trajectory_planner_ros({"in_place_rotations": True})
    assert ros.in_place_samples
    holo, _ = DWAParams.from_trajectory_planner_ros({})
    assert holo.y_limits == (-0.3, 0.3) and holo.vy_samples == 4
    z, warnings = DWAParams.from_trajectory_planner_ros({"max_vel_z": 1.0})
    assert z == holo and any("unknown parameter 'max_vel_z'" in w for w in warnings)


def test_trajectory_planner_ros_escape_and_deprecated_names() -> None:
    """BARN's base_local_planner_params.yaml: escape_* are applied, heading_* named."""
    p, warnings = DWAParams.from_trajectory_planner_ros(
        {"escape_vel": -0.5, "escape_reset_dist": 0.2, "escape_reset_theta": 0.3,
         "heading_lookahead": 0.325, "heading_scoring": True, "simple_attractor": False,
         "min_in_place_rotational_vel": 0.3, "odom_topic": "odometry/filtered",
         "world_model": "voxel", "restore_defaults": False}
    )  # fmt: skip
    assert (p.escape_vel, p.escape_reset_dist, p.escape_reset_theta) == (-0.5, 0.2, 0.3)
    assert p.min_vel_theta == 0.3
    text = "\n".join(warnings)
    assert "min_in_place_rotational_vel has been renamed to min_in_place_vel_theta" in text
    assert "heading_lookahead" not in text and "heading_scoring true" in text
    assert "world_model 'voxel'" in text and "simple_attractor" not in text
    assert "odom_topic" not in text and "restore_defaults" not in text
    old, warnings = DWAParams.from_trajectory_planner_ros({"backup_vel": -0.2})
    assert old.escape_vel == -0.2 and any("backup_vel has been renamed" in w for w in warnings)
    with pytest.raises(NavigationParamsError, match="escape_vel must be <= 0"):
        DWAParams.from_trajectory_planner_ros({"escape_vel": 0.5})


def test_trajectory_planner_checks_a_trajectory_up_to_sim_time_only() -> None:
    """TrajectoryPlanner's stop_time_buffer check is commented out in ROS: BARN's 0.5 m/s
    for 2 s ends 0.98 m ahead (its last pose), and a wall 0.05 m beyond the padded front
    there must not refuse it (DWA's 0.2 s more refused it: the robot crawled)."""
    p, _ = DWAParams.from_trajectory_planner_ros(
        {"max_vel_x": 0.5, "min_vel_x": 0.1, "sim_time": 2.0, "sim_granularity": 0.02,
         "acc_lim_x": 10.0, "holonomic_robot": False, "dwa": True}
    )  # fmt: skip
    fp = [[-0.31, -0.265], [-0.31, 0.265], [0.31, 0.265], [0.31, -0.265]]
    dwa = DWAPlanner(p, footprint=fp)
    cm = Costmap2D(size_x=100, size_y=100, resolution=0.05)
    pose = SE2(1.0, 2.5, 0.0)
    cm.costs[40:60, int((1.0 + 0.98 + 0.31 + 0.05) / 0.05)] = 254  # x 2.30-2.35, y 2-3 m
    plan = np.array([[1.0, 2.5, 0.0], [4.0, 2.5, 0.0]])
    dwa.set_plan(plan)
    dwa._update_local_costs(pose, plan, cm)
    fast = np.array([[0.5, 0.0, 0.0]])
    vel = Velocity2D(0.5, 0.0, 0.0)
    assert dwa._score(pose, vel, fast, cm, dwa._only)[1][0] >= 0
    assert dwa.compute_velocity(pose, vel, plan, cm).vx == pytest.approx(0.5)


def test_waves_stopped_at_the_reach_window_choose_what_whole_waves_choose(
    dwa_params: DWAParams, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The map grids are final only near the robot; every sample's cost and the command
    are the same as with the waves run to their end, also when a read falls outside
    the window (the scoring then has the waves run to their end)."""
    rng = np.random.default_rng(12)
    stopped = 0
    for _ in range(6):
        cm = _open(200)
        cells = rng.integers(0, 200, size=(400, 2))
        cm.costs[cells[:, 1], cells[:, 0]] = rng.choice([254, 253, 200, 120], size=400)
        pose = SE2(5.0, 5.0, float(rng.uniform(-3, 3)))
        plan = np.array([[5.0, 5.0, 0.0], [6.0, 5.5, 0.0], [7.5, 7.0, 0.0], [9.9, 9.0, 0.0]])
        twist = Velocity2D(0.2, 0.0, 0.1)
        answers = []
        for window in ("reach", "whole", "one cell"):
            dwa = DWAPlanner(dwa_params, footprint=FOOT)
            if window == "whole":
                monkeypatch.setattr(dwa, "_reach_window", lambda p, c: np.array([0, 0, 199, 199]))
            elif window == "one cell":
                monkeypatch.setattr(dwa, "_reach_window", lambda p, c: np.array([0, 0, 0, 0]))
            try:
                cmd = dwa.compute_velocity(pose, twist, plan, cm)
            except NoValidControlError as err:
                answers.append((str(err), None, None))
                continue
            if window == "reach":
                stopped += int(dwa._window[2] - dwa._window[0] < 199)
            answers.append((cmd, dwa.samples.tolist(), dwa.costs.tolist()))
        assert answers[0] == answers[1] == answers[2]
    assert stopped >= 3  # the waves did stop at the window
