"""A costmap's parameters, read from either spelling ROS 1 tutorials use.

*Plugins* (hydro and later)::

    plugins:
      - {name: static_layer,    type: "costmap_2d::StaticLayer"}
      - {name: obstacle_layer,  type: "costmap_2d::ObstacleLayer"}
      - {name: inflation_layer, type: "costmap_2d::InflationLayer"}
    obstacle_layer: {observation_sources: scan, scan: {data_type: LaserScan, ...}}

*Pre-hydro* (no ``plugins``): ``static_map: true`` adds a static layer, an obstacle layer
(``map_type: voxel`` -> a VoxelLayer) and an inflation layer always follow, and the
top-level ``observation_sources`` with each source's parameters, ``obstacle_range``,
``inflation_radius``, ... move into them (costmap_2d's ``loadOldParameters``). With
``plugins``, the same top-level names are copied into each layer of the matching type,
replacing the layer's own value (costmap_2d's ``copyParentParameters``).

:meth:`CostmapParams.from_ros` takes the parameters under the costmap's namespace as a
flat ``{"obstacle_layer/scan/topic": ...}`` mapping (nested mappings are flattened too)
and returns the parameters and warnings. A ``VoxelLayer`` is run as an obstacle layer (its
voxel parameters are accepted and ignored with a warning); an unknown plugin type or a bad
value is an error naming it; an unknown name is a warning naming it (ROS ignores it).

The obstacle layer's height filter and ranges are looked up as ROS's ``searchParam``
does, from the source up: a source's ``min/max_obstacle_height``, ``obstacle_range`` and
``raytrace_range`` default to the layer's, which default to the costmap's top-level ones
(ROS 1 reads ``min_obstacle_height`` per source only; packages that set it in the costmap
namespace, as a ROS 1 book's fake-robot demo does, get it applied here).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.navigation.costmap.footprint import (
    footprint_from_param,
    footprint_from_radius,
    pad_footprint,
)
from roverlab.navigation.costmap.inflation_layer import InflationLayer, InflationLayerParams
from roverlab.navigation.costmap.layered import Layer, LayeredCostmap
from roverlab.navigation.costmap.obstacle_layer import (
    ObservationSourceParams,
    ObstacleLayer,
    ObstacleLayerParams,
)
from roverlab.navigation.costmap.static_layer import StaticLayer, StaticLayerParams
from roverlab.navigation.errors import NavigationParamsError
from roverlab.navigation.params import build_params, check, flatten_ros, unknown_warning

__all__ = ["CostmapParams", "LayerParams", "PluginSpec", "make_layered_costmap"]

LayerParams = StaticLayerParams | ObstacleLayerParams | InflationLayerParams

STATIC = "costmap_2d::StaticLayer"
OBSTACLE = "costmap_2d::ObstacleLayer"
VOXEL = "costmap_2d::VoxelLayer"
INFLATION = "costmap_2d::InflationLayer"
_TYPES = (STATIC, OBSTACLE, VOXEL, INFLATION)

# costmap_2d's copyParentParameters / loadOldParameters, by plugin type
_PARENT_KEYS = {
    STATIC: ("map_topic", "unknown_cost_value", "lethal_cost_threshold", "track_unknown_space"),
    VOXEL: (
        "origin_z",
        "z_resolution",
        "z_voxels",
        "mark_threshold",
        "unknown_threshold",
        "publish_voxel_map",
    ),
    OBSTACLE: (
        "min_obstacle_height",
        "max_obstacle_height",
        "raytrace_range",
        "obstacle_range",
        "track_unknown_space",
    ),
    INFLATION: ("cost_scaling_factor", "inflation_radius"),
}
_VOXEL_ONLY = frozenset(_PARENT_KEYS[VOXEL]) | {"max_obstacle_height_voxel"}
_SOURCE_KEYS = frozenset(f.name for f in fields(ObservationSourceParams)) - {"name"}
_OBSTACLE_LAYER_KEYS = frozenset(
    {
        "enabled",
        "track_unknown_space",
        "max_obstacle_height",
        "min_obstacle_height",
        "transform_tolerance",
        "footprint_clearing_enabled",
        "combination_method",
        "observation_sources",
        "obstacle_range",
        "raytrace_range",
    }
)
# accepted by costmap_2d, no effect in roverlab
_IGNORED_TOP = frozenset({"save_debug_pgm", "publish_voxel_map"})


def _canonical_type(type_: object, where: str) -> str:
    if not isinstance(type_, str):
        raise NavigationParamsError(f"{where}: plugin type must be a string, got {type_!r}")
    t = type_.strip().replace("/", "::")
    if t.startswith("nav2_costmap_2d::"):
        t = "costmap_2d::" + t.split("::", 1)[1]
    if t not in _TYPES:
        raise NavigationParamsError(
            f"{where}: unknown costmap plugin type {type_!r} (roverlab has {', '.join(_TYPES)})"
        )
    return t


@dataclass(frozen=True, slots=True)
class PluginSpec:
    """One entry of ``plugins``: its name, ROS type and parsed parameters."""

    name: str
    type: str
    params: LayerParams


@dataclass(frozen=True, slots=True, kw_only=True)
class CostmapParams:
    """Costmap2DROS's parameters (ROS names and defaults) and its plugins.

    ``footprint`` is the polygon given (None: a 16-gon of ``robot_radius``).
    """

    global_frame: str = "map"
    robot_base_frame: str = "base_link"
    transform_tolerance: float = 0.3
    update_frequency: float = 5.0
    publish_frequency: float = 0.0
    rolling_window: bool = False
    always_send_full_costmap: bool = False
    track_unknown_space: bool = False
    width: float = 10.0
    height: float = 10.0
    resolution: float = 0.05
    origin_x: float = 0.0
    origin_y: float = 0.0
    footprint: Any = None
    robot_radius: float = 0.46
    footprint_padding: float = 0.01
    footprint_topic: str = "footprint"
    published_footprint_topic: str = "footprint"
    plugins: tuple[PluginSpec, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        check(bool(self.global_frame), "costmap: global_frame must not be empty")
        check(bool(self.robot_base_frame), "costmap: robot_base_frame must not be empty")
        check(self.transform_tolerance >= 0, "costmap: transform_tolerance must be >= 0")
        check(self.update_frequency >= 0, "costmap: update_frequency must be >= 0")
        check(self.publish_frequency >= 0, "costmap: publish_frequency must be >= 0")
        check(self.resolution > 0, f"costmap: resolution must be > 0, got {self.resolution}")
        check(self.width > 0, f"costmap: width must be > 0 m, got {self.width}")
        check(self.height > 0, f"costmap: height must be > 0 m, got {self.height}")
        check(self.robot_radius >= 0, "costmap: robot_radius must be >= 0")
        check(self.footprint_padding >= 0, "costmap: footprint_padding must be >= 0")
        fp = footprint_from_param(self.footprint, where="costmap") if self.footprint else None
        object.__setattr__(self, "footprint", None if fp is None else tuple(map(tuple, fp)))
        names = [p.name for p in self.plugins]
        check(len(set(names)) == len(names), "costmap: a plugin name is listed twice")

    @property
    def size_cells(self) -> tuple[int, int]:
        """``(size_x, size_y)``: ``width / resolution`` and ``height / resolution``."""
        return int(self.width / self.resolution), int(self.height / self.resolution)

    def unpadded_footprint(self) -> NDArray[np.float64]:
        """The footprint polygon before padding, ``(N, 2)`` m."""
        if self.footprint is not None:
            return np.asarray(self.footprint, dtype=np.float64)
        return footprint_from_radius(self.robot_radius)

    def padded_footprint(self) -> NDArray[np.float64]:
        """The footprint the costmap uses (padded by ``footprint_padding``)."""
        return pad_footprint(self.unpadded_footprint(), self.footprint_padding)

    @classmethod
    def from_ros(
        cls, values: Mapping[str, Any], *, name: str = "costmap"
    ) -> tuple[CostmapParams, tuple[str, ...]]:
        """Parse the parameters under a costmap's namespace (see the module docstring).

        Raises:
            NavigationParamsError: an unknown name, plugin type or a bad value.
        """
        return _parse(flatten_ros(values), name)


def _split(flat: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
    top: dict[str, Any] = {}
    spaces: dict[str, dict[str, Any]] = {}
    for key, value in flat.items():
        head, sep, rest = key.partition("/")
        if sep:
            spaces.setdefault(head, {})[rest] = value
        else:
            top[key] = value
    return top, spaces


def _old_plugins(
    top: dict[str, Any], spaces: dict[str, dict[str, Any]], name: str, warnings: list[str]
) -> list[tuple[str, str]]:
    """costmap_2d's ``loadOldParameters``: move top-level names into the layers."""
    warnings.append(f'{name}: Parameter "plugins" not provided, loading pre-Hydro parameters')
    plugins: list[tuple[str, str]] = []

    def move(to: str, key: str, delete: bool = True) -> None:
        if key in top:
            spaces.setdefault(to, {})[key] = top.pop(key) if delete else top[key]

    static_map = top.pop("static_map", False)
    if not isinstance(static_map, bool):
        raise NavigationParamsError(f"{name}: static_map must be true or false, got {static_map!r}")
    if static_map:
        plugins.append(("static_layer", STATIC))
        for key in ("map_topic", "unknown_cost_value", "lethal_cost_threshold"):
            move("static_layer", key)
        move("static_layer", "track_unknown_space", delete=False)
    map_type = top.pop("map_type", "costmap")
    if map_type == "voxel":
        plugins.append(("obstacle_layer", VOXEL))
        for key in _PARENT_KEYS[VOXEL]:
            move("obstacle_layer", key)
    elif map_type == "costmap":
        plugins.append(("obstacle_layer", OBSTACLE))
    else:
        raise NavigationParamsError(f"{name}: map_type must be costmap or voxel, got {map_type!r}")
    for key in ("min_obstacle_height", "max_obstacle_height", "raytrace_range", "obstacle_range"):
        move("obstacle_layer", key)
    move("obstacle_layer", "track_unknown_space", delete=False)
    sources = top.get("observation_sources", "")
    if not isinstance(sources, str):
        raise NavigationParamsError(f"{name}: observation_sources must be a string of names")
    for src in sources.split():
        if src in spaces:
            layer = spaces.setdefault("obstacle_layer", {})
            for k, v in spaces.pop(src).items():
                layer[f"{src}/{k}"] = v
    move("obstacle_layer", "observation_sources")
    plugins.append(("inflation_layer", INFLATION))
    for key in _PARENT_KEYS[INFLATION]:
        move("inflation_layer", key)
    return plugins


