"""DWA's compiled scoring against plain reference versions: the speed-ups of
``score_rollouts`` (one pass for the grid critics, the footprint cost reused while a pose's
cells do not change, the early break along a trajectory) and of the footprint cost must
choose, and cost, exactly what the straightforward critics of base_local_planner do."""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.controllers import DWAParams, DWAPlanner, Velocity2D
from roverlab.navigation.controllers.dwa.kernels import (
    _rollout_cap,
    first_known_stretch,
    sample_grid,
)
from roverlab.navigation.controllers.dwa.planner import _adjust_resolution
from roverlab.navigation.controllers.dwa.rollouts import rollout, shared_rollout
from roverlab.navigation.costmap import Costmap2D
from roverlab.navigation.costmap.footprint_kernels import footprint_cost
from roverlab.navigation.costmap.kernels import bresenham
from roverlab.navigation.errors import NoValidControlError

BOX = np.array([[-0.2, -0.15], [-0.2, 0.15], [0.2, 0.15], [0.2, -0.15]])


def _reference_footprint_cost(
    costs: np.ndarray, res: float, ox: float, oy: float, pose: tuple[float, float, float],
    fp: np.ndarray, scale: float,
) -> float:  # fmt: skip
    """CostmapModel::footprintCost, cell by cell."""
    h, w = costs.shape
    x, y, th = pose
    if x < ox or y < oy or int((x - ox) / res) >= w or int((y - oy) / res) >= h:
        return -6.0
    center = float(costs[int((y - oy) / res), int((x - ox) / res)])
    if len(fp) < 3:
        return -6.0 if center >= 253 else center
    cells = []
    for vx, vy in fp:
        wx = x + scale * (vx * math.cos(th) - vy * math.sin(th))
        wy = y + scale * (vx * math.sin(th) + vy * math.cos(th))
        if wx < ox or wy < oy:
            return -6.0
        mx, my = int((wx - ox) / res), int((wy - oy) / res)
        if mx >= w or my >= h:
            return -6.0
        cells.append((mx, my))
    best = center
    buf = np.empty((w + h + 4, 2), dtype=np.int64)
    for k in range(len(cells)):
        (x0, y0), (x1, y1) = cells[k], cells[(k + 1) % len(cells)]
        n = bresenham(x0, y0, x1, y1, 1 << 30, buf)
        for mx, my in buf[:n]:
            c = costs[my, mx]
            if c in (254, 255):
                return -6.0
            best = max(best, float(c))
    return best


def _reference_rollout(
    pose: SE2, v: np.ndarray, p: DWAParams, extra: float
) -> tuple[list[tuple[float, float, float]], int]:
    """SimpleTrajectoryGenerator with DWA's constant velocity: the poses and ``num``."""
    vmag = math.hypot(v[0], v[1])
    num = math.ceil(
        max(
            vmag * p.sim_time / p.sim_granularity,
            abs(v[2]) * p.sim_time / p.angular_sim_granularity,
        )
    )
    if num == 0:
        return [], 0
    dt = p.sim_time / num
    steps = num + (math.ceil(extra / dt - 1e-9) if extra > 0 else 0)
    x, y, th = pose.x, pose.y, pose.theta
    out = []
    for _ in range(steps):
        out.append((x, y, th))
        x += (v[0] * math.cos(th) + v[1] * math.cos(math.pi / 2 + th)) * dt
        y += (v[0] * math.sin(th) + v[1] * math.sin(math.pi / 2 + th)) * dt
        th += v[2] * dt
    return out, num


