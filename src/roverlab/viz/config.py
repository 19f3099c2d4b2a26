"""The dashboard's display configuration: rviz ``.rviz`` files in, its own JSON out.

Pure: no bus, no clock. A :class:`DashboardConfig` is the fixed frame plus an ordered list
of :class:`DisplayConfig` (rviz's Displays panel). Each display kind has a schema
(:data:`DISPLAY_KINDS`): the message types it draws, its default topic and its options with
their defaults. Options are validated by name and type, so a misspelt key is an error,
never silently dropped.

* :func:`load_rviz` reads a ``.rviz`` file (rviz 1's YAML: ``Visualization Manager`` ->
  ``Displays``, ``Global Options/Fixed Frame`` and ``Frame Rate``). Display classes
  roverlab does not draw are kept in :attr:`DashboardConfig.unsupported` (the page lists
  them), not an error.
* :func:`save_config` / :func:`load_config` write and read the dashboard's own format, a
  JSON document ``{"format": "roverlab-dashboard", "version": 1, "fixed_frame": ...,
  "frame_rate_hz": 30.0, "displays": [{"kind", "name", "enabled", "topic", "options"},
  ...]}``; :func:`load_config` also accepts ``.rviz`` files (told apart by content).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

import yaml

from roverlab.errors import yaml_reason
from roverlab.fileio import atomic_write_text
from roverlab.viz.errors import DashboardError
from roverlab.viz.kinds import DISPLAY_KINDS, RVIZ_CLASSES, DisplayKind
from roverlab.viz.views import check_view, default_view, view_from_rviz

__all__ = [
    "CONFIG_FORMAT",
    "DEFAULT_FRAME_RATE_HZ",
    "DISPLAY_KINDS",
    "RVIZ_CLASSES",
    "ConfigError",
    "DashboardConfig",
    "DisplayConfig",
    "DisplayKind",
    "check_frame_rate",
    "default_config",
    "load_config",
    "load_rviz",
    "parse_rviz",
    "save_config",
]

CONFIG_FORMAT: Final = "roverlab-dashboard"
_CONFIG_VERSION: Final = 1
DEFAULT_FRAME_RATE_HZ: Final = 30.0
"""rviz's ``Global Options/Frame Rate`` default."""


class ConfigError(DashboardError):
    """A display configuration (``.rviz`` or the dashboard's JSON) is malformed."""


