"""Node loggers printing the ROS console format: ``[LEVEL] [stamp] [node]: message``."""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Callable
from pathlib import Path

__all__ = ["NodeLogger", "configure_logging", "log_to_file"]

_ROOT = "roverlab"
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

    def _log(self, level: int, msg: str, exc: bool = False) -> None:
        if self._logger.isEnabledFor(level):
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
