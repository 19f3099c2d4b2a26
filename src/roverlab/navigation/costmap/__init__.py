"""costmap_2d: layered costmaps (static, obstacle, inflation layers) as pure algorithms.

* :class:`Costmap2D`: the uint8 grid with ROS's cost values;
* :class:`LayeredCostmap`: plugins updated in two steps (bounds, then costs in the window);
* :class:`StaticLayer`, :class:`ObstacleLayer`, :class:`InflationLayer`: the plugins;
* :class:`CostmapParams`: the parameters in both ROS spellings; :func:`make_layered_costmap`;
* :mod:`.publisher`: OccupancyGrid / OccupancyGridUpdate / PolygonStamped messages;
* ``roverlab.navigation.costmap.node``: ``Costmap2DROS`` and the ``costmap_2d_node`` node.
"""

from roverlab.navigation.costmap.costmap_2d import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from roverlab.navigation.costmap.footprint import (
    footprint_from_param,
    footprint_from_radius,
    footprint_radii,
    pad_footprint,
    transform_footprint,
)
from roverlab.navigation.costmap.inflation_layer import (
    InflationLayer,
    InflationLayerParams,
    compute_cost,
)
from roverlab.navigation.costmap.layered import Bounds, CostmapLayer, Layer, LayeredCostmap
from roverlab.navigation.costmap.obstacle_layer import (
    Observation,
    ObservationBuffer,
    ObservationSourceParams,
    ObstacleLayer,
    ObstacleLayerParams,
    project_scan,
)
from roverlab.navigation.costmap.params import CostmapParams, PluginSpec, make_layered_costmap
from roverlab.navigation.costmap.publisher import (
    COST_TRANSLATION_TABLE,
    CostmapPublisherState,
    costmap_to_occupancy_grid,
    costmap_update_message,
    footprint_message,
)
from roverlab.navigation.costmap.static_layer import (
    StaticLayer,
    StaticLayerParams,
    interpret_values,
)

__all__ = [
    "COST_TRANSLATION_TABLE",
    "FREE_SPACE",
    "INSCRIBED_INFLATED_OBSTACLE",
    "LETHAL_OBSTACLE",
    "NO_INFORMATION",
    "Bounds",
    "Costmap2D",
    "CostmapLayer",
    "CostmapParams",
    "CostmapPublisherState",
    "InflationLayer",
    "InflationLayerParams",
    "Layer",
    "LayeredCostmap",
    "Observation",
    "ObservationBuffer",
    "ObservationSourceParams",
    "ObstacleLayer",
    "ObstacleLayerParams",
    "PluginSpec",
    "StaticLayer",
    "StaticLayerParams",
    "compute_cost",
    "costmap_to_occupancy_grid",
    "costmap_update_message",
    "footprint_from_param",
    "footprint_from_radius",
    "footprint_message",
    "footprint_radii",
    "interpret_values",
    "make_layered_costmap",
    "pad_footprint",
    "project_scan",
    "transform_footprint",
]