def _reference_cost(dwa: DWAPlanner, pose: SE2, v: np.ndarray, cm: Costmap2D) -> float:
    """Every critic of DWAPlanner in turn, each over every point, as ROS scores one
    trajectory (the oscillation flags clear)."""
    p = dwa.params
    if math.hypot(v[0], v[1]) + 1e-4 < p.min_vel_trans and abs(v[2]) + 1e-4 < p.min_vel_theta:
        return -100.0
    if math.hypot(v[0], v[1]) - 1e-4 > p.max_vel_trans:
        return -100.0
    traj, num = _reference_rollout(pose, v, p, 0.0)
    if num == 0:
        return -100.0
    path, goal, front = dwa._grids
    occ, goal_s, align_s, path_s, _, twirl, fpd = dwa._scales
    size = float(cm.size_x * cm.size_y)
    total = 0.0
    for grid, scale, shift, strict in (
        (front, goal_s, fpd, False), (path, align_s, fpd, False),
        (path, path_s, 0.0, True), (goal, goal_s, 0.0, True),
    ):  # fmt: skip
        if scale == 0.0:
            continue
        value = 0.0
        for x, y, th in traj[:num]:
            px, py = x + shift * math.cos(th), y + shift * math.sin(th)
            if px < cm.origin_x or py < cm.origin_y:
                return -4.0
            mx, my = (
                int((px - cm.origin_x) / cm.resolution),
                int((py - cm.origin_y) / cm.resolution),
            )
            if mx >= cm.size_x or my >= cm.size_y:
                return -4.0
            value = float(grid[my, mx])
            if strict and value == size:
                return -3.0
            if strict and value == size + 1.0:
                return -2.0
        if value != 0.0:
            total += value * scale
    if twirl != 0.0 and v[2] != 0.0:
        total += abs(v[2]) * twirl
    speed = math.hypot(v[0], v[1])
    grow = 1.0
    if speed > p.scaling_speed and p.max_vel_trans > p.scaling_speed:
        grow = (
            p.max_scaling_factor * (speed - p.scaling_speed) / (p.max_vel_trans - p.scaling_speed)
            + 1.0
        )
    full, _ = _reference_rollout(pose, v, p, p.stop_time_buffer)
    oc = 0.0
    for i, point in enumerate(full):
        fc = _reference_footprint_cost(
            cm.costs, cm.resolution, cm.origin_x, cm.origin_y, point, dwa.footprint, grow
        )
        if fc < 0:
            return fc
        if i < num:
            oc = oc + fc if p.sum_scores else max(oc, fc)
    return total + oc * occ


