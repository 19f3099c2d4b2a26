"""Simulated SLAM logs with ground truth: buildings the Radish logs do not have.

* :mod:`.buildings`: layouts (a long featureless corridor, T and X junctions, a loop, an
  open hall) as an occupancy grid and a route;
* :mod:`.logs`: a robot driving the route with a 180- or 360-degree laser and odometry of
  a chosen noise level, written as CARMEN ``.clf`` + Radish ``.relations`` + TUM ground
  truth, which ``roverlab slam run`` and ``roverlab slam eval`` read.
"""

from roverlab.slam.simulated.buildings import BUILDINGS, Building, building
from roverlab.slam.simulated.logs import (
    LASERS,
    NOISE_LEVELS,
    Laser,
    OdometryNoise,
    SimulatedLog,
    simulate,
    write_log,
)

__all__ = [
    "BUILDINGS",
    "LASERS",
    "NOISE_LEVELS",
    "Building",
    "Laser",
    "OdometryNoise",
    "SimulatedLog",
    "building",
    "simulate",
    "write_log",
]
