"""teb_local_planner: band, robot models, optimisation in a closed loop, parameters."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from roverlab.geometry import SE2
from roverlab.navigation.controllers import FootprintModel, TebParams, TebPlanner, Velocity2D
from roverlab.navigation.controllers.teb import TimedElasticBand
from roverlab.navigation.controllers.teb.kernels import associate_obstacles, robot_distance
from roverlab.navigation.controllers.teb.obstacles import costmap_obstacles
from roverlab.navigation.costmap import Costmap2D, footprint_from_radius, pad_footprint
from roverlab.navigation.errors import NavigationParamsError, NoValidControlError
from roverlab.navigation.planners import NavfnPlanner
from tests.navigation.controllers.conftest import TEB
from tests.navigation.controllers.sim import ROBOT_RADIUS, costmaps, field_world, run

FOOT = footprint_from_radius(ROBOT_RADIUS)


def test_band_initialisation_and_autosize() -> None:
    band = TimedElasticBand()
    plan = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    band.init_from_plan(plan, 0.5, 1.0, True, 3, False)
    assert band.poses.shape == (3, 3) and band.dts == pytest.approx([2.0, 2.0])
    band.auto_resize(0.3, 0.1, 3, 500)  # one pass halves each long interval
    assert len(band.dts) == len(band.poses) - 1 > 3
    assert band.dts.sum() == pytest.approx(4.0)
    assert band.poses[0] == pytest.approx(plan[0]) and band.poses[-1] == pytest.approx(plan[-1])
    for _ in range(10):
        band.auto_resize(0.3, 0.1, 3, 500)
    assert (band.dts <= 0.4 + 1e-9).all()
    band.update_and_prune(np.array([0.3, 0.0, 0.0]), np.array([2.0, 0.1, 0.0]), 3)
    assert band.poses[0] == pytest.approx([0.3, 0.0, 0.0]) and band.poses[-1][1] == 0.1


def test_robot_models_distances() -> None:
    assert robot_distance(0, 0, 0, 0, np.zeros(0), 3.0, 4.0) == pytest.approx(5.0)
    assert robot_distance(0, 0, 0, 1, np.array([1.0]), 3.0, 4.0) == pytest.approx(4.0)
    two = np.array([0.5, 0.2, 0.5, 0.3])  # front 0.5 m ahead r 0.2, rear 0.5 m behind r 0.3
    assert robot_distance(0, 0, math.pi / 2, 2, two, 0.0, 2.0) == pytest.approx(1.3)
    line = np.array([-0.5, 0.0, 0.5, 0.0])
    assert robot_distance(1, 1, 0, 3, line, 1.2, 2.0) == pytest.approx(1.0)
    square = np.array([0.2, 0.2, -0.2, 0.2, -0.2, -0.2, 0.2, -0.2])
    assert robot_distance(0, 0, 0, 4, square, 1.0, 0.0) == pytest.approx(0.8)


def test_footprint_model_parameters() -> None:
    m = FootprintModel.from_ros(
        {"type": "polygon", "vertices": [[0.1, 0.1], [-0.1, 0.1], [0, -0.1]]}
    )
    assert m.code == 4 and len(m.values) == 6
    p, _ = TebParams.from_ros(
        {
            "footprint_model/type": "line",
            "footprint_model/line_start": [-0.1, 0.0],
            "footprint_model/line_end": [0.1, 0.0],
        }
    )
    assert p.footprint_model == FootprintModel("line", (-0.1, 0.0, 0.1, 0.0))
    with pytest.raises(NavigationParamsError, match="radius is required"):
        FootprintModel.from_ros({"type": "circular"})
    with pytest.raises(NavigationParamsError, match="type must be one of"):
        FootprintModel.from_ros({"type": "blob"})


def test_parameters_validation_and_unimplemented_names() -> None:
    p, warnings = TebParams.from_ros(
        {**TEB, "enable_homotopy_class_planning": True, "max_vel_x_backwards": 0.0}
    )
    assert any("homotopy class planning is not implemented" in w for w in warnings)
    assert any("max_vel_x_backwards to be <= 0" in w for w in warnings)
    # teb's default is homotopy planning on: a user who never set it is told too
    _, silent = TebParams.from_ros({"enable_homotopy_class_planning": False})
    _, told = TebParams.from_ros({})
    assert silent == () and any("enable_homotopy_class_planning is true" in w for w in told)
    holo, warnings = TebParams.from_ros({"max_vel_y": 0.2, "enable_homotopy_class_planning": False})
    assert holo.max_vel_y == 0.0 and any("max_vel_y 0.2 ignored" in w for w in warnings)
    misspelt, warnings = TebParams.from_ros(
        {"dt_reff": 0.3, "enable_homotopy_class_planning": False, "odom_topic": "odom",
         "max_number_classes": 4, "obstacle_proximity_ratio_max_vel": 1.0,
         "costmap_converter": {"CostmapToPolygonsDBSMCCH": {"cluster_max_distance": 0.4}},
         "footprint_model": {"type": "circular", "radius": 0.2, "raduis": 0.3}}
    )  # fmt: skip
    assert misspelt.dt_ref == 0.3 and misspelt.footprint_model.values == (0.2,)
    text = "\n".join(warnings)
    assert "unknown parameter 'dt_reff' (did you mean dt_ref?)" in text
    assert "max_number_classes" in text and "obstacle_proximity_ratio_max_vel" in text
    assert "costmap_converter/CostmapToPolygonsDBSMCCH/cluster_max_distance" in text
    assert "'raduis'" in text and "odom_topic" not in text
    with pytest.raises(NavigationParamsError, match="dt_hysteresis"):
        TebParams(dt_ref=0.3, dt_hysteresis=0.4)
    assert p.trans_limit == p.max_vel_x


def _open() -> Costmap2D:
    return Costmap2D(size_x=60, size_y=60, resolution=0.05)


def test_straight_run_command_respects_limits(teb_params: TebParams) -> None:
    teb = TebPlanner(teb_params, footprint=FOOT)
    plan = np.column_stack([np.linspace(0.5, 2.5, 21), np.full(21, 1.5), np.zeros(21)])
    cmd = teb.compute_velocity(SE2(0.5, 1.5, 0.0), Velocity2D(), plan, _open())
    assert 0.0 < cmd.vx <= teb_params.max_vel_x + 1e-9
    assert abs(cmd.wz) < 0.2 and cmd.vy == 0.0
    dts = teb.band.dts
    assert (dts > 0).all() and len(teb.band.poses) >= teb_params.min_samples
    # time-optimal against soft speed limits (TEB's penalties start at max - epsilon, and
    # trade against time, so the band may plan a little above max_vel_x; the command is
    # saturated)
    mean_speed = float(np.sum(np.hypot(*np.diff(teb.band.poses[:, :2], axis=0).T))) / dts.sum()
    assert 0.5 * 0.26 < mean_speed < 1.5 * 0.26


def test_goal_reached_gives_a_zero_command(teb_params: TebParams) -> None:
    teb = TebPlanner(teb_params, footprint=FOOT)
    plan = np.array([[0.5, 1.5, 0.0], [1.5, 1.5, 0.5]])
    cmd = teb.compute_velocity(SE2(1.48, 1.5, 0.45), Velocity2D(), plan, _open())
    assert cmd == Velocity2D() and teb.is_goal_reached()
    cmd = teb.compute_velocity(SE2(1.48, 1.5, 0.45), Velocity2D(0.2, 0, 0), plan, _open())
    assert not teb.is_goal_reached()  # not stopped


def test_blocked_start_is_not_feasible(teb_params: TebParams) -> None:
    cm = _open()
    cm.costs[26:35, 26:35] = 254  # the robot's outline over lethal cells
    teb = TebPlanner(teb_params, footprint=FOOT)
    plan = np.column_stack([np.linspace(1.5, 2.5, 11), np.full(11, 1.5), np.zeros(11)])
    with pytest.raises(NoValidControlError, match="not feasible"):
        for _ in range(3):
            teb.compute_velocity(SE2(1.5, 1.5, 0.0), Velocity2D(), plan, cm)
    assert not teb.band.is_init  # cleared, as TEB resets its planner


@pytest.mark.parametrize("seed", [0, 2])
def test_teb_reaches_the_goal_through_a_cluttered_field(teb_params: TebParams, seed: int) -> None:
    r = run(
        TebPlanner(teb_params, footprint=FOOT), field_world(seed), SE2(1, 1, 0), SE2(5, 5, 1.57)
    )
    assert r.reached and not r.collided, (r.pose, r.steps, r.failures)
    assert math.hypot(r.pose.x - 5, r.pose.y - 5) < 0.1


def test_move_forward_only(teb_params: TebParams) -> None:
    p = TebParams.from_ros(
        {**TEB, "max_vel_x_backwards": 0.01, "weight_kinematics_forward_drive": 1000}
    )[0]
    r = run(TebPlanner(p, footprint=FOOT), field_world(1), SE2(1, 1, math.pi), SE2(2.5, 1.5, 0.0))
    assert r.reached and not r.collided
    assert min(c.vx for c in r.commands) >= -0.01 - 1e-9


def test_teb_is_deterministic(teb_params: TebParams) -> None:
    glob, local = costmaps(field_world(3))
    plan = NavfnPlanner().plan(SE2(1, 1, 0), SE2(5, 5, 0), glob.costmap)
    local.update_map(1.0, 1.0, 0.0)
    cmds = []
    for _ in range(3):
        teb = TebPlanner(teb_params, footprint=FOOT)
        cmds.append(teb.compute_velocity(SE2(1, 1, 0), Velocity2D(0.1, 0, 0), plan, local.costmap))
    # the solver is compiled code without BLAS: the same bits every call
    for c in cmds[1:]:
        assert (c.vx, c.wz) == (cmds[0].vx, cmds[0].wz)


def test_work_per_cycle_is_bounded_by_the_band_not_the_costmap(teb_params: TebParams) -> None:
    """Issue 28: 318-378 ms cycles in BARN's dense worlds, every lethal cell a point
    obstacle checked against every pose. The association now sees only the obstacles
    within its reach of the band (a k-d tree) and keeps the 8 closest force-included ones
    per pose (plus the closest left and right)."""
    poses = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0]])
    ring = np.column_stack([0.5 + 0.1 * np.cos(np.arange(40)), 0.1 * np.sin(np.arange(40))])
    op = np.empty(200, dtype=np.int64)
    oo = np.empty(200, dtype=np.int64)
    cnt = associate_obstacles(poses, ring, 0, np.zeros(0), 0.5, 2.0, op, oo, 8)
    assert cnt == 8 and (op[:cnt] == 1).all()
    d = np.hypot(ring[:, 0] - 0.5, ring[:, 1])
    assert set(d[oo[:cnt]]) <= set(np.sort(d)[:8])  # the closest eight
    teb = TebPlanner(teb_params, footprint=FOOT)
    cm = _open()
    cm.costs[:, ::2] = 254  # a costmap full of lethal cells: 900 of them
    teb.obstacles = costmap_obstacles(teb.params, SE2(0.5, 1.5, 0.0), cm, np.zeros((0, 3)))
    teb._obstacle_tree = cKDTree(teb.obstacles)
    band = np.column_stack([np.linspace(0.5, 1.5, 11), np.full(11, 1.5), np.zeros(11)])
    near = teb._near_obstacles(band)
    fp = teb_params.footprint_model
    reach = teb_params.min_obstacle_dist * teb_params.obstacle_association_cutoff_factor
    reach += fp.values[0] if fp.type == "circular" else 0.0
    gaps = near[:, None, :] - band[None, 1:-1, :2]
    dist = np.hypot(gaps[..., 0], gaps[..., 1]).min(axis=1)
    assert 0 < len(near) < len(teb.obstacles) and (dist <= reach + 1e-9).all()


def test_feasibility_check_lookahead_distance_replaces_the_pose_count() -> None:
    """TEB's isTrajectoryFeasible: with ``feasibility_check_lookahead_distance`` set, the
    check ends at the last pose within that distance, whatever feasibility_check_no_poses
    says (at 2 m/s the 5 poses of the default reach 3 m ahead, into clutter the band has
    not yet been optimised around)."""
    cm = _open()
    cm.costs[25:35, 38:41] = 254  # a wall across x = 1.9..2.05 m
    poses = np.column_stack([0.5 + 0.3 * np.arange(8), np.full(8, 1.5), np.zeros(8)])

    def feasible(**kw: float) -> bool:
        teb = TebPlanner(TebParams(**kw), footprint=FOOT)  # type: ignore[arg-type]
        teb.band.poses, teb.band.dts = poses.copy(), np.full(7, 0.3)
        return teb._feasible(cm)

    assert not feasible(feasibility_check_no_poses=5)  # pose 5 (x = 2.0) in the wall
    assert feasible(feasibility_check_no_poses=5, feasibility_check_lookahead_distance=0.8)
    assert feasible(feasibility_check_no_poses=2)
    # the distance replaces the count (TEB sets look_ahead_idx from it)
    assert not feasible(feasibility_check_no_poses=2, feasibility_check_lookahead_distance=2.0)


def _jackal() -> TebParams:
    import yaml

    from roverlab.description import find_package

    path = find_package("robot_navigation") / "param" / "Jackal" / "teb_local_planner_params.yaml"
    return TebParams.from_ros(yaml.safe_load(path.read_text())["TebLocalPlannerROS"])[0]


_BODY = np.array([[-0.21, -0.165], [-0.21, 0.165], [0.21, 0.165], [0.21, -0.165]])


def test_jackal_teb_model_covers_the_padded_footprint_inside_and_out() -> None:
    """The bundled Jackal file's model keeps every point of the costmap's padded footprint
    (BARN's 0.42 x 0.33 m body + footprint_padding 0.1) within min_obstacle_dist, the
    centre included. TEB checks feasibility with the padded footprint, so a bare-body model
    let the band come within the padding (2 m/s: "not feasible" near every post); and TEB's
    polygon distance is to the outline, so the padded polygon itself (the old file) put
    its centre 0.265 m from "the robot": a post inside a pose was never pushed out."""
    params = _jackal()
    fm = params.footprint_model
    padded = pad_footprint(_BODY, 0.1)
    lo, hi = padded.min(axis=0), padded.max(axis=0)
    gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], 13), np.linspace(lo[1], hi[1], 11))
    dist = [robot_distance(0.0, 0.0, 0.0, fm.code, fm.as_array(), x, y)
            for x, y in zip(gx.ravel(), gy.ravel(), strict=True)]  # fmt: skip
    # by half a cell at least: the band sees a post's cells as their centres, while the
    # feasibility check rejects a pose whose outline crosses any part of a cell (the old
    # line of +-0.1 m reached the padded corners with 2 mm to spare: BARN world_287)
    assert max(dist) <= params.min_obstacle_dist - 0.5 * 0.05
    # at 2 m/s feasibility_check_no_poses 5 reaches 3 m ahead; the file checks 1 m
    assert params.feasibility_check_lookahead_distance == 1.0


def test_jackal_band_pushes_out_a_post_that_appears_inside_it() -> None:
    """BARN world_194 at 0.5 m/s: a post the laser first marks where the warm-started band
    already runs lies inside some poses' footprints. With the old file (the padded polygon,
    whose distance is to the outline) those poses kept the post inside, the band between
    them tangled and autoResize grew it to 500 poses (150-600 ms per cycle). The band must
    leave the post outside every pose and stay short."""
    params = _jackal()
    teb = TebPlanner(params, footprint=pad_footprint(_BODY, 0.1))
    cm = Costmap2D(size_x=100, size_y=100, resolution=0.05)  # 5 x 5 m
    plan = np.column_stack([np.linspace(0.5, 4.0, 36), np.full(36, 2.5), np.zeros(36)])
    start = SE2(0.5, 2.5, 0.0)
    teb.compute_velocity(start, Velocity2D(), plan, cm)  # the straight band, warm
    cm.costs[49:52, 44:47] = 254  # a 0.15 m post at (2.25, 2.5), 1.75 m ahead, on the band
    post = np.array([2.25, 2.5])
    for _ in range(8):
        teb.compute_velocity(start, Velocity2D(), plan, cm)
    poses = teb.band.poses
    rel = post - poses[:, :2]
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    along, across = rel[:, 0] * c + rel[:, 1] * s, -rel[:, 0] * s + rel[:, 1] * c
    inside = (np.abs(along) < 0.21 + 0.075) & (np.abs(across) < 0.165 + 0.075)
    assert not inside.any(), poses[inside]
    length = float(np.sum(np.hypot(*np.diff(poses[:, :2], axis=0).T)))
    assert len(poses) < 40 and length < 5.0, (len(poses), length)


# BARN world_287 at 0.5 m/s, the local costmap's lethal cells within 0.7 m of the robot
# (cell indices of a 0.05 m grid), the robot's pose and every 4th point of navfn's plan
_GAP_CELLS = [
    (34, 69), (35, 69), (35, 70), (36, 68), (36, 69), (37, 69), (38, 69), (38, 70), (39, 68),
    (39, 69), (39, 70), (40, 69), (41, 69), (41, 70), (42, 68), (42, 69), (43, 68), (43, 69),
    (43, 71), (43, 72), (43, 91), (43, 92), (44, 69), (44, 70), (44, 72), (44, 73), (44, 90),
    (44, 91), (45, 72), (45, 89), (45, 91), (46, 71), (46, 72), (46, 88), (46, 89), (46, 90),
    (47, 72), (47, 73), (47, 87), (47, 88), (48, 72), (48, 88),
]  # fmt: skip
_GAP_PLAN = [
    (1.98, 4.03), (2.1, 4.04), (2.2, 4.05), (2.29, 4.04), (2.39, 4.02), (2.49, 4.0),
    (2.55, 4.07), (2.64, 4.12), (2.72, 4.18), (2.78, 4.25), (2.85, 4.33), (2.91, 4.41),
    (2.96, 4.5), (3.01, 4.58), (3.08, 4.66), (3.15, 4.73), (3.22, 4.8), (3.29, 4.86),
    (3.37, 4.92), (3.45, 4.99),
]  # fmt: skip


def test_jackal_band_turning_in_a_gap_keeps_the_padded_corners_off_the_posts() -> None:
    """BARN world_287 at 0.5 m/s: the plan turns left just beyond a 0.65 m gap. With the
    old model (a line of +-0.1 m, min_obstacle_dist 0.34) the optimised band began its
    turn inside the gap, where the padded footprint's corners lie 0.338 m from the line
    (2 mm inside the model): a corner's outline crossed a post cell 0.5 m ahead, every band
    was "not feasible", and the robot stood still 9.5 s (44.1 s for the world; the same in
    world_118, 122, 169 and 238, and for good in 64, 231 and 286). With the file's model
    the band is feasible and the robot drives on at full speed."""
    params = replace(_jackal(), max_vel_x=0.5, oscillation_recovery=False)
    cm = Costmap2D(size_x=160, size_y=160, resolution=0.05)
    for ix, iy in _GAP_CELLS:
        cm.costs[iy, ix] = 254
    plan = np.column_stack([np.array(_GAP_PLAN), np.zeros(len(_GAP_PLAN))])
    pose = SE2(1.98, 4.012, 0.2665)
    padded = pad_footprint(_BODY, 0.1)
    cmd = TebPlanner(params, footprint=padded).compute_velocity(pose, Velocity2D(), plan, cm)
    assert cmd.vx == pytest.approx(0.5)
    old = replace(params, footprint_model=FootprintModel("line", (-0.1, 0.0, 0.1, 0.0)))
    with pytest.raises(NoValidControlError, match="not feasible"):
        TebPlanner(old, footprint=padded).compute_velocity(pose, Velocity2D(), plan, cm)


# BARN world_176 at 0.5 m/s: the local costmap's lethal cells within 1.5 m of the robot
# beside and behind it (the posts the band passes when it turns back), the robot's pose
# and every 4th point of navfn's plan (3.2 m)
_BEHIND_CELLS = [
    (84, 51), (84, 54), (84, 57), (85, 51), (85, 52), (85, 54), (85, 55), (85, 57), (85, 58),
    (85, 59), (86, 52), (86, 55), (86, 56), (86, 58), (86, 59), (87, 57), (87, 58), (87, 90),
    (88, 57), (88, 58), (88, 59), (88, 86), (88, 87), (88, 89), (88, 90), (88, 91), (89, 58),
    (89, 59), (89, 86), (89, 89), (90, 58), (90, 75), (91, 74), (91, 75), (91, 76), (91, 77),
    (91, 78), (91, 79), (91, 83), (91, 84), (91, 86), (91, 87), (92, 55), (92, 56), (92, 76),
    (92, 79), (92, 83), (92, 86), (93, 55), (93, 72), (94, 71), (94, 72), (94, 73), (95, 74),
    (102, 60), (103, 61),
]  # fmt: skip
_BEHIND_PLAN = [
    (4.03, 4.03), (4.02, 3.91), (4.02, 3.81), (4.01, 3.71), (4.0, 3.62), (3.98, 3.52),
    (3.96, 3.42), (3.94, 3.32), (3.91, 3.22), (3.89, 3.13), (3.87, 3.03), (3.84, 2.93),
    (3.84, 2.83), (3.84, 2.73), (3.85, 2.63), (3.84, 2.53), (3.84, 2.43), (3.83, 2.33),
    (3.85, 2.24), (3.86, 2.14), (3.92, 2.06), (3.99, 1.99), (4.07, 1.94), (4.15, 1.89),
    (4.22, 1.9), (4.32, 1.92), (4.42, 1.92), (4.52, 1.92), (4.62, 1.93), (4.71, 1.95),
    (4.81, 1.97), (4.91, 1.99),
]  # fmt: skip


def test_band_turning_back_sees_the_posts_behind_the_robot() -> None:
    """BARN world_176 at 0.5 m/s: the robot faces -x and navfn's plan turns back past
    posts behind it. TEB leaves out a cell behind the robot and farther than
    costmap_obstacles_behind_robot_dist (the Jackal file: 1.0 m), so the band, initialised
    from the plan, ran through those posts, its feasibility check (the costmap's padded
    footprint) rejected it every cycle, and the robot stood still 15 s until move_base's
    recoveries (44.8 s for the world). The cells near the plan where it runs behind the
    robot are the band's obstacles too: it turns back clear of the posts."""
    params = replace(_jackal(), max_vel_x=0.5)
    cm = Costmap2D(size_x=160, size_y=160, resolution=0.05)
    for ix, iy in _BEHIND_CELLS:
        cm.costs[iy, ix] = 254
    plan = np.column_stack([np.array(_BEHIND_PLAN), np.zeros(len(_BEHIND_PLAN))])
    pose = SE2(4.047, 4.015, -3.1139)
    teb = TebPlanner(params, footprint=pad_footprint(_BODY, 0.1))
    cmd = teb.compute_velocity(pose, Velocity2D(), plan, cm)
    assert cmd.vx > 0 and cmd.wz == pytest.approx(params.max_vel_theta)  # turning left
    assert len(teb.obstacles) == len(_BEHIND_CELLS)
    # a plan straight ahead keeps TEB's filter: the cells behind are left out
    ahead = np.column_stack([np.linspace(4.0, 2.0, 21), np.full(21, 4.0), np.zeros(21)])
    teb.compute_velocity(pose, Velocity2D(), ahead, cm)
    rel = teb.obstacles - [pose.x, pose.y]
    behind = rel @ [math.cos(pose.theta), math.sin(pose.theta)] < 0
    far = np.hypot(rel[:, 0], rel[:, 1]) > params.costmap_obstacles_behind_robot_dist
    assert not (behind & far).any() and 0 < len(teb.obstacles) < len(_BEHIND_CELLS)


