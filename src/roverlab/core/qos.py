"""Quality-of-service profiles (the subset that matters in one executor and over Zenoh)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

__all__ = ["QoSProfile", "qos_profile"]

Durability = Literal["volatile", "transient_local"]
Reliability = Literal["reliable", "best_effort"]


@dataclass(frozen=True, slots=True)
class QoSProfile:
    """History depth and durability, as rclpy.qos.QoSProfile.

    Args:
        depth: history depth: a subscription keeps at most this many undelivered
            messages (the oldest is dropped and counted); a transient-local publisher
            keeps this many for late subscribers.
        durability: ``"transient_local"`` makes a publisher latched (ROS 1 ``latch=True``):
            every subscription created later receives its last ``depth`` messages.
        reliability: carried for compatibility; in-process delivery is always reliable.
    """

    depth: int = 10
    durability: Durability = "volatile"
    reliability: Reliability = "reliable"

    def __post_init__(self) -> None:
        if not isinstance(self.depth, int) or self.depth < 1:
            raise ValueError(f"QoS depth must be an integer >= 1, got {self.depth!r}")
        if self.durability not in ("volatile", "transient_local"):
            raise ValueError(f"unknown QoS durability {self.durability!r}")
        if self.reliability not in ("reliable", "best_effort"):
            raise ValueError(f"unknown QoS reliability {self.reliability!r}")

    @property
    def latched(self) -> bool:
        return self.durability == "transient_local"


def qos_profile(qos: QoSProfile | int) -> QoSProfile:
    """Accept an int history depth (the rclpy shorthand) or a profile."""
    if isinstance(qos, QoSProfile):
        return qos
    if isinstance(qos, bool) or not isinstance(qos, int):
        raise TypeError(f"qos must be a QoSProfile or an int depth, got {qos!r}")
    return QoSProfile(depth=qos)
