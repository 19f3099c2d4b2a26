"""The navigation benchmark (``roverlab nav bench``): the whole stack (simulator,
map_server, amcl or fake_localization, move_base) in one process on simulated time,
driven through seeded random goals; success, collisions, path ratio, time per goal and
the planners' compute times per run.

Above the domains: it wires :mod:`roverlab.sim`, :mod:`roverlab.launch` (the
``robot_navigation`` package), :mod:`roverlab.navigation` and :mod:`roverlab.maps`.
"""

from roverlab.navbench.grid import BenchGrid, GoalSamplingError, sample_goals
from roverlab.navbench.harness import (
    LOCALIZATIONS,
    PARAM_SETS,
    PLANNERS,
    SUCCESS_RADIUS_M,
    TIMING_KEYS,
    BenchConfig,
    BenchError,
    run_bench,
    run_episode,
)
from roverlab.navbench.report import BenchReport, GoalRecord

__all__ = [
    "LOCALIZATIONS",
    "PARAM_SETS",
    "PLANNERS",
    "SUCCESS_RADIUS_M",
    "TIMING_KEYS",
    "BenchConfig",
    "BenchError",
    "BenchGrid",
    "BenchReport",
    "GoalRecord",
    "GoalSamplingError",
    "run_bench",
    "run_episode",
    "sample_goals",
]
