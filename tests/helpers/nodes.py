"""In-process helpers for tests that run nodes or the ``roverlab`` command."""

from __future__ import annotations

import logging
from typing import Any

import numpy as np

from roverlab.cli.main import main
from roverlab.core import Context, QoSProfile

__all__ = ["collect", "range_at", "run_main"]


def collect(ctx: Context, topics: dict[str, Any]) -> dict[str, list[Any]]:
    """Subscribe a ``collector`` node to ``{topic: type}``; the returned lists fill up with
    the messages (a queue of 1000 each)."""
    got: dict[str, list[Any]] = {t: [] for t in topics}
    node = ctx.create_node("collector")
    for topic, typ in topics.items():
        node.create_subscription(typ, topic, got[topic].append, QoSProfile(depth=1000))
    return got


def range_at(scan: Any, angle: float) -> float:
    """The range of the beam of ``scan`` (a LaserScan) nearest to ``angle`` (rad)."""
    ranges = np.asarray(scan.ranges)
    angles = scan.angle_min + scan.angle_increment * np.arange(len(ranges))
    return float(ranges[int(np.argmin(np.abs(np.angle(np.exp(1j * (angles - angle))))))])


def run_main(argv: list[str]) -> int:
    """The ``roverlab`` entry point in this process: its exit code. The ``roverlab``
    logger's set-up (the command points its handler at this test's captured stderr) is put
    back afterwards, so later tests in the process log as before."""
    logger = logging.getLogger("roverlab")
    saved = (list(logger.handlers), logger.level, logger.propagate)
    try:
        main(argv)
    except SystemExit as done:
        return int(done.code or 0)
    finally:
        logger.handlers[:] = saved[0]
        logger.setLevel(saved[1])
        logger.propagate = saved[2]
    return 0