@pytest.mark.parametrize("fp", [BOX, np.zeros((0, 2))], ids=["polygon", "circle"])
def test_scoring_costs_every_sample_as_the_plain_critics_do(
    dwa_params: DWAParams, fp: np.ndarray
) -> None:
    rng = np.random.default_rng(5)
    checked = 0
    seen: set[float] = set()
    kinds = ("clutter", "edge", "walled in", "goal walled in", "clutter")
    for trial, kind in enumerate(kinds):
        cm = Costmap2D(size_x=60, size_y=60, resolution=0.05)
        cells = rng.integers(0, 60, size=(40, 2))
        cm.costs[cells[:, 1], cells[:, 0]] = rng.choice([254, 253, 200, 90, 255], size=40)
        dwa = DWAPlanner(dwa_params, footprint=fp)
        pose = SE2(1.5, 1.5, float(rng.uniform(-3, 3)))
        plan = np.array([[1.5, 1.5, 0.0], [2.2, 1.9, 0.0], [2.9, 2.8, 0.0]])
        if kind == "edge":  # the nose point leaves the map: -4
            pose = SE2(0.25, 1.5, math.pi - 0.3)
            plan = np.array([[0.25, 1.5, 0.0], [0.6, 1.5, 0.0], [1.5, 1.5, 0.0]])
        elif kind == "walled in":  # a ring the waves from the plan cannot cross: -2
            plan = np.array([[2.4, 1.5, 0.0], [2.9, 2.8, 0.0]])
            cm.costs[16:45, 16:45] = 0
            cm.costs[18:43, 18] = cm.costs[18:43, 42] = 253
            cm.costs[18, 18:43] = cm.costs[42, 18:43] = 253
        elif kind == "goal walled in":  # the goal's wave fails first, the path's later
            plan = np.array([[1.5, 1.5, 0.0], [2.1, 2.1, 0.0], [2.6, 2.6, 0.0]])
            cm.costs[48:57, 48] = cm.costs[48:57, 56] = 253
            cm.costs[48, 48:57] = cm.costs[56, 48:57] = 253
            cm.costs[rng.integers(25, 40, 30), rng.integers(25, 40, 30)] = 253
        twist = Velocity2D(0.1, 0.0, float(rng.uniform(-0.5, 0.5)))
        with contextlib.suppress(NoValidControlError):  # sets up the grids either way
            dwa.compute_velocity(pose, twist, plan, cm)
        samples = dwa._sample_velocities(pose, twist)
        best, full = dwa._score(pose, twist, samples, cm, dwa._only, prune=False)
        ref = [_reference_cost(dwa, pose, v, cm) for v in samples]
        np.testing.assert_array_equal(full, ref, err_msg=f"trial {trial}")
        seen.update(c for c in ref if c < 0)
        valid = np.flatnonzero(full >= 0)
        assert best == (valid[np.argmin(full[valid])] if len(valid) else -1)
        # pruned: the same choice, every other valid sample's cost a lower bound of its own
        pbest, pruned = dwa._score(pose, twist, samples, cm, dwa._only, prune=True)
        assert pbest == best and (best < 0 or pruned[best] == full[best])
        assert (pruned[valid] <= full[valid]).all()
        checked += len(valid)
    assert checked > 100  # enough valid samples were compared
    assert {-100.0, -6.0, -4.0, -3.0, -2.0} <= seen or len(fp) < 3


def test_footprint_cost_is_the_cell_by_cell_outline_cost() -> None:
    rng = np.random.default_rng(6)
    costs = rng.choice(np.array([0, 50, 200, 253, 254, 255], dtype=np.uint8), size=(40, 50),
                       p=[0.6, 0.2, 0.1, 0.05, 0.03, 0.02])  # fmt: skip
    buf = np.empty((200, 2), dtype=np.int64)
    pentagon = np.array([[0.3, 0.0], [-0.2, 0.2], [-0.25, -0.1], [0.0, -0.3], [0.2, -0.2]])
    seen = set()
    for _ in range(1500):
        pose = (
            float(rng.uniform(-0.2, 2.7)),
            float(rng.uniform(-0.2, 2.2)),
            float(rng.uniform(-7, 7)),
        )
        for fp in (BOX, pentagon, np.zeros((0, 2))):
            scale = 1.0 if rng.random() < 0.5 else float(rng.uniform(1.0, 1.6))
            got = footprint_cost(costs, 0.05, 0.0, 0.0, *pose, fp, scale, buf)
            want = _reference_footprint_cost(costs, 0.05, 0.0, 0.0, pose, fp, scale)
            assert got == want, (pose, len(fp), scale)
            seen.add(got)
    assert {-6.0, 0.0, 50.0, 200.0} <= seen


def _reference_stretch(plan: np.ndarray, cm: Costmap2D) -> np.ndarray:
    """The numpy version: the plan adjusted to the resolution, each point looked up."""
    pts = _adjust_resolution(plan, cm.resolution)
    cells = np.floor((pts - [cm.origin_x, cm.origin_y]) / cm.resolution).astype(np.int64)
    ok = (pts[:, 0] >= cm.origin_x) & (pts[:, 1] >= cm.origin_y)
    ok &= (cells[:, 0] < cm.size_x) & (cells[:, 1] < cm.size_y)
    ok[ok] = cm.costs[cells[ok, 1], cells[ok, 0]] != 255
    idx = np.flatnonzero(ok)
    if len(idx) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    stop = np.flatnonzero(~ok[idx[0] :])
    return cells[idx[0] : idx[0] + (int(stop[0]) if len(stop) else len(ok))]


