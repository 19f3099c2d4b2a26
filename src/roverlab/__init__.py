"""roverlab: the classic ROS mobile-robot stack as one pip-installable Python package."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("roverlab")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0"

__all__ = ["__version__"]
