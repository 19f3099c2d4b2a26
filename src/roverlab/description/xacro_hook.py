"""xacro expansion with ``$(find pkg)`` resolved through roverlab's package path.

The ``xacro`` PyPI package (2.1.x, the ROS 2 release) resolves ``$(find pkg)`` with
``ament_index_python``, which needs a ROS 2 install. roverlab replaces that one function,
``xacro.substitution_args._eval_find`` (and its entry in ``_eval_dict``, used by
``$(eval find('pkg'))``), for the duration of each expansion, under a lock, so ``$(find)``
looks packages up in :class:`~roverlab.description.packages.PackagePath`. Everything else
(properties, macros, ``xacro:arg`` / ``$(arg)``, includes relative to the including file,
conditionals, in-order processing, the output formatting) is xacro's own.

The hook point is pinned (:data:`XACRO_PINNED_VERSION`); :func:`check_xacro_hook` fails with
a clear :class:`XacroError` if an upgrade moved it, and a test calls it.
"""

from __future__ import annotations

import contextlib
import importlib.metadata
import io
import logging
import threading
import xml.parsers.expat
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any, Final

import xacro
import xacro.substitution_args

from roverlab.description.errors import DescriptionError, PackageNotFoundError, XacroError
from roverlab.description.packages import PackagePath

__all__ = [
    "XACRO_HOOK",
    "XACRO_PINNED_VERSION",
    "check_xacro_hook",
    "xacro_file",
    "xacro_string",
]

XACRO_PINNED_VERSION: Final = "2.1"
"""The xacro release series (major.minor) whose internals the hook relies on."""
XACRO_HOOK: Final = ("xacro.substitution_args", "_eval_find")
"""Module and function replaced to resolve ``$(find pkg)``."""
_XACRO_API: Final = ("process_file", "process_doc", "parse", "init_stacks", "XacroException")

_LOCK = threading.RLock()  # xacro keeps its state in module globals
_log = logging.getLogger("roverlab.description")


def check_xacro_hook() -> None:
    """Check that the installed xacro is the pinned series and still has the hook point.

    Raises:
        XacroError: another xacro series, or the function roverlab replaces is gone.
    """
    try:
        version = importlib.metadata.version("xacro")
    except importlib.metadata.PackageNotFoundError:
        version = "unknown"
    sa = xacro.substitution_args
    problems: list[str] = []
    if not version.startswith(XACRO_PINNED_VERSION + "."):
        problems.append(f"xacro {version} installed, roverlab supports {XACRO_PINNED_VERSION}.x")
    if not callable(getattr(sa, XACRO_HOOK[1], None)):
        problems.append(f"{'.'.join(XACRO_HOOK)} is missing")
    if not isinstance(getattr(sa, "_eval_dict", None), dict) or "find" not in sa._eval_dict:
        problems.append("xacro.substitution_args._eval_dict['find'] is missing")
    problems.extend(f"xacro.{name} is missing" for name in _XACRO_API if not hasattr(xacro, name))
    if problems:
        raise XacroError(
            "cannot hook $(find) into xacro: " + "; ".join(problems) + f" (pip install "
            f"'xacro>={XACRO_PINNED_VERSION},<{_next_minor(XACRO_PINNED_VERSION)}')"
        )


def _next_minor(series: str) -> str:
    major, minor = series.split(".")
    return f"{major}.{int(minor) + 1}"


@contextlib.contextmanager
def _find_hooked(find: Callable[[str], str]) -> Iterator[None]:
    sa = xacro.substitution_args
    old_function, old_eval = sa._eval_find, sa._eval_dict["find"]
    sa._eval_find = find
    sa._eval_dict["find"] = find
    try:
        yield
    finally:
        sa._eval_find = old_function
        sa._eval_dict["find"] = old_eval


