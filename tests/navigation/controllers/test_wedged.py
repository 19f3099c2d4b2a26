"""Never wedged (issue 28): a robot stopped beside a pillar at a door, an obstacle inside
its padded footprint's circumscribed radius while its body is clear. Every sample of the
local planner is refused and rotate_recovery "can't rotate in place"; base_local_planner's
escape backs it out (its real footprint checked) and it drives through the door."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.controllers import DWAParams, DWAPlanner, Velocity2D
from roverlab.navigation.costmap import Costmap2D, footprint_radii
from roverlab.navigation.move_base.recovery import RotateRecovery
from tests.navigation.controllers.sim import RES, costmaps, run

#: a Jackal-sized body (BARN's footprint) padded by BARN's 0.1 m
BODY = [[-0.21, -0.165], [-0.21, 0.165], [0.21, 0.165], [0.21, -0.165]]
PADDING = 0.1
#: BARN's base_local_planner_params.yaml (TrajectoryPlannerROS, dwa: true)
BARN_TP = {
    "acc_lim_x": 10.0, "acc_lim_theta": 20.0, "max_vel_x": 0.5, "min_vel_x": 0.1,
    "max_vel_theta": 1.57, "min_in_place_vel_theta": 0.314, "holonomic_robot": False,
    "escape_vel": -0.5, "yaw_goal_tolerance": 0.157, "xy_goal_tolerance": 0.25,
    "sim_time": 2.0, "sim_granularity": 0.02, "angular_sim_granularity": 0.02,
    "vx_samples": 6, "vtheta_samples": 20, "controller_frequency": 20.0,
    "meter_scoring": True, "occdist_scale": 0.1, "pdist_scale": 0.75, "gdist_scale": 1.0,
    "dwa": True, "oscillation_reset_dist": 0.05, "escape_reset_dist": 0.1,
    "escape_reset_theta": 0.1,
}  # fmt: skip
PILLAR = (2.75, 1.45)  # by the door's lower jamb; the door is y 1.55..2.45 in x 3.0..3.1


def _corridor() -> np.ndarray:
    """6 x 4 m: a wall across x = 3.0..3.1 m with a 0.9 m door, 0.15 m pillars by it."""
    g = np.zeros((80, 120), np.int8)
    g[:2, :] = g[-2:, :] = g[:, :2] = g[:, -2:] = 100
    g[:, 60:62] = 100
    g[31:49, 60:62] = 0
    ys, xs = np.mgrid[0:80, 0:120]
    for px, py in (PILLAR, (PILLAR[0], 2.55)):
        g[np.hypot((xs + 0.5) * RES - px, (ys + 0.5) * RES - py) <= 0.075] = 100
    return g


def _wedged(angle: float, gap: float) -> SE2:
    """Heading +x with the pillar ``gap`` m (surface) away at ``angle`` off the heading."""
    d = gap + 0.075
    return SE2(PILLAR[0] - d * math.cos(angle), PILLAR[1] - d * math.sin(angle), 0.0)


def _dwa(escape_vel: float) -> DWAPlanner:
    p, _ = DWAParams.from_trajectory_planner_ros({**BARN_TP, "escape_vel": escape_vel})
    _, local = costmaps(_corridor(), 4.0, footprint=BODY, padding=PADDING, inflation_radius=0.3)
    return DWAPlanner(p, footprint=local.footprint, body_footprint=BODY)


@pytest.mark.parametrize(("angle", "gap"), [(0.0, 0.30), (0.6, 0.33), (-0.3, 0.36)])
def test_a_wedged_robot_backs_out_and_drives_through_the_door(angle: float, gap: float) -> None:
    grid = _corridor()
    start = _wedged(angle, gap)
    _, local = costmaps(grid, 4.0, footprint=BODY, padding=PADDING, inflation_radius=0.3)
    local.update_map(start.x, start.y, start.theta)
    _, circumscribed = footprint_radii(local.footprint)
    assert gap + 0.075 < circumscribed + 0.075  # inside the padded circumscribed radius
    # the wedge: ROS's rotate_recovery cannot turn, and without the escape every sample
    # is refused
    rot = RotateRecovery("rotate_recovery", footprint=local.footprint)
    rot.start(start)
    assert rot.step(start, local.costmap) is None and rot.blocked
    plan = np.array([[start.x, start.y, 0.0], [3.05, 2.0, 0.0], [4.5, 2.0, 0.0]])
    # every candidate is refused with the padded footprint (what DWA did, and what its
    # escape hatches start from)
    dwa = _dwa(-0.5)
    dwa.set_plan(plan)
    dwa._update_local_costs(start, plan, local.costmap)
    samples = dwa._sample_velocities(start, Velocity2D())
    assert dwa._score(start, Velocity2D(), samples, local.costmap, dwa._only)[0] < 0
    cmd = dwa.compute_velocity(start, Velocity2D(), plan, local.costmap)
    assert cmd.vx < 0.0 or not math.isclose(cmd.vx, 0.0)  # it moves
    r = run(
        dwa, grid, start, SE2(4.5, 2.0, 0.0), dt=0.05, max_steps=1200, local_m=4.0,
        body=BODY, padding=PADDING, inflation_radius=0.3, acc=(10.0, 20.0),
    )  # fmt: skip
    assert r.reached and not r.collided, (r.pose, r.failures)
    assert r.pose.x > 4.0


def test_an_escape_blocked_behind_gives_forward_motion_back() -> None:
    """Escaping leaves forward samples out; once backing up is blocked too (a wall just
    behind the body), forward motion is sampled again rather than refusing everything."""
    cm = Costmap2D(size_x=80, size_y=80, resolution=RES)
    pose = SE2(1.0, 2.0, 0.0)
    # cell 0.65-0.70 m: 9 cm behind the body, inside the padding, clear of half of it
    cm.costs[30:50, int((pose.x - 0.33) / RES)] = 254
    plan = np.array([[1.0, 2.0, 0.0], [2.0, 2.0, 0.0], [3.5, 2.0, 0.0]])
    dwa = _dwa(-0.5)
    dwa.escaping, dwa._escape_from = True, pose  # backing out of a wedge, just begun
    cmd = dwa.compute_velocity(pose, Velocity2D(), plan, cm)
    assert cmd.vx > 0.0 and not dwa.escaping
    # the same robot with room behind goes on backing up
    dwa.escaping, dwa._escape_from = True, pose
    room = Costmap2D(size_x=80, size_y=80, resolution=RES)
    only_back = dwa.compute_velocity(pose, Velocity2D(), plan, room)
    assert dwa.escaping and only_back == Velocity2D(-0.5, 0.0, 0.0)  # no forward sample


def test_in_place_rotations_turn_a_robot_facing_a_dead_end() -> None:
    """TrajectoryPlanner samples rotations in place (``min_in_place_vel_theta``) every
    cycle, whatever ``min_vel_x`` is (``in_place_rotations: true``), and takes one when
    its cost is not above the best arc's: in a 0.85 m wide pocket facing its end wall
    (the plan behind) the robot turns where it stands; with both directions stuck it
    drives the best arc; roverlab's default samples only the dynamic window (vx >= 0.1)
    and backs up."""
    cm = Costmap2D(size_x=80, size_y=80, resolution=RES)
    cm.costs[31:49, 49] = cm.costs[31, 30:50] = cm.costs[48, 30:50] = 254  # open at -x
    pose = SE2(2.0, 2.0, 0.0)  # 0.45 m from the end wall, 0.4 m from each side
    plan = np.array([[2.0, 2.0, 0.0], [1.0, 2.0, 0.0], [0.5, 2.0, 0.0]])
    dwa = _dwa(-0.5)
    dwa.params = dataclasses.replace(dwa.params, in_place_samples=True)
    cmd = dwa.compute_velocity(pose, Velocity2D(), plan, cm)
    assert cmd.vx == 0.0 and abs(cmd.wz) >= 0.314 and not dwa.escaping, cmd
    arcs = (dwa.samples[:, 0] > 0.0) & (dwa.costs >= 0)
    turned = (dwa.samples == [cmd.vx, cmd.vy, cmd.wz]).all(axis=1)
    assert arcs.any() and dwa.costs[turned][0] <= dwa.costs[arcs].min()
    # the stuck flags: once it has turned one way after the other, that first way is out
    r = dwa._rotations
    r.rotating_left = r.rotating_right = r.stuck_left = r.stuck_right = True
    r._prev = pose
    assert dwa.compute_velocity(pose, Velocity2D(), plan, cm).vx > 0.0
    # the default refuses every arc of its window here and backs up (world_245's loop)
    assert _dwa(-0.5).compute_velocity(pose, Velocity2D(), plan, cm).vx < 0.0


def test_a_stalled_robot_turns_in_place_and_the_progress_check_resets_when_it_moves() -> None:
    """roverlab's progress check (Nav2's SimpleProgressChecker names): the default
    samples no rotation in place, so in the pocket it backs up, drives back in and
    repeats (BARN world_245 for 78 s); after ``movement_time_allowance`` within
    ``required_movement_radius`` it samples TrajectoryPlanner's rotations and turns."""
    cm = Costmap2D(size_x=80, size_y=80, resolution=RES)
    cm.costs[31:49, 49] = cm.costs[31, 30:50] = cm.costs[48, 30:50] = 254  # open at -x
    pose = SE2(2.0, 2.0, 0.0)
    plan = np.array([[2.0, 2.0, 0.0], [1.0, 2.0, 0.0], [0.5, 2.0, 0.0]])
    base = _dwa(-0.5)
    assert base.params.movement_time_allowance == 20.0  # TrajectoryPlannerROS's default
    p = dataclasses.replace(base.params, movement_time_allowance=0.2)  # 4 cycles at 20 Hz
    dwa = DWAPlanner(p, footprint=base.footprint, body_footprint=BODY)
    cmds = [dwa.compute_velocity(pose, Velocity2D(), plan, cm) for _ in range(6)]
    assert all(c.vx < 0.0 for c in cmds[:4]), cmds  # backing up, not yet stalled
    assert cmds[-1].vx == 0.0 and abs(cmds[-1].wz) >= 0.314, cmds  # turns in place
    # 0.6 m on, the window starts again: no rotation until stalled again
    assert not dwa._progress.stalled(SE2(1.4, 2.0, 0.0)) and not dwa._progress.is_stalled
    off = dataclasses.replace(p, movement_time_allowance=0.0)  # 0: never (window only)
    never = DWAPlanner(off, footprint=base.footprint, body_footprint=BODY)
    assert all(never.compute_velocity(pose, Velocity2D(), plan, cm).vx < 0 for _ in range(6))
