"""DWA's map grids: the wavefront (MapGrid::computeTargetDistance) and the plan's
resolution adjustment (MapGrid::adjustPlanResolution) against plain reference versions."""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from roverlab.geometry import SE2
from roverlab.navigation.controllers.dwa.kernels import (
    rollout,
    target_distance,
    target_distance_window,
)
from roverlab.navigation.controllers.dwa.planner import _adjust_resolution, _forward_window
from roverlab.navigation.costmap import Costmap2D


def _reference_wave(costs: np.ndarray, seeds: list[tuple[int, int]]) -> np.ndarray:
    """Breadth-first search cell by cell, as MapGrid does it."""
    h, w = costs.shape
    size = h * w
    out = np.full((h, w), size + 1.0)
    seen = np.zeros((h, w), dtype=bool)
    queue: deque[tuple[int, int]] = deque()
    for x, y in seeds:
        out[y, x] = 0.0
        seen[y, x] = True
        queue.append((x, y))
    while queue:
        x, y = queue.popleft()
        for nx, ny in ((x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)):
            if not (0 <= nx < w and 0 <= ny < h) or seen[ny, nx]:
                continue
            seen[ny, nx] = True
            if costs[ny, nx] >= 253:  # inscribed, lethal, unknown
                out[ny, nx] = size
                continue
            out[ny, nx] = out[y, x] + 1.0
            queue.append((nx, ny))
    return out


def test_target_distance_is_the_breadth_first_wave() -> None:
    rng = np.random.default_rng(3)
    values = np.array([0, 40, 252, 253, 254, 255], dtype=np.uint8)
    for _ in range(40):
        h, w = (int(v) for v in rng.integers(1, 25, 2))
        costs = rng.choice(values, size=(h, w), p=[0.55, 0.2, 0.05, 0.07, 0.08, 0.05])
        n = int(rng.integers(1, 4))
        seeds = [(int(rng.integers(0, w)), int(rng.integers(0, h))) for _ in range(n)]
        out = np.empty((h, w))
        target_distance(costs, np.array(seeds, dtype=np.int64), out)
        np.testing.assert_array_equal(out, _reference_wave(costs, seeds))


def test_the_wave_stopped_at_a_window_has_the_final_values_inside_it() -> None:
    rng = np.random.default_rng(5)
    values = np.array([0, 40, 252, 253, 254, 255], dtype=np.uint8)
    stopped = 0
    for _ in range(300):
        h, w = (int(v) for v in rng.integers(1, 40, 2))
        sparse = rng.random() < 0.7
        p = [0.7, 0.15, 0.03, 0.04, 0.05, 0.03] if sparse else [0.55, 0.2, 0.05, 0.07, 0.08, 0.05]
        costs = rng.choice(values, size=(h, w), p=p)
        n = int(rng.integers(1, 6))
        seeds = [(int(rng.integers(0, w)), int(rng.integers(0, h))) for _ in range(n)]
        x0, x1 = sorted(int(v) for v in rng.integers(-3, w + 3, 2))
        y0, y1 = sorted(int(v) for v in rng.integers(-3, h + 3, 2))
        x1, y1 = max(x1, 0), max(y1, 0)  # the window overlaps the grid
        out = np.empty((h, w))
        ended = target_distance_window(
            costs, np.array(seeds, dtype=np.int64), out, np.array([x0, y0, x1, y1])
        )
        ref = _reference_wave(costs, seeds)
        cx0, cy0, cx1, cy1 = max(x0, 0), max(y0, 0), min(x1, w - 1), min(y1, h - 1)
        inside = ref[cy0 : cy1 + 1, cx0 : cx1 + 1]
        np.testing.assert_array_equal(out[cy0 : cy1 + 1, cx0 : cx1 + 1], inside)
        if ended:
            np.testing.assert_array_equal(out, ref)
        else:
            stopped += 1
    assert stopped > 50  # the wave did stop early in many of the cases


def test_adjust_resolution_inserts_even_points_up_to_the_resolution() -> None:
    rng = np.random.default_rng(4)
    res = 0.05
    plan = np.cumsum(rng.normal(scale=0.06, size=(60, 3)), axis=0)
    out = _adjust_resolution(plan, res)
    gaps = np.hypot(*np.diff(plan[:, :2], axis=0).T)
    steps = [math.ceil(d / res) if d > res else 1 for d in gaps]
    at = np.concatenate([[0], np.cumsum(steps)])
    assert len(out) == at[-1] + 1
    np.testing.assert_array_equal(out[at], plan[:, :2])  # every plan point, unchanged
    spacing = np.hypot(*np.diff(out, axis=0).T)
    assert spacing.max() <= res + 1e-12
    for i, k in enumerate(steps):  # the inserted points split each segment evenly
        np.testing.assert_allclose(spacing[at[i] : at[i + 1]], gaps[i] / k, rtol=1e-9)
    assert _adjust_resolution(plan[:1], res).shape == (1, 2)


def test_the_forward_window_holds_every_cell_a_forward_rollout_reads() -> None:
    """With constant velocities, vx >= 0, no lateral motion and at most half a turn over
    sim_time, the grid critics read (every pose's cell, the last goal-front point's)
    only inside the cut window: the cut is a bound, not a guess."""
    rng = np.random.default_rng(9)
    cm = Costmap2D(size_x=200, size_y=200, resolution=0.05, origin_x=-5.0, origin_y=-5.0)
    acc = np.array([2.5, 0.0, 3.2])
    traj = np.empty((4000, 5))
    cut = 0
    for _ in range(300):
        sim_time = float(rng.uniform(0.5, 3.0))
        max_th = math.pi / sim_time * float(rng.uniform(0.3, 1.0))
        v_max, fpd = float(rng.uniform(0.1, 1.0)), float(rng.uniform(0.0, 0.5))
        pose = SE2(*rng.uniform(-2, 2, 2), float(rng.uniform(-math.pi, math.pi)))
        reach = v_max * sim_time + fpd
        r = math.ceil(reach / cm.resolution) + 2
        cx, cy = math.floor((pose.x + 5.0) / 0.05), math.floor((pose.y + 5.0) / 0.05)
        square = np.array([cx - r, cy - r, cx + r, cy + r], dtype=np.int64)
        win = _forward_window(pose, cm, reach, fpd, square)
        cut += int((win != square).any())
        for vx, vth in rng.uniform((0.0, -max_th), (v_max, max_th), (20, 2)):
            num, _, _ = rollout(
                pose.as_array(), np.zeros(3), np.array([vx, 0.0, vth]), sim_time, 0.025,
                0.1, False, acc, 0.0, traj,
            )  # fmt: skip
            pts = [traj[:num, :2], traj[num - 1 : num, :2] + fpd * traj[num - 1 : num, 3:5]]
            for x, y in np.vstack(pts):
                mx, my = int((x + 5.0) / 0.05), int((y + 5.0) / 0.05)
                assert win[0] <= mx <= win[2] and win[1] <= my <= win[3]
    assert cut > 200  # the window was cut in most cases
