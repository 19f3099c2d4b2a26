"""What the SLAM methods share: the scan records they read and ROS parameter sets.

* :class:`ScanLike`: what ``run_log`` reads from a scan (a ``roverlab.slam.data.ScanRecord``).
* :class:`Runaway`: why a batch run stopped early (its estimate left any plausible building).
* :class:`RunawayWatch`: notices a batch run's estimate leaving any plausible building.
* :func:`params_from_ros`: a parameter dataclass from a launch file's ``<param>`` set.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Collection, Mapping
from typing import Any, NamedTuple, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2

__all__ = ["Runaway", "RunawayWatch", "ScanLike", "params_from_ros"]

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


class Runaway(NamedTuple):
    """Why a batch run stopped early: the estimate left the largest plausible map.

    Attributes:
        scan: index of the first scan not processed.
        stamp: its log time (s).
        jump_stamp: log time (s) of the estimate's (or its prediction's) largest step
            between two scans up to it (NaN if unknown), where it most likely jumped.
        jump_m: the size of that step (m).
        message: the error that stopped the run.
        method: the SLAM method, for the warning.
    """

    scan: int
    stamp: float
    jump_stamp: float
    jump_m: float
    message: str
    method: str = "hector"

    def warning(self) -> str:
        """One line naming where the estimate jumped."""
        where = (
            f"it jumped by {self.jump_m:.2f} m at log time {self.jump_stamp:.3f} s; "
            if math.isfinite(self.jump_stamp)
            else ""
        )
        return (
            f"warning: {self.method}'s estimate ran away ({self.message}); {where}mapping "
            f"stopped at log time {self.stamp:.3f} s (scan {self.scan}): the map and trajectory "
            f"hold the scans before it"
        )


class RunawayWatch:
    """Watches a batch run's predicted positions, one per scan, for a runaway.

    Args:
        max_extent_m: a prediction farther than this from the first one along x or y has
            run away (inf: never).
        method: the SLAM method, for the warning.
    """

    def __init__(self, max_extent_m: float, method: str) -> None:
        self.max_extent_m = float(max_extent_m)
        self.method = method
        self._start: tuple[float, float] | None = None
        self._last: tuple[float, float] | None = None
        self._largest = (0.0, math.nan)

    def check(self, scan: int, stamp: float, x: float, y: float) -> Runaway | None:
        """The runaway if scan ``scan`` (log time ``stamp``), predicted at ``(x, y)``, lies
        beyond the extent (the run should stop before it); else None."""
        if self._start is None or self._last is None:
            self._start = self._last = (x, y)
            return None
        step = math.hypot(x - self._last[0], y - self._last[1])
        if step > self._largest[0]:
            self._largest = (step, float(stamp))
        self._last = (x, y)
        far = max(abs(x - self._start[0]), abs(y - self._start[1]))
        if not far > self.max_extent_m:
            return None
        msg = (
            f"the robot at ({x:.2f}, {y:.2f}) m is {far:.0f} m from its start, beyond the "
            f"{self.max_extent_m:.0f} m any building here spans"
        )
        return Runaway(scan, float(stamp), self._largest[1], self._largest[0], msg, self.method)


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