def test_failure_detector_flags_a_robot_turning_back_and_forth() -> None:
    """TEB's FailureDetector: normalised commands, detection from half a buffer, mean
    speeds below the eps and more than one sign change of the angular velocity."""
    from roverlab.navigation.controllers.teb.recovery import FailureDetector

    fd = FailureDetector(10)
    wobble = [Velocity2D(0.01, 0.0, 0.3 * (-1) ** k) for k in range(10)]
    assert not fd.update(wobble[0], 0.5, 0.2, 1.5, 0.1, 0.1)  # less than half full
    results = [fd.update(c, 0.5, 0.2, 1.5, 0.1, 0.1) for c in wobble[1:]]
    assert results[3:] == [True] * 6  # from 5 of 10 entries on
    turning = FailureDetector(10)
    assert not any(turning.update(Velocity2D(0.0, 0.0, 0.3), 0.5, 0.2, 1.5, 0.1, 0.1)
                   for _ in range(10))  # fmt: skip
    driving = FailureDetector(10)
    assert not any(driving.update(Velocity2D(0.3, 0.0, 0.3 * (-1) ** k), 0.5, 0.2, 1.5, 0.1, 0.1)
                   for k in range(10))  # fmt: skip


def test_oscillation_recovery_prefers_the_current_turning_direction() -> None:
    """TebLocalPlannerROS::configureBackupModes: on an oscillation the robot's current
    turning direction is kept (EdgePreferRotDir on the band's first three turns) for
    oscillation_recovery_min_duration s, then released. The turn the band plans for a goal
    straight behind the robot follows it."""
    from roverlab.navigation.controllers.teb.recovery import OscillationRecovery
    from roverlab.navigation.move_base.plugins import make_local_planner

    teb, _, _ = make_local_planner(
        "teb_local_planner/TebLocalPlannerROS",
        {**TEB, "oscillation_filter_duration": 1.0, "oscillation_recovery_min_duration": 2.0},
        footprint=FOOT,
        controller_frequency=10.0,
    )
    params = teb.params  # type: ignore[attr-defined]
    assert params.controller_frequency == 10.0  # move_base's, as TEB reads it
    rec = OscillationRecovery(params)
    t = 0.0
    for k in range(10):  # 1 s of a wobble, the robot turning right at the end
        out = rec.update(t, Velocity2D(0.0, 0.0, 0.2 * (-1) ** k), Velocity2D(0.0, 0.0, -0.1))
        t += 0.1
    assert out == -1
    steady = Velocity2D(0.3, 0.0, 0.0)
    held = []
    while t < 5.0:
        held.append(rec.update(t, steady, Velocity2D(0.3, 0.0, 0.0)))
        t += 0.1
    assert held[0] == -1 and held[-1] == 0  # held for 2 s after the last detection
    assert 15 <= held.count(-1) <= 25
    # a goal straight behind: the band turns right; preferring left holds its first three
    # turns (TEB's EdgePreferRotDir penalises only the other direction) and the command
    plan = np.column_stack([np.linspace(1.5, 0.5, 11), np.full(11, 1.5), np.full(11, math.pi)])
    wz, first = {}, {}
    for rotdir in (1, -1):
        p = TebPlanner(params, footprint=FOOT)
        p._recovery.preferred_rotdir, p._recovery.time_last_oscillation = rotdir, 0.0
        wz[rotdir] = p.compute_velocity(SE2(1.5, 1.5, 0.0), Velocity2D(), plan, _open()).wz
        first[rotdir] = p.band.poses[3, 2]
    assert wz[-1] < -0.5 and first[-1] < -0.5
    assert wz[1] > -0.2 and first[1] > -0.1, (wz, first)