def _parse(flat: dict[str, Any], name: str) -> tuple[CostmapParams, tuple[str, ...]]:
    warnings: list[str] = []
    top, spaces = _split(flat)
    raw_plugins = top.pop("plugins", None)
    if raw_plugins is None:
        plugin_list = _old_plugins(top, spaces, name, warnings)
    else:
        if not isinstance(raw_plugins, list | tuple):
            raise NavigationParamsError(f"{name}: plugins must be a list of {{name, type}}")
        plugin_list = []
        for entry in raw_plugins:
            if not isinstance(entry, Mapping) or "name" not in entry or "type" not in entry:
                raise NavigationParamsError(
                    f"{name}: each plugin must be {{name: ..., type: ...}}, got {entry!r}"
                )
            plugin_list.append((str(entry["name"]), _canonical_type(entry["type"], name)))
        for old in ("static_map", "map_type"):
            if old in top:
                top.pop(old)
                warnings.append(
                    f'{name}: Pre-Hydro parameter "{old}" unused since "plugins" is provided'
                )
        used: set[str] = set()
        for pname, ptype in plugin_list:
            for key in _PARENT_KEYS[ptype] + (_PARENT_KEYS[OBSTACLE] if ptype == VOXEL else ()):
                if key in top:
                    spaces.setdefault(pname, {})[key] = top[key]
                    used.add(key)
        for key in used - {"track_unknown_space"}:
            top.pop(key)
    specs = [
        PluginSpec(pname, ptype, _layer(pname, ptype, spaces.pop(pname, {}), top, name, warnings))
        for pname, ptype in plugin_list
    ]
    for space, keys in spaces.items():
        warnings.append(
            f"{name}: parameters {', '.join(f'{space}/{k}' for k in sorted(keys))} are unused "
            f"(no plugin named {space})"
        )
    top.pop("observation_sources", None)
    for key in sorted(set(top) & (_IGNORED_TOP | _VOXEL_ONLY)):
        top.pop(key)
        warnings.append(f"{name}: parameter {key} has no effect in roverlab (ignored)")
    for key in sorted(set(top) & {k for keys in _PARENT_KEYS.values() for k in keys}):
        if key != "track_unknown_space":
            top.pop(key)
            warnings.append(f"{name}: parameter {key} is unused (no layer of its type)")
    if "footprint_topic" in top:
        warnings.append(
            f"{name}: footprint_topic is not subscribed: roverlab has no dynamic footprint "
            "(the footprint parameter is used)"
        )
    params, res = build_params(CostmapParams, top, where=name, extra={"plugins": tuple(specs)})
    return params, tuple(warnings) + res.warnings


