"""slam_gmapping (Grisetti, Stachniss, Burgard 2007) as a pure algorithm: no node, no TF.

* :class:`GMappingParams`: the ROS parameters (names and defaults of slam_gmapping).
* :class:`GMapping`: the Rao-Blackwellised particle filter with the improved proposal and
  adaptive resampling; ``process(ranges, angles, odom_pose, timestamp) -> bool`` per scan,
  ``best_particle()``, ``occupancy()``, ``map_to_odom()``, ``run_log(log)`` over a
  ``roverlab.slam.data.logs.LaserLog`` (one robot pose per scan plus the final map).
* :class:`ParticleMaps`: the hit/visit count maps of all particles in one growable block;
  :mod:`.kernels` holds the compiled scan matcher, proposal and map update.
"""

from roverlab.slam.gmapping.errors import (
    GMappingError,
    GMappingInputError,
    GMappingParamsError,
)
from roverlab.slam.gmapping.grid import GMappingMap, ParticleMaps
from roverlab.slam.gmapping.params import (
    DEPRECATED_PARAMETERS,
    NODE_PARAMETERS,
    GMappingParams,
)
from roverlab.slam.gmapping.slam import (
    GMapping,
    GMappingRun,
    Particle,
    ScanLike,
    UpdateInfo,
    run_log,
)

__all__ = [
    "DEPRECATED_PARAMETERS",
    "NODE_PARAMETERS",
    "GMapping",
    "GMappingError",
    "GMappingInputError",
    "GMappingMap",
    "GMappingParams",
    "GMappingParamsError",
    "GMappingRun",
    "Particle",
    "ParticleMaps",
    "ScanLike",
    "UpdateInfo",
    "run_log",
]
