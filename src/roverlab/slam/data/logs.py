"""Laser logs: scans with the robot's odometry pose, from CARMEN logs and ROS bags.

A :class:`LaserLog` is a sequence of :class:`ScanRecord` (one laser scan: ranges, beam
geometry, the robot's odometry pose at the scan and the laser's pose on the robot) with
numpy columns for the per-scan values. Readers are generators, so a long log can be
processed as it is read; :func:`load_log` collects one into a :class:`LaserLog`.

Formats (:func:`iter_log` picks by content and name):

* CARMEN ``.clf`` logs, plain, gzip or bzip2 (:func:`read_clf`): ``FLASER``,
  ``ROBOTLASER1`` and (on request) ``RAWLASER1`` front-laser lines, ``ODOM`` lines for
  scans that carry no pose. The scan timestamp is the line's ``ipc_timestamp``, kept as
  the original text (:attr:`ScanRecord.timestamp_text`) so that trajectory files can
  repeat it byte for byte.
* ROS 1 ``.bag`` files, ROS 2 bag folders and ``.mcap`` files (:func:`read_bag`), via
  rosbags: ``sensor_msgs/LaserScan`` on ``/scan``, odometry from ``nav_msgs/Odometry`` on
  ``/odom`` or else from the ``odom -> base`` transforms on ``/tf``, the laser's mounting
  from ``/tf_static``.

Every problem with a file is a :class:`~roverlab.slam.data.errors.LogError` naming the file
(and, for text logs, the line).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, Final

from roverlab.slam.data.bag_logs import read_bag
from roverlab.slam.data.carmen import CLF_RANGE_MAX_M, carmen_beam_geometry, read_clf
from roverlab.slam.data.errors import LogError
from roverlab.slam.data.scans import LaserLog, ScanRecord

__all__ = [
    "CLF_RANGE_MAX_M",
    "LaserLog",
    "ScanRecord",
    "carmen_beam_geometry",
    "iter_log",
    "load_log",
    "read_bag",
    "read_clf",
]


# ----------------------------------------------------------------------------- any log

_BAG_SUFFIXES: Final = (".bag", ".mcap", ".db3")


def _reader_for(path: Path) -> Callable[..., Iterator[ScanRecord]]:
    if path.is_dir() or path.suffix.lower() in _BAG_SUFFIXES:
        return read_bag
    return read_clf


def iter_log(path: str | Path, **options: Any) -> Iterator[ScanRecord]:
    """Stream the scans of any supported log: a ROS bag folder, ``.bag``, ``.mcap`` (or a
    ROS 2 ``.db3``) goes to :func:`read_bag`, anything else to :func:`read_clf`.

    Args:
        path: The log.
        **options: Keyword options of the chosen reader.

    Raises:
        LogError: the file does not exist, an option is not one of the reader's, or
            reading fails.
    """
    p = Path(path)
    if not p.exists():
        raise LogError(f"{p}: no such file or directory")
    reader = _reader_for(p)
    allowed = [
        name
        for name, param in inspect.signature(reader).parameters.items()
        if param.kind is inspect.Parameter.KEYWORD_ONLY
    ]
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise LogError(
            f"{p}: unknown option(s) {', '.join(unknown)} for {reader.__name__} "
            f"(accepted: {', '.join(allowed)})"
        )
    return reader(p, **options)


def load_log(path: str | Path, **options: Any) -> LaserLog:
    """All scans of a log (see :func:`iter_log` for the formats and options)."""
    return LaserLog(iter_log(path, **options), source=str(path))