def test_first_known_stretch_is_the_adjusted_plan_looked_up() -> None:
    rng = np.random.default_rng(8)
    cm = Costmap2D(size_x=50, size_y=40, resolution=0.05, origin_x=-0.3, origin_y=0.2)
    cm.costs[rng.integers(0, 40, 300), rng.integers(0, 50, 300)] = 255
    lengths = set()
    for _ in range(200):
        n = int(rng.integers(1, 30))
        plan = np.cumsum(rng.normal(scale=0.12, size=(n, 3)), axis=0) + np.array([0.9, 1.1, 0.0])
        got = first_known_stretch(np.ascontiguousarray(plan[:, :2]), cm.costs, 0.05, -0.3, 0.2)
        want = _reference_stretch(plan, cm)
        np.testing.assert_array_equal(got, want)
        lengths.add(min(len(want), 2))
    assert lengths == {0, 1, 2}  # none known, a single cell and longer stretches all met


@pytest.mark.parametrize("continued", [False, True])
def test_rollouts_sharing_their_headings_are_the_plain_rollouts_bit_for_bit(
    continued: bool,
) -> None:
    """score_rollouts computes a heading sequence once for every sample with the same
    angular velocity and step count: each trajectory must still be rollout's, bit for bit
    (with and without continued acceleration, lateral samples rolled out plainly)."""
    rng = np.random.default_rng(8)
    gen = np.array([1.7, 0.025, 0.1, 0.0, 0.55, 0.0, 0.2])
    acc = np.array([2.5, 1.0, 3.2])
    for trial in range(20):
        vx = np.round(rng.uniform(-0.2, 0.55, 5), 3)
        vth = np.round(rng.uniform(-1.0, 1.0, 7), 3)
        vy = [0.0, 0.1] if trial % 4 == 3 else [0.0]
        samples = np.array([(x, y, th) for x in vx for y in vy for th in vth] + [(0.0, 0.0, 0.0)])
        pos = np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-math.pi, math.pi)])
        vel = np.array([rng.uniform(0, 0.5), 0.05 if trial % 5 == 4 else 0.0, rng.uniform(-1, 1)])
        cap = 8 + max(_rollout_cap(s[0], s[1], s[2], gen) for s in samples)
        keys, nkeys = np.empty((len(samples), 2)), np.zeros(1, dtype=np.int64)
        heads = np.empty((len(samples), cap, 3))
        for extra_time in (0.0, gen[6]):
            for k in rng.permutation(len(samples)):
                got = np.full((cap, 5), np.nan)
                want = np.full((cap, 5), np.nan)
                n1 = shared_rollout(
                    k, samples, pos, vel, gen, acc, continued, extra_time, keys, nkeys, heads,
                    got,
                )  # fmt: skip
                n2 = rollout(pos, vel, samples[k], *gen[:3], continued, acc, extra_time, want)
                assert n1 == n2[:2]
                m = n1[0] + n1[1]
                assert got[:m].tobytes() == want[:m].tobytes()
        if not (continued and vel[1] != 0.0):  # else every sample is rolled out plainly
            assert 0 < nkeys[0] < len(samples)  # headings were shared


def test_the_sample_grid_is_every_combination_theta_fastest() -> None:
    """The compiled sample grid against numpy's repeat / tile layout of the samples."""
    rng = np.random.default_rng(2)
    for nx, ny, nth in ((1, 1, 1), (6, 1, 20), (3, 4, 5)):
        xs, ys, ths = rng.normal(size=nx), rng.normal(size=ny), rng.normal(size=nth)
        want = np.column_stack(
            [np.repeat(xs, ny * nth), np.tile(np.repeat(ys, nth), nx), np.tile(ths, nx * ny)]
        )
        assert sample_grid(xs, ys, ths).tobytes() == want.tobytes()
