"""Costmap2D geometry, the rolling window's shift, convex polygon fill, footprints."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.navigation.costmap import (
    Costmap2D,
    footprint_from_param,
    footprint_from_radius,
    footprint_radii,
    pad_footprint,
    transform_footprint,
)
from roverlab.navigation.costmap.kernels import footprint_cost, line_cost
from roverlab.navigation.errors import CostmapError, NavigationParamsError


def test_world_to_map_truncates_and_rejects_points_off_the_map() -> None:
    cm = Costmap2D(size_x=10, size_y=10, resolution=0.5, origin_x=-1.0, origin_y=2.0)
    assert cm.world_to_map(-1.0, 2.0) == (0, 0)
    assert cm.world_to_map(0.99, 2.49) == (3, 0)
    assert cm.world_to_map(3.99, 6.99) == (9, 9)
    assert cm.world_to_map(-1.01, 3.0) is None
    assert cm.world_to_map(4.0, 3.0) is None
    assert cm.map_to_world(0, 0) == pytest.approx((-0.75, 2.25))
    assert cm.world_to_map_enforce_bounds(-50.0, 50.0) == (0, 9)


def test_update_origin_keeps_the_overlap_and_resets_the_rest() -> None:
    cm = Costmap2D(size_x=10, size_y=10, resolution=1.0, default_value=255)
    cm.costs[:] = 0
    cm.set_cost(5, 5, 254)
    cm.set_cost(1, 1, 100)
    cm.update_origin(3.4, -2.2)  # whole cells: +3 in x, -2 in y (truncated)
    assert (cm.origin_x, cm.origin_y) == (3.0, -2.0)
    assert cm.get_cost(2, 7) == 254  # world (5.5, 5.5)
    assert np.count_nonzero(cm.costs == 100) == 0  # (1.5, 1.5) left the window
    assert (cm.costs[:2, :] == 255).all() and (cm.costs[:, 7:] == 255).all()
    assert (cm.costs[2:, :7] != 255).all()


def test_convex_polygon_fill_covers_the_square_and_refuses_vertices_off_the_map() -> None:
    cm = Costmap2D(size_x=10, size_y=10, resolution=1.0)
    assert cm.set_convex_polygon_cost([[2.5, 2.5], [6.5, 2.5], [6.5, 5.5], [2.5, 5.5]], 7)
    filled = np.argwhere(cm.costs == 7)
    assert filled[:, 0].min() == 2 and filled[:, 0].max() == 5  # rows (y)
    assert filled[:, 1].min() == 2 and filled[:, 1].max() == 6  # columns (x)
    assert len(filled) == 4 * 5
    assert not cm.set_convex_polygon_cost([[2.5, 2.5], [12.0, 2.5], [6.5, 5.5]], 9)
    assert not (cm.costs == 9).any()


def test_bad_geometry_is_one_clear_error() -> None:
    with pytest.raises(CostmapError, match="resolution"):
        Costmap2D(size_x=3, size_y=3, resolution=0.0)
    with pytest.raises(CostmapError, match="width"):
        Costmap2D(size_x=0, size_y=3, resolution=0.1)


def test_footprints_from_radius_string_and_padding() -> None:
    circle = footprint_from_radius(0.2)
    assert circle.shape == (16, 2)
    inscribed, circumscribed = footprint_radii(circle)
    assert circumscribed == pytest.approx(0.2)
    assert inscribed == pytest.approx(0.2 * math.cos(math.pi / 16))
    square = footprint_from_param("[[0.1, 0.1], [-0.1, 0.1], [-0.1, -0.1], [0.1, -0.1]]")
    assert square is not None
    assert footprint_radii(square) == pytest.approx((0.1, math.hypot(0.1, 0.1)))
    assert np.allclose(pad_footprint(square, 0.05)[0], [0.15, 0.15])
    assert footprint_from_param("[]") is None
    with pytest.raises(NavigationParamsError, match="three points"):
        footprint_from_param([[0.1, 0.1], [0.2, 0.2]])
    with pytest.raises(NavigationParamsError, match="cannot read footprint"):
        footprint_from_param("[[0.1, 0.1], [")
    placed = transform_footprint(1.0, 2.0, math.pi / 2, square)
    assert placed[0] == pytest.approx([0.9, 2.1])


def test_footprint_cost_sees_every_cell_the_outline_crosses() -> None:
    """Where DWA wedged mybot in a held-out door (narrow_doors, seed 0): the footprint's
    slanted left edge crosses a corner of a door post's lethal cell. A Bresenham line
    between the vertices' cells (CostmapModel's) passes beside that cell, so the pose looked
    legal and the robot drove there; 1 cm further back the line caught it, and every motion
    was refused. The exact outline refuses the pose itself and accepts it once clear."""
    res, ox, oy = 0.05, 9.0, 0.5
    costs = np.zeros((60, 60), dtype=np.uint8)
    lethal = (int((10.42 - ox) / res), int((1.92 - oy) / res))  # cell [10.40, 10.45) x [1.90, 1.95)
    costs[lethal[1], lethal[0]] = 254
    fp = np.array([[-0.135, -0.11], [-0.135, 0.11], [0.135, 0.11], [0.135, -0.11]])
    buf = np.empty((256, 2), dtype=np.int64)
    x, y, th = 10.5415, 1.8735, 1.3280

    def bresenham_outline(px: float, py: float) -> float:
        c, s = math.cos(th), math.sin(th)
        cells = [
            (int((px + a * c - b * s - ox) / res), int((py + a * s + b * c - oy) / res))
            for a, b in fp
        ]
        return min(line_cost(costs, *cells[k], *cells[(k + 1) % 4], buf) for k in range(4))

    assert bresenham_outline(x, y) >= 0  # CostmapModel: legal
    assert bresenham_outline(x - 0.01 * math.cos(th), y - 0.01 * math.sin(th)) < 0
    assert footprint_cost(costs, res, ox, oy, x, y, th, fp, 1.0, buf) == -6.0
    # 5 cm further from the post (to the right, across the edge) the outline is clear
    assert footprint_cost(costs, res, ox, oy, x + 0.05, y, th, fp, 1.0, buf) == 0.0
