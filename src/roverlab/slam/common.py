"""What the SLAM methods share: the scan records they read and ROS parameter sets.

* :class:`ScanLike`: what ``run_log`` reads from a scan (a ``roverlab.slam.data.ScanRecord``).
* :func:`params_from_ros`: a parameter dataclass from a launch file's ``<param>`` set.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Collection, Mapping
from typing import Any, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2

__all__ = ["ScanLike", "params_from_ros"]

T = TypeVar("T")


class ScanLike(Protocol):
    """What the SLAM methods' ``run_log`` read from a scan (a ``roverlab.slam.data.ScanRecord``)."""

    @property
    def timestamp(self) -> float: ...
    @property
    def timestamp_text(self) -> str: ...
    @property
    def ranges(self) -> NDArray[np.float32]: ...
    @property
    def angle_min(self) -> float: ...
    @property
    def angle_increment(self) -> float: ...
    @property
    def range_min(self) -> float: ...
    @property
    def range_max(self) -> float: ...
    @property
    def odom_pose(self) -> SE2: ...
    @property
    def laser_offset(self) -> SE2: ...


def params_from_ros(
    cls: Callable[..., T],
    params: Mapping[str, Any],
    *,
    ignored: Collection[str],
    unknown: Callable[[str], Exception],
) -> T:
    """Build the parameter dataclass ``cls`` from ROS-named ``params``.

    Integers given for float fields are accepted (``value="2"``); names in ``ignored``
    (node-level or deprecated ones) are skipped; any other name that is not a field raises
    ``unknown(name)``. The dataclass checks the values.
    """
    types = {f.name: str(f.type) for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    kwargs: dict[str, Any] = {}
    for key, value in params.items():
        if key in ignored:
            continue
        if key not in types:
            raise unknown(key)
        if "float" in types[key] and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        kwargs[key] = value
    return cls(**kwargs)
