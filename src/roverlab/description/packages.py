"""ROS package lookup without ROS: ``$(find pkg)``, ``package://`` and ``file://``.

A package is a folder holding a ``package.xml``; its name is the manifest's ``<name>`` (or,
when that cannot be read, the folder's name). As ``rospack`` does with ``ROS_PACKAGE_PATH``,
each search root is crawled for packages (a package folder is not searched further; hidden
folders and folders with ``CATKIN_IGNORE`` / ``COLCON_IGNORE`` are skipped) and the first
root that provides a name wins. The roots, in order:

1. ``ROVERLAB_PACKAGE_PATH`` (``os.pathsep``-separated),
2. ``ROS_PACKAGE_PATH``,
3. the packages bundled with roverlab (:data:`roverlab.packages.BUNDLED_PACKAGES_DIR`),
4. extra folders given by the caller (``package_path=``).
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Final
from urllib.parse import unquote, urlparse

from roverlab.description.errors import DescriptionError, PackageNotFoundError
from roverlab.packages import BUNDLED_PACKAGES_DIR

__all__ = [
    "ENV_VARS",
    "MAX_CRAWL_DEPTH",
    "PackagePath",
    "find_package",
    "package_search_path",
    "resolve_uri",
]

ENV_VARS: Final = ("ROVERLAB_PACKAGE_PATH", "ROS_PACKAGE_PATH")
"""Environment variables read, in this order, for package search roots."""
MAX_CRAWL_DEPTH: Final = 8
"""How many folder levels below a search root are searched for ``package.xml``."""
_IGNORE_MARKERS: Final = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")

PathLike = str | os.PathLike[str]


def package_search_path(
    extra: Iterable[PathLike] = (), *, environ: Mapping[str, str] | None = None
) -> tuple[Path, ...]:
    """The package search roots in lookup order (see the module docstring).

    Args:
        extra: folders searched after every other root.
        environ: the environment to read (default ``os.environ``).

    Returns:
        The roots, without duplicates, in order.
    """
    env = os.environ if environ is None else environ
    roots: list[Path] = []
    for var in ENV_VARS:
        roots.extend(Path(p) for p in env.get(var, "").split(os.pathsep) if p.strip())
    roots.append(BUNDLED_PACKAGES_DIR)
    roots.extend(Path(p) for p in extra)
    unique: list[Path] = []
    for r in roots:
        if r not in unique:
            unique.append(r)
    return tuple(unique)


def _manifest_name(manifest: Path) -> str:
    try:
        name = ET.parse(manifest).getroot().findtext("name")
    except (ET.ParseError, OSError):
        name = None
    return name.strip() if name and name.strip() else manifest.parent.name


def _crawl(root: Path) -> Iterator[tuple[str, Path]]:
    """``(name, folder)`` of every package under ``root``, depth first, sorted by name."""
    seen: set[Path] = set()
    stack: list[tuple[Path, int]] = [(root, 0)]
    while stack:
        folder, depth = stack.pop()
        try:
            real = folder.resolve()
        except OSError:
            continue
        if real in seen or not folder.is_dir():
            continue
        seen.add(real)
        manifest = folder / "package.xml"
        if manifest.is_file():
            yield _manifest_name(manifest), folder
            continue
        if depth >= MAX_CRAWL_DEPTH or any((folder / m).exists() for m in _IGNORE_MARKERS):
            continue
        try:
            subdirs = sorted(
                Path(e.path)
                for e in os.scandir(folder)
                if e.is_dir() and not e.name.startswith(".") and e.name != "__pycache__"
            )
        except OSError:
            continue
        stack.extend((d, depth + 1) for d in reversed(subdirs))


class PackagePath:
    """A package search path; packages are found by crawling the roots once, lazily.

    Args:
        extra: folders searched after the environment and the bundled packages.
        environ: the environment to read (default ``os.environ``, read now).
    """

    def __init__(
        self, extra: Iterable[PathLike] = (), *, environ: Mapping[str, str] | None = None
    ) -> None:
        self.roots: tuple[Path, ...] = package_search_path(extra, environ=environ)
        self._index: dict[str, Path] | None = None

    def packages(self) -> dict[str, Path]:
        """Every package found, name -> folder (the first root providing a name wins)."""
        if self._index is None:
            index: dict[str, Path] = {}
            for root in self.roots:
                for name, folder in _crawl(root):
                    index.setdefault(name, folder)
            self._index = index
        return dict(self._index)

    def find(self, name: str) -> Path:
        """The folder of package ``name`` (what ``$(find name)`` expands to).

        Raises:
            PackageNotFoundError: no root provides the package.
        """
        folder = self.packages().get(name)
        if folder is None:
            where = ", ".join(str(r) for r in self.roots)
            raise PackageNotFoundError(f"package '{name}' not found (searched: {where})")
        return folder

    def resolve_uri(self, uri: str) -> Path:
        """The file a ``package://pkg/path``, ``file://`` URI or plain path names.

        Raises:
            PackageNotFoundError: the package of a ``package://`` URI is unknown.
            DescriptionError: a malformed URI or an unsupported scheme.
        """
        if uri.startswith("package://"):
            rest = uri[len("package://") :]
            pkg, _, rel = rest.partition("/")
            if not pkg:
                raise DescriptionError(f"malformed package URI '{uri}' (no package name)")
            return self.find(pkg) / unquote(rel)
        if uri.startswith("file://"):
            parsed = urlparse(uri)
            if parsed.netloc not in ("", "localhost"):
                raise DescriptionError(f"file URI '{uri}' names a remote host")
            return Path(unquote(parsed.path))
        scheme = urlparse(uri).scheme
        if len(scheme) > 1:  # one letter is a Windows drive
            raise DescriptionError(
                f"unsupported URI scheme '{scheme}://' in '{uri}' (use package:// or file://)"
            )
        return Path(uri)


def find_package(name: str, package_path: Iterable[PathLike] = ()) -> Path:
    """The folder of ROS package ``name``; ``package_path`` adds search roots (last).

    Raises:
        PackageNotFoundError: with the list of folders searched.
    """
    return PackagePath(package_path).find(name)


def resolve_uri(uri: str, package_path: Iterable[PathLike] = ()) -> Path:
    """The file named by ``package://pkg/rel``, ``file:///abs`` or a plain path.

    Raises:
        PackageNotFoundError: the package of a ``package://`` URI is unknown.
        DescriptionError: a malformed URI or an unsupported scheme.
    """
    return PackagePath(package_path).resolve_uri(uri)