# the seeded "barn" family, world barn_0189 (mybot, NanoRobot's parameters): the local
# costmap's lethal cells within 0.7 m of the robot (cell indices of a 0.05 m grid), the
# robot stopped in front of a gap, and every 4th point of the global plan through it
_MYBOT_GAP_CELLS = [
    (29, 48), (30, 49), (32, 39), (33, 37), (33, 38), (33, 39), (34, 38), (34, 46), (35, 45),
    (35, 46), (36, 46), (36, 47), (36, 49), (36, 50), (37, 46), (37, 47), (45, 43), (45, 44),
    (45, 50), (45, 52), (46, 43), (46, 44), (46, 45), (46, 46), (46, 47), (46, 48), (46, 49),
    (46, 50), (46, 52), (47, 42), (47, 43), (47, 46), (47, 49), (48, 40), (48, 41), (49, 40),
    (49, 41), (49, 42), (49, 43), (49, 44), (50, 40), (50, 42), (50, 43), (52, 41), (53, 40),
]  # fmt: skip
_MYBOT_GAP_PLAN = [
    (2.0, 2.01), (2.0, 2.11), (2.01, 2.2), (2.04, 2.29), (2.05, 2.39), (2.05, 2.49),
    (2.05, 2.62), (2.1, 2.78), (2.14, 2.87), (2.16, 2.97), (2.15, 3.07), (2.14, 3.16),
]  # fmt: skip


