"""Robot descriptions bundled with roverlab, laid out as ROS package folders.

Each sub-folder (``mbot_description``, ``bingda_tutorials``, ``mycar``) is a ROS package: a
``package.xml`` plus ``urdf/``, ``launch/``, ``config/`` and ``worlds/`` data, found by
``$(find pkg)`` and ``package://pkg/...`` through :mod:`roverlab.description.packages`
after ``ROVERLAB_PACKAGE_PATH`` and ``ROS_PACKAGE_PATH``. This module holds no code.
"""

from __future__ import annotations

from pathlib import Path
from typing import Final

__all__ = ["BUNDLED_PACKAGES_DIR"]

BUNDLED_PACKAGES_DIR: Final = Path(__file__).resolve().parent
"""The folder holding the bundled ROS packages."""
