"""The Joints panel: joint_state_publisher_gui's sliders in the dashboard.

One slider per movable joint of the robot description (mimic joints follow their joint):
revolute and prismatic joints over their limits, continuous joints over -pi..pi, starting
where joint_state_publisher starts them (0, or the middle of limits that exclude 0). A
moved slider is published on :data:`SLIDER_TOPIC` (sensor_msgs/JointState with every
slider's position); the launch registry's ``joint_state_publisher_gui`` listens to it (a
``source_list`` entry), so its ``/joint_states`` follow the sliders.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from roverlab.description.model import JointType, RobotModel
from roverlab.msgs import Header, JointState

__all__ = ["SLIDER_TOPIC", "JointSlider", "JointSliders"]

SLIDER_TOPIC: Final = "/joint_state_publisher_gui/sliders"
"""Where the dashboard publishes the slider positions."""


@dataclass
class JointSlider:
    """One slider: a joint, its range and its position."""

    name: str
    lower: float
    upper: float
    position: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "lower": round(self.lower, 6),
            "upper": round(self.upper, 6),
            "position": round(self.position, 6),
        }


class JointSliders:
    """The sliders of one robot description."""

    def __init__(self, model: RobotModel) -> None:
        self.sliders: dict[str, JointSlider] = {}
        for joint in model.movable_joints:
            if joint.mimic is not None or joint.type == JointType.PLANAR:
                continue
            limit = joint.limit
            if joint.type == JointType.CONTINUOUS or limit is None:
                lower, upper = -math.pi, math.pi
            else:
                lower, upper = float(limit.lower), float(limit.upper)
            start = 0.0 if lower <= 0.0 <= upper else (lower + upper) / 2.0
            self.sliders[joint.name] = JointSlider(joint.name, lower, upper, start)

    def set(self, name: str, position: float) -> None:
        """Move one slider (clamped to its range).

        Raises:
            KeyError: no slider of that name.
            ValueError: a non-finite position.
        """
        slider = self.sliders[name]
        if not math.isfinite(position):
            raise ValueError(f"joint {name}: position must be finite, got {position}")
        slider.position = min(max(position, slider.lower), slider.upper)

    def message(self, stamp: Any) -> Any:
        """A JointState with every slider's position."""
        names = list(self.sliders)
        return JointState(
            header=Header(stamp=stamp),
            name=names,
            position=np.array([self.sliders[n].position for n in names]),
        )

    def to_list(self) -> list[dict[str, Any]]:
        return [s.to_dict() for s in self.sliders.values()]
