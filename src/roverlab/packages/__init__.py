"""The ROS packages bundled with roverlab (the seeds' robots, worlds and launch files).

Each sub-folder (``mbot_description``, ``bingda_tutorials``, ``mycar``,
``robot_navigation``, ...) is a ROS package: a ``package.xml`` plus ``urdf/``, ``launch/``,
``config/`` and ``worlds/`` data, found by ``$(find pkg)`` and ``package://pkg/...``
through :mod:`roverlab.description.packages` after ``ROVERLAB_PACKAGE_PATH`` and
``ROS_PACKAGE_PATH``. This module holds no code. (The code that reads robot descriptions
is :mod:`roverlab.description`; the bundled world files are in ``roverlab/world/bundled``.)
"""

from __future__ import annotations

from pathlib import Path
from typing import Final

__all__ = ["BUNDLED_PACKAGES_DIR"]

BUNDLED_PACKAGES_DIR: Final = Path(__file__).resolve().parent
"""The folder holding the bundled ROS packages."""
