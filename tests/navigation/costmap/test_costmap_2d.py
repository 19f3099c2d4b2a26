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