@dataclass
class DisplayConfig:
    """One display of the Displays panel.

    Attributes:
        kind: a key of :data:`DISPLAY_KINDS`.
        name: the label shown (rviz's ``Name``).
        enabled: drawn (and subscribed) or not.
        topic: the topic it draws (``""`` for kinds without one).
        options: the kind's options; missing ones take the defaults.
    """

    kind: str
    name: str = ""
    enabled: bool = True
    topic: str = ""
    options: dict[str, Any] = field(default_factory=dict)

    def option(self, name: str) -> Any:
        """The option's value, or the kind's default."""
        if name in self.options:
            return self.options[name]
        return DISPLAY_KINDS[self.kind].options[name]

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able form with every option filled in."""
        opts = dict(DISPLAY_KINDS[self.kind].options)
        opts.update(self.options)
        return {
            "kind": self.kind,
            "name": self.name,
            "enabled": self.enabled,
            "topic": self.topic,
            "options": opts,
        }


@dataclass
class DashboardConfig:
    """Fixed frame, displays and what a loaded ``.rviz`` had that roverlab cannot draw.

    Attributes:
        fixed_frame: rviz's ``Global Options/Fixed Frame``.
        frame_rate_hz: rviz's ``Global Options/Frame Rate``: the most frames a second the
            page draws (it draws only when something changed).
        view: the camera (:mod:`roverlab.viz.views`): ``{"mode": "2D"}`` or rviz's
            ``Views/Current`` (Orbit, TopDownOrtho, ThirdPersonFollower).
        displays: in panel order (drawn in this order too, later on top).
        unsupported: ``"Name (rviz/Class)"`` of each display that was skipped.
        source: the file it came from, if any.
    """

    fixed_frame: str = "map"
    displays: list[DisplayConfig] = field(default_factory=list)
    unsupported: list[str] = field(default_factory=list)
    source: str = ""
    view: dict[str, Any] = field(default_factory=default_view)
    frame_rate_hz: float = DEFAULT_FRAME_RATE_HZ

    def __post_init__(self) -> None:
        self.frame_rate_hz = check_frame_rate(self.frame_rate_hz, "dashboard config")

    def to_dict(self) -> dict[str, Any]:
        """The JSON document :func:`save_config` writes."""
        return {
            "format": CONFIG_FORMAT,
            "version": _CONFIG_VERSION,
            "fixed_frame": self.fixed_frame,
            "frame_rate_hz": self.frame_rate_hz,
            "displays": [d.to_dict() for d in self.displays],
            "unsupported": list(self.unsupported),
            "view": dict(self.view),
        }


def default_config(fixed_frame: str = "map") -> DashboardConfig:
    """What the dashboard shows without a file: grid, map, scan, robot, TF, odometry,
    camera, plus disabled displays for plans, particles, clouds, markers, goals and the
    footprint."""
    enabled = ("grid", "map", "laser_scan", "robot_model", "tf", "odometry", "image")
    names = {
        "grid": "Grid",
        "map": "Map",
        "laser_scan": "LaserScan",
        "robot_model": "RobotModel",
        "tf": "TF",
        "odometry": "Odometry",
        "image": "Image",
    }
    displays = [
        DisplayConfig(k, names[k], True, DISPLAY_KINDS[k].default_topic, {}) for k in enabled
    ]
    displays[-2].options["keep"] = 1
    extra: list[tuple[str, str, str, dict[str, Any]]] = [
        ("path", "Global plan", "/move_base/NavfnROS/plan", {"color": [25, 255, 0]}),
        ("path", "Local plan", "/move_base/DWAPlannerROS/local_plan", {"color": [0, 12, 255]}),
        ("pose_array", "Particles", "/particlecloud", {}),
        ("pose_with_covariance", "AMCL pose", "/amcl_pose", {}),
        ("point_cloud2", "PointCloud2", "/camera/depth/points", {}),
        ("marker", "Marker", "/visualization_marker", {}),
        ("marker_array", "MarkerArray", "/visualization_marker_array", {}),
        ("pose", "Goal", "/move_base_simple/goal", {}),
        ("polygon", "Footprint", "/move_base/local_costmap/footprint", {}),
        ("map", "Costmap", "/move_base/global_costmap/costmap", {"color_scheme": "costmap"}),
    ]
    displays += [DisplayConfig(k, n, False, t, o) for k, n, t, o in extra]
    return DashboardConfig(fixed_frame=fixed_frame, displays=displays)


# ------------------------------------------------------------------ validation
def check_frame_rate(value: Any, where: str) -> float:
    """A Frame Rate (frames a second, at least 1, as rviz's update timer needs).

    Raises:
        ConfigError: not a number, or below 1 (the message names ``where``).
    """
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    if not ok or not value >= 1 or value == float("inf"):
        raise ConfigError(
            f"{where}: Frame Rate must be a number >= 1 (frames a second), got {value!r}"
        )
    return float(value)


def _check_option(where: str, kind: str, name: str, value: Any) -> Any:
    defaults = DISPLAY_KINDS[kind].options
    if name not in defaults:
        raise ConfigError(
            f"{where}: display kind {kind!r} has no option {name!r} "
            f"(options: {', '.join(sorted(defaults)) or 'none'})"
        )
    default = defaults[name]
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise ConfigError(f"{where}: option {name!r} must be true or false, got {value!r}")
        return value
    if isinstance(default, int):
        if isinstance(value, bool) or not isinstance(value, int | float) or value != int(value):
            raise ConfigError(f"{where}: option {name!r} must be an integer, got {value!r}")
        return int(value)
    if isinstance(default, float):
        if isinstance(value, bool) or not isinstance(value, int | float) or value != value:
            raise ConfigError(f"{where}: option {name!r} must be a number, got {value!r}")
        return float(value)
    if isinstance(default, list):
        ok = (
            isinstance(value, list)
            and len(value) == 3
            and all(isinstance(c, int | float) and 0 <= c <= 255 for c in value)
        )
        if not ok:
            raise ConfigError(f"{where}: option {name!r} must be [r, g, b] 0..255, got {value!r}")
        return [int(c) for c in value]
    if not isinstance(value, str):
        raise ConfigError(f"{where}: option {name!r} must be a string, got {value!r}")
    choices = {
        "color_scheme": ("map", "costmap", "raw"),
        "color_map": ("gray", "jet", "hot", "rainbow"),
        "color_transformer": ("FlatColor", "Intensity", "AxisColor", "RGB8"),
        "axis": ("X", "Y", "Z"),
    }.get(name)
    if choices and value not in choices:
        raise ConfigError(f"{where}: option {name!r} must be one of {', '.join(choices)}")
    return value


def display_from_dict(data: Any, where: str) -> DisplayConfig:
    """A :class:`DisplayConfig` from the JSON form, validated.

    Raises:
        ConfigError: unknown kind, unknown option, wrong type (message names ``where``).
    """
    if not isinstance(data, Mapping):
        raise ConfigError(f"{where}: a display must be a mapping, got {data!r}")
    unknown = set(data) - {"kind", "name", "enabled", "topic", "options"}
    if unknown:
        raise ConfigError(f"{where}: unknown display key(s) {', '.join(sorted(unknown))}")
    kind = data.get("kind")
    if kind not in DISPLAY_KINDS:
        raise ConfigError(
            f"{where}: unknown display kind {kind!r} (kinds: {', '.join(DISPLAY_KINDS)})"
        )
    name, enabled, topic = data.get("name", kind), data.get("enabled", True), data.get("topic")
    if topic is None:
        topic = DISPLAY_KINDS[kind].default_topic
    if not isinstance(name, str) or not isinstance(enabled, bool) or not isinstance(topic, str):
        raise ConfigError(f"{where}: name and topic must be strings and enabled a boolean")
    if topic and not topic.startswith("/"):
        topic = "/" + topic
    options = data.get("options", {})
    if not isinstance(options, Mapping):
        raise ConfigError(f"{where}: options must be a mapping")
    checked = {k: _check_option(where, kind, str(k), v) for k, v in options.items()}
    return DisplayConfig(kind, name, enabled, topic, checked)


def config_from_dict(data: Any, where: str = "dashboard config") -> DashboardConfig:
    """A :class:`DashboardConfig` from :meth:`DashboardConfig.to_dict`'s form, validated.

    Raises:
        ConfigError: not a dashboard config, or a bad display (the message names ``where``).
    """
    if not isinstance(data, Mapping) or data.get("format") != CONFIG_FORMAT:
        raise ConfigError(f"{where}: not a roverlab dashboard config (no format: {CONFIG_FORMAT})")
    if data.get("version") != _CONFIG_VERSION:
        raise ConfigError(f"{where}: unsupported config version {data.get('version')!r}")
    frame = data.get("fixed_frame", "map")
    displays = data.get("displays", [])
    if not isinstance(frame, str) or not frame or not isinstance(displays, list):
        raise ConfigError(f"{where}: fixed_frame must be a name and displays a list")
    unsupported = [str(u) for u in data.get("unsupported", [])]
    try:
        view = check_view(data.get("view"), where)
    except DashboardError as err:
        raise ConfigError(str(err)) from err
    rate = check_frame_rate(data.get("frame_rate_hz", DEFAULT_FRAME_RATE_HZ), where)
    return DashboardConfig(
        fixed_frame=frame.lstrip("/"),
        displays=[
            display_from_dict(d, f"{where}: display {i + 1}") for i, d in enumerate(displays)
        ],
        unsupported=unsupported,
        source=where,
        view=view,
        frame_rate_hz=rate,
    )


# ------------------------------------------------------------------------ rviz
def _rviz_color(text: Any, where: str) -> list[int]:
    try:
        parts = [int(round(float(p))) for p in str(text).split(";")]
    except ValueError:
        raise ConfigError(f"{where}: bad colour {text!r} (expected 'R; G; B')") from None
    if len(parts) != 3 or not all(0 <= p <= 255 for p in parts):
        raise ConfigError(f"{where}: bad colour {text!r} (expected 'R; G; B', 0..255)")
    return parts


def _rviz_number(d: Mapping[str, Any], key: str, where: str) -> float | None:
    if key not in d:
        return None
    try:
        return float(d[key])
    except (TypeError, ValueError):
        raise ConfigError(f"{where}: {key} must be a number, got {d[key]!r}") from None


def _rviz_point_colours(d: Mapping[str, Any], opts: dict[str, Any], where: str) -> None:
    """The Intensity and AxisColor transformers' properties of a LaserScan / PointCloud2."""
    for key, opt in (("Min Intensity", "min_intensity"), ("Max Intensity", "max_intensity")):
        value = _rviz_number(d, key, where)
        if value is not None:
            opts[opt] = value
    flags = (
        ("Autocompute Intensity Bounds", "autocompute_intensity_bounds"),
        ("Use rainbow", "use_rainbow"),
        ("Invert Rainbow", "invert_rainbow"),
        ("Use Fixed Frame", "use_fixed_frame"),
    )
    for key, opt in flags:
        if key in d:
            opts[opt] = bool(d[key])
    for key, opt in (("Min Color", "min_color"), ("Max Color", "max_color")):
        if key in d:
            opts[opt] = _rviz_color(d[key], where)
    if "Channel Name" in d:
        opts["channel_name"] = str(d["Channel Name"])
    if "Axis" in d:
        opts["axis"] = str(d["Axis"])
    bounds = d.get("Autocompute Value Bounds")  # rviz 1: {Value, Min Value, Max Value}
    if isinstance(bounds, Mapping):
        if "Value" in bounds:
            opts["autocompute_value_bounds"] = bool(bounds["Value"])
        for key, opt in (("Min Value", "min_value"), ("Max Value", "max_value")):
            value = _rviz_number(bounds, key, where)
            if value is not None:
                opts[opt] = value
    elif bounds is not None:
        opts["autocompute_value_bounds"] = bool(bounds)


def _rviz_display(d: Mapping[str, Any], kind: str, where: str) -> DisplayConfig:
    opts: dict[str, Any] = {}

    def num(key: str, opt: str, *, integer: bool = False) -> None:
        value = _rviz_number(d, key, where)
        if value is not None:
            opts[opt] = int(value) if integer else value

    if "Alpha" in d and "alpha" in DISPLAY_KINDS[kind].options:
        num("Alpha", "alpha")
    if "Color" in d and "color" in DISPLAY_KINDS[kind].options:
        opts["color"] = _rviz_color(d["Color"], where)
    topic = d.get("Topic", d.get("Image Topic"))  # rviz 1 Image/Camera: "Image Topic"
    if kind == "grid":
        num("Cell Size", "cell_size")
        num("Plane Cell Count", "cell_count", integer=True)
        ref = str(d.get("Reference Frame", "<Fixed Frame>"))
        opts["reference_frame"] = "" if ref == "<Fixed Frame>" else ref.lstrip("/")
    elif kind == "map":
        if "Color Scheme" in d:
            opts["color_scheme"] = str(d["Color Scheme"])
        if "Draw Behind" in d:
            opts["draw_behind"] = bool(d["Draw Behind"])
    elif kind in ("laser_scan", "point_cloud2"):
        num("Decay Time", "decay_s")
        num("Size (Pixels)", "size_px")
        if "Color Transformer" in d:
            opts["color_transformer"] = str(d["Color Transformer"])
        _rviz_point_colours(d, opts, where)
    elif kind == "robot_model":
        topic = "/" + str(d.get("Robot Description", "robot_description")).lstrip("/")
    elif kind == "tf":
        if "Show Names" in d:
            opts["show_names"] = bool(d["Show Names"])
        if "Show Axes" in d:
            opts["show_axes"] = bool(d["Show Axes"])
        num("Marker Scale", "scale")
    elif kind in ("odometry", "pose", "pose_array", "pose_with_covariance"):
        if kind == "odometry":
            num("Keep", "keep", integer=True)
            num("Position Tolerance", "position_tolerance")
            num("Angle Tolerance", "angle_tolerance")
        shape = d.get("Shape")
        if isinstance(shape, Mapping):  # Odometry keeps its arrow under Shape
            if "Color" in shape:
                opts["color"] = _rviz_color(shape["Color"], where)
            num_alpha = _rviz_number(shape, "Alpha", where)
            if num_alpha is not None:
                opts["alpha"] = num_alpha
            shaft = _rviz_number(shape, "Shaft Length", where)
            head = _rviz_number(shape, "Head Length", where)
            if shaft is not None or head is not None:
                opts["length"] = (shaft or 0.0) + (head or 0.0)
        else:
            shaft = _rviz_number(d, "Shaft Length", where)
            head = _rviz_number(d, "Head Length", where)
            if shaft is not None or head is not None:
                opts["length"] = (shaft or 0.0) + (head or 0.0)
            if kind == "pose_array":
                num("Arrow Length", "length")
    elif kind == "path":
        num("Line Width", "line_width")
    elif kind == "marker" and topic is None:
        topic = d.get("Marker Topic")
    elif kind == "image":
        transport = str(d.get("Transport Hint", "raw"))
        if topic and transport == "compressed":
            topic = str(topic).rstrip("/") + "/compressed"
    if topic is None:
        topic = DISPLAY_KINDS[kind].default_topic
    return display_from_dict(
        {
            "kind": kind,
            "name": str(d.get("Name", kind)),
            "enabled": bool(d.get("Enabled", d.get("Value", True))),
            "topic": str(topic),
            "options": opts,
        },
        where,
    )


def parse_rviz(text: str, source: str = "<rviz>") -> DashboardConfig:
    """A :class:`DashboardConfig` from the text of a ``.rviz`` file.

    Raises:
        ConfigError: not YAML, or not an rviz config (the message names ``source``).
    """
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise ConfigError(f"{source}: not a valid .rviz (YAML) file: {yaml_reason(err)}") from err
    manager = data.get("Visualization Manager") if isinstance(data, Mapping) else None
    if not isinstance(manager, Mapping):
        raise ConfigError(f"{source}: no 'Visualization Manager' section: not an .rviz file")
    options = manager.get("Global Options") or {}
    if not isinstance(options, Mapping):
        raise ConfigError(f"{source}: 'Global Options' must be a mapping")
    frame = str(options.get("Fixed Frame", "map")).lstrip("/") or "map"
    rate = _rviz_number(options, "Frame Rate", f"{source}: Global Options")
    config = DashboardConfig(
        fixed_frame=frame,
        source=source,
        view=view_from_rviz(manager),
        frame_rate_hz=check_frame_rate(
            DEFAULT_FRAME_RATE_HZ if rate is None else rate, f"{source}: Global Options"
        ),
    )
    raw = manager.get("Displays") or []
    if not isinstance(raw, list):
        raise ConfigError(f"{source}: 'Displays' must be a list")

    def walk(items: list[Any]) -> None:
        for i, d in enumerate(items):
            if not isinstance(d, Mapping):
                raise ConfigError(f"{source}: display {i + 1} is not a mapping")
            cls = str(d.get("Class", ""))
            if cls == "rviz/Group" and isinstance(d.get("Displays"), list):
                walk(d["Displays"])
                continue
            short = cls.rsplit("/", 1)[-1]
            kind = RVIZ_CLASSES.get(cls) or RVIZ_CLASSES.get(f"rviz/{short}")
            name = str(d.get("Name", short))
            if kind is None:
                config.unsupported.append(f"{name} ({cls or 'no Class'})")
                continue
            config.displays.append(_rviz_display(d, kind, f"{source}: display {name!r}"))

    walk(raw)
    return config


def load_rviz(path: str | os.PathLike[str]) -> DashboardConfig:
    """:func:`parse_rviz` of a file.

    Raises:
        ConfigError: unreadable file, or not an ``.rviz`` config.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{p}: cannot read: {err}") from err
    return parse_rviz(text, str(p))


def load_config(path: str | os.PathLike[str]) -> DashboardConfig:
    """A dashboard JSON config or an ``.rviz`` file (told apart by content).

    Raises:
        ConfigError: unreadable, or neither format.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{p}: cannot read: {err}") from err
    if text.lstrip().startswith("{"):
        try:
            data = json.loads(text)
        except json.JSONDecodeError as err:
            raise ConfigError(f"{p}: not valid JSON: {err}") from err
        return config_from_dict(data, str(p))
    return parse_rviz(text, str(p))


def save_config(config: DashboardConfig, path: str | os.PathLike[str]) -> Path:
    """Write ``config`` as the dashboard's JSON, atomically (temp file + rename).

    Raises:
        ConfigError: the file cannot be written (nothing is left behind).
    """
    p = Path(path)
    text = json.dumps(config.to_dict(), indent=2) + "\n"
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(p, text)
    except OSError as err:
        raise ConfigError(f"{p}: cannot write: {err}") from err
    return p
