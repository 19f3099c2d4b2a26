"""amcl's map: the likelihood field (a distance transform), free cells, tables, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.localization.amcl import AmclMap, AmclMapError
from tests.localization.amcl.helpers import ORIGIN, RES, room_grid, room_map


def test_distance_field_is_the_exact_capped_distance_to_occupied_cells() -> None:
    m = room_map(max_dist_m=0.5)
    occ = np.argwhere(room_grid() == 100)
    rng = np.random.default_rng(0)
    for r, c in rng.integers(0, (100, 160), size=(200, 2)):
        brute = RES * math.sqrt(float(((occ - (r, c)) ** 2).sum(axis=1).min()))
        assert m.distance[r, c] == pytest.approx(min(brute, 0.5))
    assert m.distance.max() == pytest.approx(0.5)
    assert (m.distance[room_grid() == 100] == 0.0).all()


def test_free_cells_bounds_and_cells() -> None:
    m = room_map()
    assert m.free_cells.shape == (int((room_grid() == 0).sum()), 2)
    assert m.bounds == pytest.approx((-1.0, -0.5, 7.0, 4.5))
    assert m.contains(0.0, 0.0) and not m.contains(7.0, 0.0) and not m.contains(-1.01, 0.0)
    # the cell a point lies in (not amcl's round-to-nearest-corner)
    assert m.cell_of((ORIGIN[0] + 0.049, ORIGIN[1] + 0.051)).tolist() == [1, 0]
    assert m.cell_of((ORIGIN[0] - 0.001, ORIGIN[1])).tolist() == [0, -1]


def test_likelihood_tables_hold_amcls_per_beam_terms() -> None:
    m = room_map()
    table, off = m.likelihood_table(z_hit=0.95, z_rand=0.05, sigma_hit=0.2, range_max=10.0)
    d = m.distance
    pz = 0.95 * np.exp(-(d**2) / 0.08) + 0.05 / 10.0
    assert table == pytest.approx(pz**3)
    assert off == pytest.approx((0.95 * math.exp(-4.0 / 0.08) + 0.005) ** 3)
    log_table, log_off = m.log_likelihood_table(
        z_hit=0.95, z_rand=0.05, sigma_hit=0.2, range_max=10.0
    )
    assert log_table == pytest.approx(np.log(pz))
    assert log_off == pytest.approx(math.log(0.95 * math.exp(-4.0 / 0.08) + 0.005))


def test_map_without_free_cells_is_a_clear_error() -> None:
    data = np.full((20, 30), -1, dtype=np.int8)
    data[5, :] = 100
    with pytest.raises(AmclMapError, match=r"\(30 x 20 cells\) has no free cell"):
        AmclMap(data=data, resolution_m=0.05, origin_xy=(0.0, 0.0))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"data": np.zeros((0, 4), np.int8)}, "non-empty 2-D grid"),
        ({"data": np.zeros(4, np.int8)}, "non-empty 2-D grid"),
        ({"resolution_m": 0.0}, "resolution must be a positive number"),
        ({"origin_xy": (math.nan, 0.0)}, "origin must be finite"),
        ({"max_dist_m": -1.0}, "laser_likelihood_max_dist must be > 0"),
    ],
)
def test_bad_maps(kwargs: dict[str, object], message: str) -> None:
    args: dict[str, object] = {
        "data": np.zeros((4, 4), np.int8), "resolution_m": 0.05, "origin_xy": (0.0, 0.0),
    }  # fmt: skip
    args.update(kwargs)
    with pytest.raises(AmclMapError, match=message):
        AmclMap(**args)  # type: ignore[arg-type]


def test_a_map_without_obstacles_has_a_flat_field() -> None:
    m = AmclMap(data=np.zeros((5, 5), np.int8), resolution_m=0.1, origin_xy=(0, 0), max_dist_m=1.5)
    assert (m.distance == 1.5).all()