def test_mybot_band_threads_a_barn_family_gap_it_can_pass() -> None:
    """world_families.py's barn_0189 (and 0122, 0137, 0151, 0191, 0201, 0211, 0257 of
    300): the plan runs through gaps that leave 0.15-0.18 m from mybot's centre to the
    cells' centres (its padded half-width is 0.11 m). TEB's obstacle edges penalise a
    distance below min_obstacle_dist + penalty_epsilon; with TEB's default 0.1 that asked
    0.30 m of the circular model (0.15 + 0.05 + 0.1), every pose in the gap was pushed
    from both sides, the band tangled (poses 0.6 m apart, some backwards) and was "not
    feasible" every cycle: the robot stood in front of the gap until move_base gave up.
    With the bundled file's penalty_epsilon the band goes through at full speed."""
    import yaml

    from roverlab.description import find_package

    path = find_package("robot_navigation") / "param" / "NanoRobot"
    params = TebParams.from_ros(
        yaml.safe_load((path / "teb_local_planner_params.yaml").read_text())["TebLocalPlannerROS"]
    )[0]
    common = yaml.safe_load((path / "costmap_common_params.yaml").read_text())
    padded = pad_footprint(np.array(common["footprint"]), common["footprint_padding"])
    cm = Costmap2D(size_x=80, size_y=80, resolution=0.05)
    for ix, iy in _MYBOT_GAP_CELLS:
        cm.costs[iy, ix] = 254
    plan = np.column_stack([np.array(_MYBOT_GAP_PLAN), np.zeros(len(_MYBOT_GAP_PLAN))])
    pose = SE2(2.001, 2.001, 1.2656)
    teb = TebPlanner(params, footprint=padded)
    cmd = teb.compute_velocity(pose, Velocity2D(), plan, cm)
    assert cmd.vx == pytest.approx(params.max_vel_x)
    poses = teb.band.poses[: params.feasibility_check_no_poses + 1]
    step = np.diff(poses[:, :2], axis=0)
    ahead = step[:, 0] * np.cos(poses[:-1, 2]) + step[:, 1] * np.sin(poses[:-1, 2])
    assert (ahead > 0).all() and np.hypot(*step.T).max() < 0.25, poses  # not tangled
    old = replace(params, penalty_epsilon=0.1)
    with pytest.raises(NoValidControlError, match="not feasible"):
        TebPlanner(old, footprint=padded).compute_velocity(pose, Velocity2D(), plan, cm)