def _where(label: str) -> str:
    """The file being processed when xacro failed (and the top file if different)."""
    files = [str(f) for f in (xacro.filestack or []) if f]
    if not files:
        return label
    inner = files[-1]
    return inner if inner == files[0] else f"{inner} (included from {files[0]})"


def _macros() -> str:
    names = [m.body.getAttribute("name") for m in (xacro.macrostack or []) if m.body is not None]
    return "".join(f"in macro '{n}': " for n in reversed(names))


def _one_line(text: str) -> str:
    return " ".join(text.split())


def _translate(err: Exception, label: str) -> XacroError:
    where = _where(label)
    context = _macros()
    cause = getattr(err, "exc", None)
    if isinstance(cause, PackageNotFoundError):
        return XacroError(f"{where}: {context}$(find): {cause}")
    if isinstance(cause, OSError) and getattr(cause, "filename", None):
        return XacroError(
            f"{where}: {context}<xacro:include filename='{cause.filename}'>: "
            f"{cause.strerror or 'cannot open'}"
        )
    if isinstance(cause, xacro.substitution_args.ArgException):
        name = str(cause)
        return XacroError(
            f"{where}: {context}$(arg {name}): undefined xacro argument "
            f"(declare <xacro:arg name='{name}'> or pass {name}:=value)"
        )
    return XacroError(f"{where}: {context}{_one_line(str(err)) or type(err).__name__}")


def _expand(
    path: Path | None, text: str | None, args: Mapping[str, str], packages: PackagePath
) -> str:
    check_xacro_hook()
    label = str(path) if path is not None else "<string>"

    def find(name: str) -> str:
        return str(packages.find(name))

    captured = io.StringIO()
    with _LOCK:
        old_verbosity = xacro.verbosity
        try:
            with _find_hooked(find), contextlib.redirect_stderr(captured):
                doc: Any
                if path is not None:
                    doc = xacro.process_file(str(path), mappings=dict(args), verbosity=0)
                else:
                    xacro.init_stacks(None)
                    doc = xacro.parse(text)
                    xacro.process_doc(doc, mappings=dict(args), verbosity=0)
                result: str = doc.toprettyxml(indent="  ")
        except xml.parsers.expat.ExpatError as err:
            raise XacroError(f"{_where(label)}: XML parse error: {err}") from err
        except DescriptionError:
            raise
        except RecursionError as err:
            raise XacroError(f"{_where(label)}: {_macros()}recursion too deep") from err
        except Exception as err:  # xacro raises XacroException, but also plain errors
            raise _translate(err, label) from err
        finally:
            xacro.verbosity = old_verbosity
            xacro.substitution_args_context["arg"] = {}
            del xacro.all_includes[:]
    for line in captured.getvalue().splitlines():
        if line.strip():
            _log.warning("xacro: %s: %s", label, line.strip())
    return result


def xacro_file(
    path: str | Path,
    *,
    args: Mapping[str, str] | None = None,
    package_path: PackagePath | None = None,
) -> str:
    """Expand a xacro file: what ``xacro path name:=value ...`` prints.

    Args:
        path: the ``.xacro`` / ``.urdf.xacro`` file.
        args: xacro arguments (``laser_visual:=true`` is ``{"laser_visual": "true"}``).
        package_path: where ``$(find pkg)`` looks (default: environment + bundled).

    Returns:
        The expanded XML document, formatted as xacro writes it.

    Raises:
        XacroError: one line naming the file (and macro) at fault.
    """
    p = Path(path)
    if not p.is_file():
        raise XacroError(f"{p}: no such file")
    return _expand(p.resolve(), None, args or {}, package_path or PackagePath())


def xacro_string(
    xml_text: str,
    *,
    args: Mapping[str, str] | None = None,
    package_path: PackagePath | None = None,
) -> str:
    """Expand a xacro document given as a string (relative includes resolve from the cwd).

    Raises:
        XacroError: one line naming the element or macro at fault.
    """
    return _expand(None, xml_text, args or {}, package_path or PackagePath())
