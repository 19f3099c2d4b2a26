"""Node loggers: a warning identical to one just said is counted, not printed, for
``REPEAT_S`` wall seconds (a lasting condition is a few lines a minute, as ROS code writes
it with ROS_WARN_THROTTLE); other warnings and info lines are untouched."""

from __future__ import annotations

import logging

import pytest

from roverlab.core import log as log_mod
from roverlab.core.log import NodeLogger


def test_repeated_identical_warnings_are_counted_not_printed(
    caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    now = [1000.0]
    monkeypatch.setattr(log_mod.time, "monotonic", lambda: now[0])
    logger = NodeLogger("move_base", lambda: 0.0)
    text = "global_costmap: could not get robot pose: Tf has two or more unconnected trees."
    with caplog.at_level(logging.INFO, logger="roverlab"):
        for _ in range(10):  # once a second for ten seconds
            logger.warning(text)
            logger.info("a progress line")
            now[0] += 1.0
        logger.warning("another warning")
        now[0] += log_mod.REPEAT_S
        logger.warning(text)
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert warnings == [text, "another warning", f"{text} (and 9 more times in 30 s)"]
    assert sum(r.getMessage() == "a progress line" for r in caplog.records) == 10
