"""Static, obstacle and inflation layers, and the layered two-step update."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.navigation.costmap import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
    CostmapLayer,
    StaticLayerParams,
    compute_cost,
    interpret_values,
)
from roverlab.navigation.costmap.layered import Bounds, LayeredCostmap
from roverlab.navigation.errors import CostmapError
from tests.navigation.conftest import INFLATION, OBSTACLE, STATIC, layered


# ---------------------------------------------------------------------------- static layer
def test_interpret_values_trinary_scaled_and_unknown() -> None:
    vals = np.array([-1, 0, 50, 99, 100], dtype=np.int8)
    p = StaticLayerParams()
    assert interpret_values(vals, p).tolist() == [255, 0, 0, 0, 254]
    p = StaticLayerParams(trinary_costmap=False, track_unknown_space=False)
    assert interpret_values(vals, p).tolist() == [0, 0, 127, 251, 254]
    p = StaticLayerParams(lethal_cost_threshold=50)
    assert interpret_values(vals, p).tolist() == [255, 0, 254, 254, 254]


def test_static_layer_fills_and_locks_the_master_grid(map10: np.ndarray) -> None:
    lc = layered({"plugins": [STATIC]}, map10, res=0.5)
    lc.update_map(1.0, 1.0, 0.0)
    assert (lc.costmap.size_x, lc.costmap.size_y, lc.costmap.resolution) == (10, 10, 0.5)
    assert lc.size_locked
    assert lc.costmap.get_cost(5, 3) == LETHAL_OBSTACLE
    assert lc.costmap.get_cost(8, 8) == NO_INFORMATION
    assert lc.costmap.get_cost(0, 0) == FREE_SPACE


def test_static_layer_update_changes_only_its_window(map10: np.ndarray) -> None:
    lc = layered({"plugins": [{**STATIC}], "static_layer": {"subscribe_to_updates": True}}, map10)
    lc.update_map(1.0, 1.0, 0.0)
    lc.update_map(1.0, 1.0, 0.0)
    assert lc.bounds_cells == (0, 0, 0, 0)  # nothing new: empty window
    static = lc.plugin("static_layer")
    static.incoming_update(1, 2, 2, 1, [100, 100])  # type: ignore[attr-defined]
    lc.update_map(1.0, 1.0, 0.0)
    assert lc.costmap.get_cost(1, 2) == lc.costmap.get_cost(2, 2) == LETHAL_OBSTACLE
    x0, xn, y0, yn = lc.bounds_cells
    assert x0 <= 1 and xn >= 3 and y0 <= 2 and yn >= 3 and (xn - x0) * (yn - y0) < 100
    with pytest.raises(CostmapError, match="off the"):
        static.incoming_update(9, 9, 2, 2, [0, 0, 0, 0])  # type: ignore[attr-defined]


def test_first_map_only_ignores_later_maps(map10: np.ndarray) -> None:
    lc = layered({"plugins": [STATIC], "static_layer": {"first_map_only": True}}, map10)
    assert not lc.plugin("static_layer").incoming_map(  # type: ignore[attr-defined]
        np.zeros((4, 4), np.int8), resolution=1.0, origin_x=0.0, origin_y=0.0
    )
    assert lc.costmap.size_x == 10


def test_static_layer_in_a_rolling_window_follows_the_robot(map10: np.ndarray) -> None:
    lc = layered(
        {"rolling_window": True, "width": 4.0, "height": 4.0, "resolution": 1.0,
         "plugins": [STATIC]},
        map10,
    )  # fmt: skip
    lc.update_map(5.5, 3.5, 0.0)
    cm = lc.costmap
    # size in metres is (4 - 1 + 0.5) * 1 (costmap_2d), so the origin is 5.5 - 1.75, truncated
    assert (cm.size_x, cm.origin_x, cm.origin_y) == (4, 3.0, 1.0)
    wall = cm.world_to_map(5.5, 3.5)
    assert wall is not None and cm.get_cost(*wall) == LETHAL_OBSTACLE


# ---------------------------------------------------------------------------- combination
class _Const(CostmapLayer):
    def __init__(self, name: str, values: np.ndarray, mode: str) -> None:
        super().__init__(name)
        self.values = values
        self.mode = mode

    def update_bounds(
        self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds, now_s: float
    ) -> None:
        bounds.touch(0.0, 0.0)
        bounds.touch(2.9, 0.9)

    def update_costs(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        self.grid.costs[:] = self.values
        getattr(self, f"update_with_{self.mode}")(master, x0, y0, xn, yn)


@pytest.mark.parametrize(
    ("mode", "expected"),
    [
        ("true_overwrite", [255, 10, 200]),
        ("overwrite", [0, 10, 200]),
        ("max", [0, 100, 200]),
        ("addition", [0, 110, 252]),
    ],
)
def test_combination_rules(mode: str, expected: list[int]) -> None:
    lc = LayeredCostmap(global_frame="map", rolling_window=False, track_unknown_space=False)
    lc.resize_map(3, 1, 1.0, 0.0, 0.0)
    lc.add_plugin(_Const("base", np.array([[0, 100, 150]], np.uint8), "true_overwrite"))
    lc.add_plugin(_Const("top", np.array([[255, 10, 200]], np.uint8), mode))
    lc.update_map(0.0, 0.0, 0.0)
    assert lc.costmap.costs[0].tolist() == expected


# ---------------------------------------------------------------------------- obstacle layer
def _obstacle_costmap(**layer: object) -> LayeredCostmap:
    return layered(
        {
            "width": 10.0, "height": 10.0, "resolution": 1.0, "robot_radius": 0.3,
            "plugins": [OBSTACLE],
            "obstacle_layer": {
                "observation_sources": "scan",
                "scan": {"data_type": "LaserScan", "marking": True, "clearing": True,
                         "obstacle_range": 6.0, "raytrace_range": 8.0},
                **layer,
            },
        }
    )  # fmt: skip


def test_obstacle_layer_marks_within_range_and_height() -> None:
    lc = _obstacle_costmap()
    layer = lc.plugin("obstacle_layer")
    pts = [[3.5, 1.5, 0.2], [8.5, 1.5, 0.2], [4.5, 4.5, 2.5], [1.5, 6.5, 0.5]]
    layer.add_observation("scan", [1.5, 1.5, 0.1], pts, 0.0, 0.0)  # type: ignore[attr-defined]
    lc.update_map(1.5, 1.5, 0.0)
    cm = lc.costmap
    assert cm.get_cost(3, 1) == LETHAL_OBSTACLE
    assert cm.get_cost(8, 1) == FREE_SPACE  # 7 m from the sensor: beyond obstacle_range
    assert cm.get_cost(4, 4) == FREE_SPACE  # above the source's max_obstacle_height
    assert cm.get_cost(1, 6) == LETHAL_OBSTACLE
    assert np.count_nonzero(cm.costs == LETHAL_OBSTACLE) == 2


def test_clearing_ray_frees_cells_and_the_persistence_window() -> None:
    lc = _obstacle_costmap()
    layer = lc.plugin("obstacle_layer")
    layer.add_observation("scan", [0.5, 0.5, 0.1], [[5.5, 0.5, 0.1]], 0.0, 0.0)  # type: ignore[attr-defined]
    lc.update_map(0.5, 0.5, 0.0)
    assert lc.costmap.get_cost(5, 0) == LETHAL_OBSTACLE
    # the obstacle moved away: a longer ray through its cell clears it
    layer.add_observation("scan", [0.5, 0.5, 0.1], [[6.4, 0.5, 0.1]], 1.0, 1.0)  # type: ignore[attr-defined]
    lc.update_map(0.5, 0.5, 0.0)
    assert lc.costmap.get_cost(5, 0) == FREE_SPACE
    assert lc.costmap.get_cost(6, 0) == LETHAL_OBSTACLE
    assert len(layer.buffers["scan"].observations) == 1  # type: ignore[attr-defined]


def test_observation_persistence_and_expected_update_rate() -> None:
    lc = _obstacle_costmap(
        scan={"data_type": "LaserScan", "observation_persistence": 1.0,
              "expected_update_rate": 0.5, "clearing": False}
    )  # fmt: skip
    buf = lc.plugin("obstacle_layer").buffers["scan"]  # type: ignore[attr-defined]
    buf.buffer_points([0, 0, 0], [[1.0, 1.0, 0.1]], 0.0, 0.0)
    buf.buffer_points([0, 0, 0], [[2.0, 1.0, 0.1]], 0.8, 0.8)
    assert len(buf.get_observations()) == 2
    buf.buffer_points([0, 0, 0], [[3.0, 1.0, 0.1]], 1.5, 1.5)
    assert [o.stamp_s for o in buf.get_observations()] == [1.5, 0.8]
    assert lc.is_current(1.9)
    assert not lc.is_current(2.1)


def test_an_observation_given_as_a_function_is_made_only_when_an_update_uses_it() -> None:
    lc = _obstacle_costmap()
    layer = lc.plugin("obstacle_layer")
    made: list[float] = []

    def cloud(x: float) -> object:
        def make() -> list[list[float]]:
            made.append(x)
            return [[x, 1.5, 0.2]]

        return make

    # three scans between two updates (persistence 0): only the newest is projected
    for k, x in enumerate((3.5, 4.5, 5.5)):
        layer.add_observation("scan", [1.5, 1.5, 0.1], cloud(x), float(k), float(k))  # type: ignore[attr-defined]
    assert made == []
    lc.update_map(1.5, 1.5, 0.0)
    assert made == [5.5] and lc.costmap.get_cost(5, 1) == LETHAL_OBSTACLE
    assert lc.costmap.get_cost(3, 1) == FREE_SPACE
    lc.update_map(1.5, 1.5, 0.0)  # used again: made once
    assert made == [5.5]

    # points that cannot be made: the observation is dropped and told, the update goes on
    def broken() -> object:
        raise CostmapError("laser scan: 3 ranges but 4 angles")

    layer.add_observation("scan", [1.5, 1.5, 0.1], broken, 5.0, 5.0)  # type: ignore[attr-defined]
    lc.update_map(1.5, 1.5, 0.0)
    assert layer.sensor_warnings == ["scan dropped: laser scan: 3 ranges but 4 angles"]  # type: ignore[attr-defined]
    assert layer.buffers["scan"].observations == []  # type: ignore[attr-defined]


def test_footprint_clearing_and_overwrite_combination(map10: np.ndarray) -> None:
    values = {
        "robot_radius": 0.9, "footprint_padding": 0.0, "track_unknown_space": True,
        "plugins": [STATIC, OBSTACLE],
        "obstacle_layer": {"observation_sources": "s", "combination_method": 0,
                           "s": {"data_type": "PointCloud2", "clearing": True,
                                 "obstacle_range": 10.0, "raytrace_range": 10.0}},
    }  # fmt: skip
    lc = layered(values, map10)
    layer = lc.plugin("obstacle_layer")
    # a mark under the robot is cleared with the footprint; a ray over unknown cells
    layer.add_observation("s", [2.5, 8.5, 0.0], [[2.5, 5.5, 0.1], [8.5, 8.5, 0.1]], 0.0, 0.0)  # type: ignore[attr-defined]
    lc.update_map(2.5, 5.5, 0.0)
    cm = lc.costmap
    assert cm.get_cost(2, 5) == FREE_SPACE
    assert cm.get_cost(8, 8) == LETHAL_OBSTACLE  # overwrite: the static unknown replaced
    assert cm.get_cost(5, 8) == FREE_SPACE  # known free along the ray


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_an_observation_seen_from_a_non_finite_origin_is_refused(bad: float) -> None:
    layer = _obstacle_costmap().plugin("obstacle_layer")
    for k in range(3):
        origin = [0.5, 0.5, 0.1]
        origin[k] = bad
        with pytest.raises(CostmapError, match="sensor origin is not finite"):
            layer.add_observation("scan", origin, [[3.5, 1.5, 0.2]], 0.0, 0.0)  # type: ignore[attr-defined]


def test_obstacles_move_with_the_rolling_window() -> None:
    lc = layered(
        {"rolling_window": True, "width": 6.0, "height": 6.0, "resolution": 1.0,
         "plugins": [OBSTACLE],
         "obstacle_layer": {"observation_sources": "s", "s": {"data_type": "PointCloud2"}}}
    )  # fmt: skip
    layer = lc.plugin("obstacle_layer")
    layer.add_observation("s", [0.0, 0.0, 0.0], [[1.5, 0.5, 0.1]], 0.0, 0.0)  # type: ignore[attr-defined]
    lc.update_map(0.0, 0.0, 0.0)
    layer.buffers["s"].clear()  # type: ignore[attr-defined]
    lc.update_map(3.0, 0.0, 0.0)  # the window shifts three cells
    cell = lc.costmap.world_to_map(1.5, 0.5)
    assert cell is not None and lc.costmap.get_cost(*cell) == LETHAL_OBSTACLE
    lc.update_map(9.0, 0.0, 0.0)  # far away: the mark left the window
    assert not (lc.costmap.costs == LETHAL_OBSTACLE).any()


# ---------------------------------------------------------------------------- inflation
def test_inflation_costs_follow_costmap_2d_formula() -> None:
    grid = np.zeros((21, 21), np.int8)
    grid[10, 10] = 100
    res, radius, scale = 0.05, 0.5, 5.0
    lc = layered(
        {"robot_radius": 0.1, "footprint_padding": 0.0, "plugins": [STATIC, INFLATION],
         "inflation_layer": {"inflation_radius": radius, "cost_scaling_factor": scale}},
        grid, res,
    )  # fmt: skip
    lc.update_map(0.0, 0.0, 0.0)
    cm = lc.costmap
    inscribed = lc.inscribed_radius
    assert inscribed == pytest.approx(0.1 * math.cos(math.pi / 16))
    for dx, dy in [(0, 0), (1, 0), (1, 1), (3, 0), (4, 3), (7, 2), (10, 0)]:
        d = math.hypot(dx, dy)
        expected = compute_cost(d, res, inscribed, scale)
        assert cm.get_cost(10 + dx, 10 + dy) == expected, (dx, dy)
    assert cm.get_cost(10, 10) == LETHAL_OBSTACLE
    assert cm.get_cost(11, 10) == INSCRIBED_INFLATED_OBSTACLE
    assert compute_cost(4, res, inscribed, scale) == int(252 * math.exp(-scale * (0.2 - inscribed)))
    assert cm.get_cost(0, 0) == FREE_SPACE  # beyond the radius
    assert np.array_equal(cm.costs, cm.costs.T)  # symmetric around the obstacle


def test_inflation_matches_the_nearest_obstacle_almost_everywhere() -> None:
    rng = np.random.default_rng(3)
    grid = np.zeros((40, 40), np.int8)
    cells = rng.integers(0, 40, size=(25, 2))
    grid[cells[:, 1], cells[:, 0]] = 100
    lc = layered(
        {"robot_radius": 0.2, "footprint_padding": 0.0, "plugins": [STATIC, INFLATION],
         "inflation_layer": {"inflation_radius": 0.5, "cost_scaling_factor": 3.0}},
        grid, 0.05,
    )  # fmt: skip
    lc.update_map(0.0, 0.0, 0.0)
    ys, xs = np.nonzero(grid == 100)
    yy, xx = np.mgrid[0:40, 0:40]
    d = np.min(np.hypot(xx[..., None] - xs, yy[..., None] - ys), axis=-1)
    r = lc.plugin("inflation_layer").cell_inflation_radius  # type: ignore[attr-defined]
    ref = np.zeros_like(lc.costmap.costs)
    near = d <= r
    ref[near] = [compute_cost(v, 0.05, lc.inscribed_radius, 3.0) for v in d[near]]
    got = lc.costmap.costs
    # costmap_2d's bin order can reach a cell from a farther obstacle first (never nearer)
    assert (got.astype(int) <= ref.astype(int)).all()
    assert np.mean(got == ref) > 0.995


def test_inflation_of_unknown_cells() -> None:
    grid = np.full((9, 9), -1, np.int8)
    grid[4, 4] = 100
    base = {"robot_radius": 0.15, "footprint_padding": 0.0, "track_unknown_space": True,
            "plugins": [STATIC, INFLATION]}  # fmt: skip
    lc = layered({**base, "inflation_layer": {"inflation_radius": 0.4}}, grid, 0.1)
    lc.update_map(0.0, 0.0, 0.0)
    assert lc.costmap.get_cost(5, 4) == INSCRIBED_INFLATED_OBSTACLE
    assert lc.costmap.get_cost(7, 4) == NO_INFORMATION  # low costs do not replace unknown
    lc = layered(
        {**base, "inflation_layer": {"inflation_radius": 0.4, "inflate_unknown": True}}, grid, 0.1
    )
    lc.update_map(0.0, 0.0, 0.0)
    assert 0 < lc.costmap.get_cost(7, 4) < INSCRIBED_INFLATED_OBSTACLE


def test_inflation_window_covers_last_and_new_bounds() -> None:
    grid = np.zeros((30, 30), np.int8)
    lc = layered(
        {"plugins": [{**STATIC}, INFLATION], "static_layer": {"subscribe_to_updates": True},
         "inflation_layer": {"inflation_radius": 0.3}},
        grid, 0.1,
    )  # fmt: skip
    lc.update_map(0.0, 0.0, 0.0)
    static = lc.plugin("static_layer")
    static.incoming_update(10, 10, 1, 1, [100])  # type: ignore[attr-defined]
    lc.update_map(0.0, 0.0, 0.0)
    assert lc.costmap.get_cost(12, 10) > 0
    static.incoming_update(10, 10, 1, 1, [0])  # type: ignore[attr-defined]
    lc.update_map(0.0, 0.0, 0.0)
    assert not lc.costmap.costs.any()  # the old inflation went with the obstacle


def test_clear_area_outside_a_window_as_the_clear_costmap_recovery() -> None:
    lc = _obstacle_costmap()
    layer = lc.plugin("obstacle_layer")
    pts = [[1.5, 1.5, 0.1], [4.5, 4.5, 0.1], [5.5, 8.5, 0.1]]
    layer.add_observation("scan", [1.5, 6.5, 0.1], pts, 0.0, 0.0)  # type: ignore[attr-defined]
    lc.update_map(1.5, 6.5, 0.0)
    assert np.count_nonzero(lc.costmap.costs == LETHAL_OBSTACLE) == 3
    layer.buffers["scan"].clear()  # type: ignore[attr-defined]
    layer.clear_area(3, 3, 6, 6, False)  # type: ignore[attr-defined]  # keep cells 4..5 only
    lc.update_map(1.5, 6.5, 0.0)
    assert np.argwhere(lc.costmap.costs == LETHAL_OBSTACLE).tolist() == [[4, 4]]
    layer.clear_area(3, 3, 6, 6, True)  # type: ignore[attr-defined]
    lc.update_map(1.5, 6.5, 0.0)
    assert not (lc.costmap.costs == LETHAL_OBSTACLE).any()
