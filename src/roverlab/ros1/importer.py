"""The import hook that lets a ROS 1 script's imports resolve without ROS.

* ``rospy``, ``actionlib``, ``roslib``, ``tf``, ``cv_bridge`` (and submodules) are roverlab's
  compatibility modules (:mod:`roverlab.ros1.rospy`, ...);
* ``<pkg>.msg`` and ``<pkg>.srv`` are :class:`~roverlab.ros1.messages.InterfaceModule`\\ s
  for any package the type store knows (``geometry_msgs``, ``move_base_msgs``, ...) or that
  the package path holds with ``msg/``, ``srv/`` or ``action/`` folders (a user's own
  ROS 1 package: its definitions are registered on first import). A real Python package
  of the same name wins: the hook only answers what no other finder can.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
import types
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Final

from roverlab.description import find_package
from roverlab.description.errors import DescriptionError
from roverlab.msgs import register_package_interfaces
from roverlab.msgs._store import STORE
from roverlab.msgs.interfaces import BUNDLED_INTERFACES_DIR
from roverlab.ros1.messages import InterfaceModule

__all__ = ["COMPAT_MODULES", "Ros1Finder", "install", "uninstall"]

#: ROS 1 module name -> roverlab module that stands in for it.
COMPAT_MODULES: Final = {
    "rospy": "roverlab.ros1.rospy",
    "actionlib": "roverlab.ros1.actionlib",
    "roslib": "roverlab.ros1.roslib",
    "tf": "roverlab.ros1.tf",
    "cv_bridge": "roverlab.ros1.cv_bridge",
}
_KINDS: Final = ("msg", "srv")


_MADE: set[str] = set()  # the sys.modules names this hook answered


class _ModuleLoader(importlib.abc.Loader):
    """Hands out an already built module object."""

    def __init__(self, make: Any) -> None:
        self._make = make

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        module: types.ModuleType = self._make()
        _MADE.add(spec.name)
        return module

    def exec_module(self, module: types.ModuleType) -> None:
        return None


def _package_dir(package: str) -> Path | None:
    """The package path's folder of ``package`` if it has interface folders."""
    try:
        folder = find_package(package)
    except DescriptionError:
        return None
    if any((folder / kind).is_dir() for kind in ("msg", "srv", "action")):
        return folder
    return None


class Ros1Finder(importlib.abc.MetaPathFinder):
    """Meta-path finder for the ROS 1 names (see the module docstring)."""

    def __init__(self) -> None:
        self._registered: set[str] = set()

    def _known_package(self, package: str) -> bool:
        if (BUNDLED_INTERFACES_DIR / package).is_dir():
            return True
        if any(t.startswith(package + "/") for t in STORE.typenames()):
            return True
        return _package_dir(package) is not None

    def _load_package(self, package: str) -> None:
        if package in self._registered:
            return
        self._registered.add(package)
        folder = _package_dir(package)
        if folder is not None:
            register_package_interfaces(folder, package)

    def find_spec(
        self,
        fullname: str,
        path: Sequence[str] | None = None,
        target: types.ModuleType | None = None,
    ) -> importlib.machinery.ModuleSpec | None:
        top, _, rest = fullname.partition(".")
        if top in COMPAT_MODULES:
            real = COMPAT_MODULES[top] + ("." + rest if rest else "")
            found = importlib.util.find_spec(real)
            if found is None:
                return None
            spec = importlib.machinery.ModuleSpec(
                fullname,
                _ModuleLoader(lambda: importlib.import_module(real)),
                is_package=found.submodule_search_locations is not None,
            )
            return spec
        if rest and rest not in _KINDS:
            return None
        if not rest and importlib.machinery.PathFinder.find_spec(top) is not None:
            return None  # a real package of that name
        if not self._known_package(top):
            return None
        if not rest:
            return importlib.machinery.ModuleSpec(
                fullname, _ModuleLoader(lambda: _namespace(top)), is_package=True
            )
        self._load_package(top)
        return importlib.machinery.ModuleSpec(
            fullname, _ModuleLoader(lambda: InterfaceModule(fullname, top, rest))
        )


def _namespace(name: str) -> types.ModuleType:
    module = types.ModuleType(name, f"ROS 1 package {name} (roverlab)")
    module.__path__ = []
    return module


_FINDER = Ros1Finder()


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (idempotent)."""
    if _FINDER not in sys.meta_path:
        sys.meta_path.insert(0, _FINDER)


def uninstall() -> None:
    """Remove the finder and the modules it made (tests)."""
    if _FINDER in sys.meta_path:
        sys.meta_path.remove(_FINDER)
    for name in list(_MADE):
        sys.modules.pop(name, None)
    _MADE.clear()