def _layer(
    pname: str,
    ptype: str,
    values: dict[str, Any],
    top: Mapping[str, Any],
    name: str,
    warnings: list[str],
) -> LayerParams:
    where = f"{name}/{pname}"
    if ptype == STATIC:
        p, res = build_params(StaticLayerParams, values, where=where)
        warnings.extend(res.warnings)
        return p
    if ptype == INFLATION:
        q, res = build_params(InflationLayerParams, values, where=where)
        warnings.extend(res.warnings)
        return q
    if ptype == VOXEL:
        warnings.append(
            f"{where}: costmap_2d::VoxelLayer runs as a 2-D obstacle layer in roverlab "
            "(marking and clearing in the plane; obstacles between min and max height)"
        )
    layer_vals: dict[str, Any] = {}
    source_vals: dict[str, dict[str, Any]] = {}
    for key, value in values.items():
        head, sep, rest = key.partition("/")
        if sep:
            source_vals.setdefault(head, {})[rest] = value
        elif ptype == VOXEL and key in _VOXEL_ONLY:
            warnings.append(f"{where}: voxel parameter {key} ignored")
        else:
            layer_vals[key] = value
    sources_text = layer_vals.pop("observation_sources", "")
    if not isinstance(sources_text, str):
        raise NavigationParamsError(f"{where}: observation_sources must be a string of names")
    # searchParam: the source's value, else the layer's, else the costmap's (else ROS's)
    inherited = {
        key: layer_vals.pop(key, top.get(key, default))
        for key, default in (
            ("obstacle_range", 2.5),
            ("raytrace_range", 3.0),
            ("min_obstacle_height", 0.0),
        )
    }
    inherited["max_obstacle_height"] = layer_vals.get(
        "max_obstacle_height", top.get("max_obstacle_height", 2.0)
    )
    sources = []
    for src in sources_text.split():
        sv = dict(source_vals.pop(src, {}))
        for key, value in inherited.items():
            sv.setdefault(key, value)
        s, res = build_params(
            ObservationSourceParams, sv, where=f"{where}/{src}", extra={"name": src}
        )
        warnings.extend(res.warnings)
        sources.append(s)
    for src in source_vals:
        warnings.append(
            f"{where}: parameters of {src} are unused ({src} is not an observation source)"
        )
    for key in sorted(set(layer_vals) - _OBSTACLE_LAYER_KEYS):
        warnings.append(unknown_warning(where, key, _OBSTACLE_LAYER_KEYS))
        layer_vals.pop(key)
    o, res = build_params(
        ObstacleLayerParams, layer_vals, where=where, extra={"observation_sources": tuple(sources)}
    )
    warnings.extend(res.warnings)
    return o


def make_layered_costmap(params: CostmapParams) -> LayeredCostmap:
    """The layered costmap of ``params``: master grid sized from ``width``, ``height``,
    ``resolution`` and ``origin_x/y``, the plugins in order, the padded footprint set."""
    lc = LayeredCostmap(
        global_frame=params.global_frame,
        rolling_window=params.rolling_window,
        track_unknown_space=params.track_unknown_space,
    )
    sx, sy = params.size_cells
    lc.resize_map(max(sx, 1), max(sy, 1), params.resolution, params.origin_x, params.origin_y)
    for spec in params.plugins:
        layer: Layer
        if isinstance(spec.params, StaticLayerParams):
            layer = StaticLayer(spec.name, spec.params)
        elif isinstance(spec.params, ObstacleLayerParams):
            layer = ObstacleLayer(spec.name, spec.params)
        else:
            layer = InflationLayer(spec.name, spec.params)
        lc.add_plugin(layer)
    lc.set_footprint(params.padded_footprint())
    return lc
