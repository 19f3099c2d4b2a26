"""ROS 1 amcl (adaptive Monte Carlo localization) as a pure algorithm: no node, no TF.

* :class:`AmclParams`: the ROS parameters (names and defaults of amcl's wiki page).
* :class:`AmclMap`: a map with its likelihood field (a distance transform).
* :class:`Amcl`: ``process_scan(odom_pose=..., ranges=..., bearings=...)`` per scan, as
  amcl's ``laserReceived``; ``set_initial_pose``, ``global_localization``,
  ``request_nomotion_update``; :class:`ScanResult` / :class:`PoseEstimate` out.
* :class:`ParticleFilter`: amcl's ``pf``: KLD-adaptive low-variance resampling,
  alpha_slow / alpha_fast recovery, clusters (:class:`Clusters`).
* :func:`sample_motion`: the ``diff``, ``omni``, ``diff-corrected`` and ``omni-corrected``
  odometry models; :mod:`.kernels`: the compiled sensor models and resampler.
* :func:`localize_log`: amcl over a recorded log (``roverlab amcl run``).

The ``amcl`` node is :class:`roverlab.localization.amcl.node.Amcl` (import it from there:
this package itself stays free of the runtime).
"""

from roverlab.localization.amcl.amcl import Amcl, PoseEstimate, ScanResult, select_beams
from roverlab.localization.amcl.errors import (
    AmclError,
    AmclInputError,
    AmclMapError,
    AmclParamsError,
)
from roverlab.localization.amcl.field import AmclMap
from roverlab.localization.amcl.motion import motion_noise_sigmas, sample_motion
from roverlab.localization.amcl.offline import AmclRun, Snapshot, localize_log, map_for_amcl
from roverlab.localization.amcl.params import (
    IGNORED_PARAMETERS,
    LASER_MODELS,
    NODE_PARAMETERS,
    ODOM_MODELS,
    AmclParams,
)
from roverlab.localization.amcl.pf import Clusters, ParticleFilter, kld_limits

__all__ = [
    "IGNORED_PARAMETERS",
    "LASER_MODELS",
    "NODE_PARAMETERS",
    "ODOM_MODELS",
    "Amcl",
    "AmclError",
    "AmclInputError",
    "AmclMap",
    "AmclMapError",
    "AmclParams",
    "AmclParamsError",
    "AmclRun",
    "Clusters",
    "ParticleFilter",
    "PoseEstimate",
    "ScanResult",
    "Snapshot",
    "kld_limits",
    "localize_log",
    "map_for_amcl",
    "motion_noise_sigmas",
    "sample_motion",
    "select_beams",
]
