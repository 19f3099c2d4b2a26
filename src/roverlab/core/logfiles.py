"""Where roverlab writes its log files (ROS 1's ``~/.ros/log``): one folder, one file per
node that logs to a file, named after the node's full name as roslaunch names it."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["log_dir", "node_log_file"]


def log_dir() -> Path:
    """``$ROVERLAB_LOG_DIR``, else ``~/.roverlab/log`` (not created here)."""
    return Path(os.environ.get("ROVERLAB_LOG_DIR") or Path.home() / ".roverlab" / "log")


def node_log_file(fq_name: str) -> Path:
    """The log file of the node ``fq_name`` (its resolved name): ``/robot1/amcl`` writes
    ``robot1-amcl.log`` and ``/amcl`` ``amcl.log``, so same-named nodes in different
    namespaces keep their own files. roslaunch replaces the slashes with ``-`` as well
    (a ROS name has no ``-``, so no two names share a file)."""
    return log_dir() / f"{fq_name.strip('/').replace('/', '-')}.log"
