"""Goal states and goal ids of the ROS 1 actionlib protocol (``actionlib_msgs``)."""

from __future__ import annotations

import itertools
from typing import Final

from roverlab.errors import RoverlabError
from roverlab.msgs import get_factory

__all__ = [
    "STATUS_NAMES",
    "TERMINAL_STATES",
    "ActionError",
    "GoalIDGenerator",
    "GoalStatus",
    "status_name",
]

_GOAL_STATUS = get_factory("actionlib_msgs/msg/GoalStatus")


class GoalStatus:
    """The ten goal states of ``actionlib_msgs/GoalStatus``, as in ROS 1."""

    PENDING: Final[int] = int(_GOAL_STATUS.PENDING)
    ACTIVE: Final[int] = int(_GOAL_STATUS.ACTIVE)
    PREEMPTED: Final[int] = int(_GOAL_STATUS.PREEMPTED)
    SUCCEEDED: Final[int] = int(_GOAL_STATUS.SUCCEEDED)
    ABORTED: Final[int] = int(_GOAL_STATUS.ABORTED)
    REJECTED: Final[int] = int(_GOAL_STATUS.REJECTED)
    PREEMPTING: Final[int] = int(_GOAL_STATUS.PREEMPTING)
    RECALLING: Final[int] = int(_GOAL_STATUS.RECALLING)
    RECALLED: Final[int] = int(_GOAL_STATUS.RECALLED)
    LOST: Final[int] = int(_GOAL_STATUS.LOST)


#: State names by value (the message's constant names, as slam.py's ``goal_states`` list
#: spells them).
STATUS_NAMES: Final[tuple[str, ...]] = tuple(
    sorted(_GOAL_STATUS.constants, key=_GOAL_STATUS.constants.__getitem__)
)

#: The states a goal ends in.
TERMINAL_STATES: Final = frozenset(
    {
        GoalStatus.PREEMPTED,
        GoalStatus.SUCCEEDED,
        GoalStatus.ABORTED,
        GoalStatus.REJECTED,
        GoalStatus.RECALLED,
        GoalStatus.LOST,
    }
)


def status_name(status: int) -> str:
    """``SUCCEEDED`` for 3; ``NO_SUCH_STATE_42`` for an unknown value (actionlib's words)."""
    return STATUS_NAMES[status] if 0 <= status < len(STATUS_NAMES) else f"NO_SUCH_STATE_{status}"


class ActionError(RoverlabError):
    """Misuse of an action client or server (not a spec, no goal sent, ...)."""


class GoalIDGenerator:
    """Goal ids as actionlib makes them: ``<caller id>-<counter>-<seconds with 3 decimals>``."""

    def __init__(self, caller_id: str) -> None:
        self.caller_id = caller_id
        self._count = itertools.count(1)

    def generate(self, now_s: float) -> str:
        return f"{self.caller_id}-{next(self._count)}-{now_s:.3f}"
