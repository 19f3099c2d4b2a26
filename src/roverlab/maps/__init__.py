"""Occupancy grids and map_server map files: the shared mapping layer.

* :mod:`.grid`: :class:`LogOddsGrid` and :class:`CountGrid`, occupancy grids that integrate
  laser scans with a compiled ray tracer and grow as a SLAM map needs;
* :mod:`.raytrace`: that ray tracer and the compiled kernels that apply a scan to a grid;
* :mod:`.map_io`: map_server's YAML + PGM/PNG maps, read with map_server's exact pixel
  rules (trinary, scale, raw, negate, alpha) and written byte for byte as map_saver does;
* :mod:`.node`: the ``map_server`` and ``map_saver`` nodes (import them from
  ``roverlab.maps.node``: this package itself stays free of the runtime);
* ``roverlab map server | save | info`` is :mod:`roverlab.cli.maps`.

Every error is a :class:`MapError` (a :class:`roverlab.errors.RoverlabError`).
"""

from roverlab.maps.errors import GridError, MapError
from roverlab.maps.grid import CountGrid, LogOddsGrid, ScanRays, trace_cells
from roverlab.maps.map_io import (
    CellCounts,
    ImageFormat,
    MapInfo,
    MapMode,
    OccupancyMap,
    SavedMap,
    cell_counts,
    check_save_thresholds,
    format_map_yaml,
    image_to_occupancy,
    load_map,
    occupancy_to_image,
    pgm_bytes,
    read_image_pixels,
    read_map_yaml,
    save_map,
    save_occupancy_grid,
    yaw_of_quaternion,
)

__all__ = [
    "CellCounts",
    "CountGrid",
    "GridError",
    "ImageFormat",
    "LogOddsGrid",
    "MapError",
    "MapInfo",
    "MapMode",
    "OccupancyMap",
    "SavedMap",
    "ScanRays",
    "cell_counts",
    "check_save_thresholds",
    "format_map_yaml",
    "image_to_occupancy",
    "load_map",
    "occupancy_to_image",
    "pgm_bytes",
    "read_image_pixels",
    "read_map_yaml",
    "save_map",
    "save_occupancy_grid",
    "trace_cells",
    "yaw_of_quaternion",
]
