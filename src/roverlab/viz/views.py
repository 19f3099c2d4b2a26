"""rviz's camera views (``Visualization Manager/Views/Current``) as the dashboard's view.

rviz keeps the camera in the ``.rviz`` file: ``rviz/Orbit`` (a focal point, distance, yaw
and pitch), ``rviz/TopDownOrtho`` (centre, scale in pixels per metre, angle) and
``rviz/ThirdPersonFollower`` (an orbit whose focal point follows a target frame, the yaw
turning with it). :func:`view_from_rviz` reads that section into a small JSON-able dict
the page's 3D view starts from; :func:`check_view` validates the dict form.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Final

from roverlab.viz.errors import DashboardError

__all__ = ["VIEW_CLASSES", "check_view", "default_view", "view_from_rviz"]

VIEW_CLASSES: Final[dict[str, str]] = {
    "rviz/Orbit": "Orbit",
    "rviz/XYOrbit": "Orbit",
    "rviz/TopDownOrtho": "TopDownOrtho",
    "rviz/ThirdPersonFollower": "ThirdPersonFollower",
    "rviz_default_plugins/Orbit": "Orbit",
    "rviz_default_plugins/XYOrbit": "Orbit",
    "rviz_default_plugins/TopDownOrtho": "TopDownOrtho",
    "rviz_default_plugins/ThirdPersonFollower": "ThirdPersonFollower",
}
"""rviz view controller class -> the dashboard's view mode."""

_MODES: Final = ("2D", "Orbit", "TopDownOrtho", "ThirdPersonFollower")


def default_view() -> dict[str, Any]:
    """The page's 2D top view (no 3D camera configured)."""
    return {"mode": "2D"}


def _num(d: Mapping[str, Any], key: str, default: float) -> float:
    try:
        value = float(d.get(key, default))
    except (TypeError, ValueError):
        return default
    return value if math.isfinite(value) else default


def _point(d: Any) -> list[float]:
    if not isinstance(d, Mapping):
        return [0.0, 0.0, 0.0]
    return [_num(d, "X", 0.0), _num(d, "Y", 0.0), _num(d, "Z", 0.0)]


def view_from_rviz(manager: Mapping[str, Any]) -> dict[str, Any]:
    """The view of an rviz ``Visualization Manager`` mapping (2D when it has none)."""
    views = manager.get("Views")
    current = views.get("Current") if isinstance(views, Mapping) else None
    if not isinstance(current, Mapping):
        return default_view()
    mode = VIEW_CLASSES.get(str(current.get("Class", "")))
    if mode is None:
        return default_view()
    target = str(current.get("Target Frame", "<Fixed Frame>"))
    view: dict[str, Any] = {
        "mode": mode,
        "target_frame": "" if target == "<Fixed Frame>" else target.lstrip("/"),
    }
    if mode == "TopDownOrtho":
        view.update(
            x=_num(current, "X", 0.0),
            y=_num(current, "Y", 0.0),
            scale=_num(current, "Scale", 50.0),
            angle=_num(current, "Angle", 0.0),
        )
    else:
        view.update(
            distance=_num(current, "Distance", 10.0),
            yaw=_num(current, "Yaw", 0.785398),
            pitch=_num(current, "Pitch", 0.785398),
            focal_point=_point(current.get("Focal Point")),
        )
    return view


def check_view(data: Any, where: str) -> dict[str, Any]:
    """The view dict of a saved dashboard config, validated.

    Raises:
        DashboardError: not a mapping, or an unknown mode (the message names ``where``).
    """
    if data is None:
        return default_view()
    if not isinstance(data, Mapping) or data.get("mode") not in _MODES:
        raise DashboardError(
            f"{where}: view must be a mapping with mode one of {', '.join(_MODES)}"
        )
    out = dict(data)
    for key, value in out.items():
        if key in ("mode", "target_frame"):
            if not isinstance(value, str):
                raise DashboardError(f"{where}: view {key} must be a string")
        elif key == "focal_point":
            ok = isinstance(value, list) and len(value) == 3
            if not ok or not all(isinstance(v, int | float) for v in value):
                raise DashboardError(f"{where}: view focal_point must be [x, y, z]")
        elif isinstance(value, bool) or not isinstance(value, int | float):
            raise DashboardError(f"{where}: view {key} must be a number")
    return out
