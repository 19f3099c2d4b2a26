"""What a run records while it goes: the ground-truth path, the known area over time,
contacts with the world. Read by the reports and the summary lines; never steers.
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.core import Context, Node, QoSProfile
from roverlab.geometry import SE2
from roverlab.msgs import classes as mc
from roverlab.sim.app import Simulation
from roverlab.slam.data.mapquality import ReachableArea, grid_from_msg, ground_truth

__all__ = ["CoverageSample", "RunMonitor"]

_LATCHED = QoSProfile(depth=1, durability="transient_local")


@dataclass(frozen=True, slots=True)
class CoverageSample:
    """The map at one moment: sim time (s), known area (m^2), share of the reachable area."""

    t: float
    known_m2: float
    fraction: float


@dataclass
class _Path:
    """Sample times and poses as packed doubles (8 bytes a number: an hour at 10 Hz is
    1.2 MB, where lists of tuples took 6 MB)."""

    t: array[float] = field(default_factory=lambda: array("d"))
    xy: array[float] = field(default_factory=lambda: array("d"))  # x, y, yaw per sample


class RunMonitor(Node):
    """Samples the simulator's ground truth at ``rate_hz`` and scores every ``map_topic``
    message against the world's reachable free area.

    Args:
        context: the run's context.
        simulation: the simulated robot (ground truth, contacts).
        map_topic: the SLAM map.
        rate_hz: ground-truth sampling rate.
        lidar_z_m: height of the scan plane (the ground truth's slice).

    Attributes:
        coverage: one :class:`CoverageSample` per map message.
        contacts: contact events (the simulator's count: a physics step in contact after
            one that was not).
        contact_events: when and where each began, to the sample (0.1 s) after it:
            ``(t, x, y, yaw)`` in the world.
    """

    def __init__(
        self,
        context: Context,
        simulation: Simulation,
        *,
        map_topic: str = "/map",
        rate_hz: float = 10.0,
        lidar_z_m: float | None = None,
        node_name: str = "run_monitor",
    ) -> None:
        super().__init__(node_name, context=context)
        self.simulation = simulation
        sim = simulation.simulator
        self.spawn = SE2(sim.x, sim.y, sim.yaw)  # the SLAM map frame's pose in the world
        lidars = simulation.config.lidars
        self.lidar_z_m = lidar_z_m if lidar_z_m is not None else (
            max(float(lidars[0].mount.translation[2]), 0.01) if lidars else 0.15
        )  # fmt: skip
        self.coverage: list[CoverageSample] = []
        self.contacts = 0
        self.contact_events: list[tuple[float, float, float, float]] = []
        self.map_msg: Any = None
        self._reachable: dict[float, ReachableArea] = {}
        self._path = _Path()
        self._in_contact = False
        self.create_subscription(mc.OccupancyGrid, map_topic, self._on_map, _LATCHED)
        self.create_timer(1.0 / rate_hz, self.sample)
        self.sample()

    # ------------------------------------------------------------------ sampling
    def sample(self) -> None:
        """Record the robot's true pose now (and whether it touches something)."""
        sim = self.simulation.simulator
        sim.advance()
        t = self.get_clock().now_ns() / 1e9
        # the simulator counts contact events at its physics rate (100 Hz); a sample (10 Hz)
        # places the ones that began since the last sample
        count = sim.contacts
        for _ in range(count - self.contacts):
            self.contact_events.append((t, sim.x, sim.y, sim.yaw))
        self.contacts = count
        self._in_contact = sim.contact
        self._path.t.append(t)
        self._path.xy.extend((sim.x, sim.y, sim.yaw))

    def reachable(self, resolution: float) -> ReachableArea:
        """The world's reachable free area on a grid of ``resolution`` (cached)."""
        if resolution not in self._reachable:
            gt = ground_truth(
                self.simulation.world_model, resolution=resolution, z_m=self.lidar_z_m
            )
            self._reachable[resolution] = ReachableArea(gt, self.spawn)
        return self._reachable[resolution]

    def _on_map(self, msg: Any) -> None:
        self.map_msg = msg
        grid = grid_from_msg(msg)
        data = np.asarray(grid.data)
        known_m2 = float(np.count_nonzero(data >= 0)) * grid.resolution**2
        fraction = self.reachable(grid.resolution).known_fraction(grid)
        self.coverage.append(CoverageSample(self.get_clock().now_ns() / 1e9, known_m2, fraction))

    # ------------------------------------------------------------------ results
    @property
    def times(self) -> NDArray[np.float64]:
        return np.asarray(self._path.t, dtype=np.float64)

    @property
    def world_path(self) -> NDArray[np.float64]:
        """(N, 3) true poses in the world."""
        return np.asarray(self._path.xy, dtype=np.float64).reshape(-1, 3)

    @property
    def map_path(self) -> NDArray[np.float64]:
        """(N, 2) true positions in the SLAM map's frame (the spawn pose's)."""
        xy = self.world_path[:, :2]
        return (~self.spawn).apply(xy) if len(xy) else np.zeros((0, 2))

    @property
    def distance_m(self) -> float:
        """Length of the true path."""
        xy = self.world_path[:, :2]
        return float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0

    def coverage_at(self, t: float) -> float:
        """Share of the reachable area known at sim time ``t`` (0 before the first map)."""
        best = 0.0
        for s in self.coverage:
            if s.t > t:
                break
            best = s.fraction
        return best

    def time_to(self, fraction: float) -> float:
        """First sim time the map knew ``fraction`` of the reachable area (inf: never)."""
        for s in self.coverage:
            if s.fraction >= fraction:
                return s.t
        return math.inf
