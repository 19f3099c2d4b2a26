"""Costmap messages: the translation table, full maps and updates, the footprint."""

from __future__ import annotations

import numpy as np

from roverlab.msgs import occupancy_grid_to_array
from roverlab.navigation.costmap import (
    COST_TRANSLATION_TABLE,
    Costmap2D,
    CostmapPublisherState,
    footprint_message,
)


def test_translation_table_is_costmap_2d_publishers() -> None:
    t = COST_TRANSLATION_TABLE
    assert (t[0], t[1], t[252], t[253], t[254], t[255]) == (0, 1, 98, 99, 100, -1)
    assert t[127] == 1 + (97 * 126) // 251
    assert (np.diff(t[1:253].astype(int)) >= 0).all()


def test_full_map_then_updates_then_full_after_the_window_moved() -> None:
    cm = Costmap2D(size_x=6, size_y=4, resolution=0.5, origin_x=1.0, origin_y=-1.0)
    cm.costs[1, 2] = 254
    state = CostmapPublisherState()
    kind, msg = state.next_message(cm, "map")
    assert kind == "full"
    grid = occupancy_grid_to_array(msg)
    assert grid[1, 2] == 100 and grid.shape == (4, 6)
    assert msg.info.origin.position.x == 1.0
    assert state.next_message(cm, "map")[0] == "none"
    cm.costs[3, 5] = 255
    state.update_bounds(4, 6, 2, 4)
    kind, upd = state.next_message(cm, "map")
    assert kind == "update"
    assert (upd.x, upd.y, upd.width, upd.height) == (4, 2, 2, 2)
    assert upd.data.tolist() == [0, 0, 0, -1]
    cm.update_origin(2.0, -1.0)
    state.update_bounds(0, 6, 0, 4)
    assert state.next_message(cm, "map")[0] == "full"


def test_footprint_message_is_a_stamped_polygon() -> None:
    msg = footprint_message([[0.0, 1.0], [1.0, 1.0], [1.0, 0.0]], "odom")
    assert msg.header.frame_id == "odom"
    assert [(p.x, p.y) for p in msg.polygon.points] == [(0.0, 1.0), (1.0, 1.0), (1.0, 0.0)]
