"""Ray casting benchmark: lidar rays/s, camera frames/s, occupancy-grid rays/s.

    python benchmarks/raycast.py [--seed N] [--scans N] [--frames N]

Builds a maze-like scene procedurally (a 20 m x 20 m walled square, 48 wall boxes on a
lattice = 196 segments, 20 cylindrical pillars) and prints, one figure per line,
single-threaded after warm-up (best of several repetitions):
- ``cast_2d`` rays/s, 720-beam scans from random free poses (target >= 2,000,000);
- ``cast_2d_many`` rays/s, 100 poses x 720 beams per call (a particle filter's batch);
- ``render`` 640x480 frames/s, level camera (target >= 150) and tilted 0.2 rad down;
- ``cast_grid`` rays/s on a 1000 x 1000 occupancy grid (0.05 m cells).
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from roverlab.raycast import Scene, cast_2d, cast_2d_many, cast_grid, render, scene_grid

SIZE_M = 20.0
N_BEAMS = 720
RANGE_MAX_M = 30.0


def box_segments(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    """The four faces of an axis-aligned box, counter-clockwise."""
    return [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]]


def maze_scene(rng: np.random.Generator) -> tuple[Scene, list[tuple[float, float, float, float]]]:
    """A walled square with 48 wall boxes on a 2 m lattice and 20 pillars.

    Returns:
        The scene and the boxes ``(x0, y0, x1, y1)`` (for picking free poses).
    """
    half = SIZE_M / 2
    segs = [[-half, -half, half, -half], [half, -half, half, half]]
    segs += [[half, half, -half, half], [-half, half, -half, -half]]
    boxes: list[tuple[float, float, float, float]] = []
    lattice = np.arange(-half + 2.0, half - 1.0, 2.0)
    slots = [(x, y, horiz) for x in lattice for y in lattice for horiz in (True, False)]
    for k in rng.choice(len(slots), size=48, replace=False):
        x, y, horiz = slots[k]
        b = (x, y - 0.05, x + 2.0, y + 0.05) if horiz else (x - 0.05, y, x + 0.05, y + 2.0)
        b = (b[0], b[1], min(b[2], half), min(b[3], half))
        boxes.append(b)
        segs += box_segments(*b)
    n = len(segs)
    colours = rng.integers(60, 230, size=(n, 3))
    circles = np.column_stack(
        [rng.uniform(-half + 1, half - 1, (20, 2)), rng.uniform(0.1, 0.3, 20)]
    )
    scene = Scene(
        segments=np.array(segs),
        segment_z=np.tile([0.0, 2.5], (n, 1)),
        segment_rgb=colours,
        circles=circles,
        circle_z=np.tile([0.0, 1.2], (20, 1)),
        circle_rgb=rng.integers(60, 230, size=(20, 3)),
    )
    return scene, boxes


def free_poses(
    scene: Scene,
    boxes: list[tuple[float, float, float, float]],
    n: int,
    rng: np.random.Generator,
    clearance_m: float = 0.25,
) -> NDArray[np.float64]:
    """``n`` random ``(x, y, yaw)`` at least ``clearance_m`` from every box and pillar."""
    out: list[NDArray[np.float64]] = []
    half = SIZE_M / 2 - clearance_m
    while sum(len(o) for o in out) < n:
        p = rng.uniform(-half, half, (4 * n, 2))
        ok = np.ones(len(p), dtype=bool)
        for x0, y0, x1, y1 in boxes:
            ok &= ~(
                (p[:, 0] > x0 - clearance_m)
                & (p[:, 0] < x1 + clearance_m)
                & (p[:, 1] > y0 - clearance_m)
                & (p[:, 1] < y1 + clearance_m)
            )
        c = scene.circles
        d = np.hypot(p[:, None, 0] - c[None, :, 0], p[:, None, 1] - c[None, :, 1])
        ok &= np.all(d > c[None, :, 2] + clearance_m, axis=1)
        good = p[ok]
        out.append(np.column_stack([good, rng.uniform(-math.pi, math.pi, len(good))]))
    return np.concatenate(out)[:n]


def occupancy_grid(rng: np.random.Generator, size: int = 1000) -> NDArray[np.uint8]:
    """A bordered ``size`` x ``size`` grid with random wall strips and blocks (100 = occupied)."""
    g = np.zeros((size, size), dtype=np.uint8)
    g[:2, :] = g[-2:, :] = g[:, :2] = g[:, -2:] = 100
    for _ in range(300):
        r, c = rng.integers(0, size - 60, 2)
        if rng.random() < 0.5:
            g[r : r + 2, c : c + 60] = 100
        else:
            g[r : r + 60, c : c + 2] = 100
    for _ in range(100):
        r, c = rng.integers(0, size - 10, 2)
        g[r : r + 8, c : c + 8] = 100
    return g


def best_seconds(fn: Callable[[int], object], n: int, repeats: int = 5) -> float:
    """Best wall time of ``repeats`` runs of ``fn(0..n-1)``, per call."""
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        for i in range(n):
            fn(i)
        best = min(best, (time.perf_counter() - t0) / n)
    return best


def _verdict(ok: bool) -> str:
    return "OK" if ok else "MISSED"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--scans", type=int, default=200, help="lidar scans per repetition")
    parser.add_argument("--frames", type=int, default=30, help="camera frames per repetition")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)

    scene, boxes = maze_scene(rng)
    grid = scene_grid(scene)
    print(
        f"scene: {len(scene.segments)} segments, {len(scene.circles)} circles, "
        f"grid {grid.nx}x{grid.ny} cells of {grid.cell:.2f} m, {len(grid.items)} entries"
    )
    poses = free_poses(scene, boxes, max(args.scans, 100), rng)
    rel = np.linspace(-math.pi, math.pi, N_BEAMS, endpoint=False)

    def scan(i: int) -> object:
        x, y, yaw = poses[i % len(poses)]
        return cast_2d(scene, x, y, 0.3, rel + yaw, RANGE_MAX_M)

    scan(0)
    t = best_seconds(scan, args.scans)
    hits = np.isfinite(cast_2d_many(scene, poses[:100], 0.3, rel, RANGE_MAX_M)).mean()
    rate = N_BEAMS / t
    print(
        f"cast_2d: {rate:,.0f} rays/s ({N_BEAMS}-beam scans, {hits:.0%} hits; "
        f"target >= 2,000,000: {_verdict(rate >= 2e6)})"
    )

    batch = poses[:100]
    cast_2d_many(scene, batch, 0.3, rel, RANGE_MAX_M)
    t = best_seconds(lambda i: cast_2d_many(scene, batch, 0.3, rel, RANGE_MAX_M), 3)
    print(f"cast_2d_many: {batch.shape[0] * N_BEAMS / t:,.0f} rays/s (100 poses x {N_BEAMS})")

    for pitch in (0.0, 0.2):

        def frame(i: int, pitch: float = pitch) -> object:
            x, y, yaw = poses[i % len(poses)]
            return render(
                scene, x, y, 0.5, yaw,
                hfov=1.047, width=640, height=480, near=0.1, far=20.0, pitch=pitch,
            )  # fmt: skip

        frame(0)
        t = best_seconds(frame, args.frames)
        target = f"; target >= 150: {_verdict(1 / t >= 150)}" if pitch == 0.0 else ""
        print(f"render 640x480 pitch={pitch}: {1 / t:,.1f} frames/s ({30 * t:.3f} s per "
              f"simulated second at 30 Hz{target})")  # fmt: skip

    occ = occupancy_grid(rng)
    free = np.argwhere(occ == 0)
    cells = free[rng.integers(0, len(free), 200)]
    res = 0.05

    def grid_scan(i: int) -> object:
        r, c = cells[i % len(cells)]
        return cast_grid(occ, res, (0.0, 0.0), (c + 0.5) * res, (r + 0.5) * res, rel, RANGE_MAX_M)

    grid_scan(0)
    t = best_seconds(grid_scan, args.scans)
    print(f"cast_grid: {N_BEAMS / t:,.0f} rays/s (1000x1000 grid, {RANGE_MAX_M:g} m range)")


if __name__ == "__main__":
    main()
