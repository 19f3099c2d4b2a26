"""move_base: the navigation executive (action server, state machine, recoveries).

* :mod:`.params`: move_base's parameters and recovery list;
* :mod:`.recovery`: clear_costmap_recovery and rotate_recovery (pure);
* :mod:`.plugins`: planners and recoveries by their ROS plugin names;
* :mod:`.node`: the ``move_base`` node (imported from there: it uses the runtime).
"""

from roverlab.navigation.move_base.params import (
    GLOBAL_PLANNERS,
    LOCAL_PLANNERS,
    RECOVERY_TYPES,
    MoveBaseParams,
    RecoverySpec,
    default_recoveries,
)
from roverlab.navigation.move_base.recovery import (
    ClearCostmapRecovery,
    RotateRecovery,
    RotateRecoveryParams,
)

__all__ = [
    "GLOBAL_PLANNERS",
    "LOCAL_PLANNERS",
    "RECOVERY_TYPES",
    "ClearCostmapRecovery",
    "MoveBaseParams",
    "RecoverySpec",
    "RotateRecovery",
    "RotateRecoveryParams",
    "default_recoveries",
]
