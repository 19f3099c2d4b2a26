"""Node loggers printing the ROS console format: ``[LEVEL] [stamp] [node]: message``."""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Callable
from pathlib import Path

__all__ = ["NodeLogger", "configure_logging", "log_to_file"]

_ROOT = "roverlab"
#: Wall seconds during which a node's warning or error identical to one it just printed is
#: counted instead of printed (then printed once more with the count): a condition that
#: lasts (a missing transform, a silent sensor) is said a few times a minute, not every
#: cycle, as ROS's ``ROS_WARN_THROTTLE`` lines are.
REPEAT_S = 20.0
_REPEAT_KEYS = 256
_TO_FILE: dict[str, logging.Handler] = {}  # logger name -> its file (roslaunch output="log")


def _logger_name(node_name: str) -> str:
    return f"{_ROOT}.{node_name.lstrip('/').replace('/', '.')}"


class _ScreenFilter(logging.Filter):
    """The console shows WARN and above of nodes whose output goes to a log file (as
    roslaunch's ``output="log"`` keeps stderr on the screen), everything of the rest."""

    def filter(self, record: logging.LogRecord) -> bool:
        return record.levelno >= logging.WARNING or record.name not in _TO_FILE


def log_to_file(node_name: str, path: Path) -> None:
    """roslaunch's ``output="log"`` for one node: all its messages go to ``path``, only
    warnings and errors also to the screen."""
    name = _logger_name(node_name)
    old = _TO_FILE.pop(name, None)
    logger = logging.getLogger(name)
    if old is not None:
        logger.removeHandler(old)
        old.close()
    path.parent.mkdir(parents=True, exist_ok=True)
    handler = logging.FileHandler(path, encoding="utf-8", delay=True)
    handler.setFormatter(_RosFormatter())
    logger.addHandler(handler)
    _TO_FILE[name] = handler


class _RosFormatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        stamp = getattr(record, "ros_stamp", None)
        if stamp is None:
            stamp = time.time()
        name = record.name.removeprefix(_ROOT + ".")
        line = f"[{record.levelname}] [{stamp:.6f}] [{name}]: {record.getMessage()}"
        if record.exc_info and record.levelno <= logging.DEBUG:
            line += "\n" + self.formatException(record.exc_info)
        return line


def configure_logging(level: int | str = logging.INFO, stream: object = None) -> None:
    """Send roverlab's node logs to ``stream`` (stderr by default) in the ROS format."""
    logger = logging.getLogger(_ROOT)
    for h in list(logger.handlers):
        logger.removeHandler(h)
    handler = logging.StreamHandler(stream if stream is not None else sys.stderr)  # type: ignore[arg-type]
    handler.setFormatter(_RosFormatter())
    handler.addFilter(_ScreenFilter())
    logger.addHandler(handler)
    logger.setLevel(level)
    logger.propagate = False


class NodeLogger:
    """rclpy-style logger of one node; messages are stamped with the node's clock."""

    def __init__(self, name: str, stamp: Callable[[], float]) -> None:
        self._logger = logging.getLogger(_logger_name(name))
        self._stamp = stamp
        self.name = name
        self._repeats: dict[tuple[int, str], list[float]] = {}  # -> [printed at, hidden]

    def _log(self, level: int, msg: str, exc: bool = False) -> None:
        if not self._logger.isEnabledFor(level):
            return
        if level >= logging.WARNING:
            now = time.monotonic()
            key = (level, msg)
            seen = self._repeats.get(key)
            if seen is not None and now - seen[0] < REPEAT_S:
                seen[1] += 1
                return
            if seen is not None and seen[1]:
                msg = f"{msg} (and {int(seen[1])} more times in {now - seen[0]:.0f} s)"
            if len(self._repeats) >= _REPEAT_KEYS:
                self._repeats = {k: v for k, v in self._repeats.items() if now - v[0] < REPEAT_S}
            self._repeats[key] = [now, 0.0]
        self._logger.log(level, msg, extra={"ros_stamp": self._stamp()}, exc_info=exc or None)

    def debug(self, msg: str) -> None:
        self._log(logging.DEBUG, msg)

    def info(self, msg: str) -> None:
        self._log(logging.INFO, msg)

    def warning(self, msg: str) -> None:
        self._log(logging.WARNING, msg)

    warn = warning

    def error(self, msg: str, *, exc_info: bool = False) -> None:
        self._log(logging.ERROR, msg, exc_info)

    def fatal(self, msg: str) -> None:
        self._log(logging.CRITICAL, msg)

    def get_child(self, suffix: str) -> NodeLogger:
        return NodeLogger(f"{self.name}.{suffix}", self._stamp)
