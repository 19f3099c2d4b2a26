"""xacro expansion with ``$(find pkg)`` resolved through roverlab's package path.

The ``xacro`` PyPI package (2.1.x, the ROS 2 release) resolves ``$(find pkg)`` with
``ament_index_python``, which needs a ROS 2 install. roverlab replaces that one function,
``xacro.substitution_args._eval_find`` (and its entry in ``_eval_dict``, used by
``$(eval find('pkg'))``), for the duration of each expansion, under a lock, so ``$(find)``
looks packages up in :class:`~roverlab.description.packages.PackagePath`. Everything else
(properties, macros, ``xacro:arg`` / ``$(arg)``, includes relative to the including file,
conditionals, in-order processing, the output formatting) is xacro's own.

ROS 1's xacro (kinetic, melodic) also accepted the xacro tags without their ``xacro:``
prefix (``<property>``, ``<macro>``, ``<include>``, ``<if>``, ``<unless>``, ``<arg>``,
``<insert_block>``) and macro calls without it (``<robot_body/>``), with a deprecation
warning; the 2.1 series (ROS 2) ignores them, so a ROS 1 robot expands to no links. Unless
``xacro_ns=True`` (ROS 1's ``--xacro-ns``), :func:`_ros1_hooked` wraps ``xacro.eval_all``
(to give un-prefixed xacro tags their prefix before xacro looks at them) and
``xacro.handle_macro_call`` (to call a defined macro named without the prefix), and the
expansion logs ROS 1's warning once, naming the file and the tag.

The hook points are pinned (:data:`XACRO_PINNED_VERSION`); :func:`check_xacro_hook` fails
with a clear :class:`XacroError` if an upgrade moved them, and a test calls it.
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
_XACRO_API: Final = (
    "process_file",
    "process_doc",
    "parse",
    "init_stacks",
    "XacroException",
    "eval_all",
    "handle_macro_call",
    "resolve_macro",
)
ROS1_TAGS: Final = frozenset(
    {"property", "macro", "include", "if", "unless", "arg", "insert_block"}
)
"""xacro tags ROS 1's xacro accepted without the ``xacro:`` prefix (with a warning)."""
ROS1_DEPRECATION: Final = "deprecated: xacro tags should be prepended with 'xacro' xml namespace."
"""The warning ROS 1's xacro printed for an un-prefixed tag."""

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


def _ros1_include(node: Any) -> bool:
    """ROS 1's rule: a plain ``<include>`` with child elements (Gazebo's ``<uri>``) is not
    xacro's."""
    return not any(c.nodeType == c.ELEMENT_NODE for c in node.childNodes)


@contextlib.contextmanager
def _ros1_hooked(deprecated: list[str]) -> Iterator[None]:
    """Accept ROS 1's un-prefixed xacro tags and macro calls; record each use in
    ``deprecated`` as ``"file: <tag>"``."""
    eval_all, handle_macro_call = xacro.eval_all, xacro.handle_macro_call

    def note(tag: str) -> None:
        files = [str(f) for f in (xacro.filestack or []) if f]
        deprecated.append(f"{files[-1] if files else '<string>'}: <{tag}>")

    def rename(node: Any, tag: str) -> None:
        note(tag)
        node.tagName = node.nodeName = "xacro:" + tag

    def ros1_eval_all(node: Any, macros: Any, symbols: Any) -> Any:
        for child in node.childNodes:
            if child.nodeType != child.ELEMENT_NODE or child.tagName not in ROS1_TAGS:
                continue
            if child.tagName != "include" or _ros1_include(child):
                rename(child, child.tagName)
        return eval_all(node, macros, symbols)

    def ros1_macro_call(node: Any, macros: Any, symbols: Any) -> Any:
        tag = node.tagName
        if not tag.startswith("xacro:") and ":" not in tag:
            try:
                xacro.resolve_macro(tag, macros, symbols)
            except (KeyError, TypeError, AttributeError):
                pass  # not a macro: an ordinary element
            else:
                rename(node, tag)
        return handle_macro_call(node, macros, symbols)

    xacro.eval_all, xacro.handle_macro_call = ros1_eval_all, ros1_macro_call
    try:
        yield
    finally:
        xacro.eval_all, xacro.handle_macro_call = eval_all, handle_macro_call


def _deprecation_line(uses: list[str]) -> str:
    """ROS 1's warning, once, with the un-prefixed tags each file used."""
    by_file: dict[str, list[str]] = {}
    for use in uses:
        file, _, tag = use.rpartition(": ")
        tags = by_file.setdefault(file, [])
        if tag not in tags:
            tags.append(tag)
    where = "; ".join(f"{f}: {', '.join(t)}" for f, t in by_file.items())
    return (
        f"{ROS1_DEPRECATION} Accepted as ROS 1's xacro (kinetic, melodic) did: {where} "
        "(noetic's and ROS 2's xacro refuse them: write <xacro:NAME ...>)"
    )


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


def _cause(err: BaseException) -> BaseException | None:
    """What went wrong under xacro's wrapping: an expression (``${load_yaml('$(find x)/a')}``)
    wraps the error once more for each enclosing expression, so follow ``exc`` (and the
    exception chain) down to the first error that is not xacro's own."""
    seen: set[int] = set()
    cause: BaseException | None = getattr(err, "exc", None)
    while cause is not None and id(cause) not in seen:
        seen.add(id(cause))
        if not isinstance(cause, xacro.XacroException):
            return cause
        cause = getattr(cause, "exc", None) or cause.__cause__ or cause.__context__
    return None


def _translate(err: Exception, label: str) -> XacroError:
    where = _where(label)
    context = _macros()
    cause = _cause(err)
    if isinstance(cause, PackageNotFoundError):
        return XacroError(f"{where}: {context}$(find): {cause}")
    if isinstance(cause, OSError) and getattr(cause, "filename", None):
        included = cause is getattr(err, "exc", None)  # xacro's include, not load_yaml
        if included:
            return XacroError(
                f"{where}: {context}<xacro:include filename='{cause.filename}'>: "
                f"{cause.strerror or 'cannot open'}"
            )
        return XacroError(
            f"{where}: {context}cannot read {cause.filename}: {cause.strerror or 'cannot open'}"
        )
    if isinstance(cause, xacro.substitution_args.ArgException):
        name = str(cause)
        return XacroError(
            f"{where}: {context}$(arg {name}): undefined xacro argument "
            f"(declare <xacro:arg name='{name}'> or pass {name}:=value)"
        )
    return XacroError(f"{where}: {context}{_one_line(str(err)) or type(err).__name__}")


def _expand(
    path: Path | None,
    text: str | None,
    args: Mapping[str, str],
    packages: PackagePath,
    xacro_ns: bool = False,
) -> str:
    check_xacro_hook()
    label = str(path) if path is not None else "<string>"

    def find(name: str) -> str:
        return str(packages.find(name))

    captured = io.StringIO()
    deprecated: list[str] = []
    ros1 = contextlib.nullcontext() if xacro_ns else _ros1_hooked(deprecated)
    with _LOCK:
        old_verbosity = xacro.verbosity
        try:
            with _find_hooked(find), ros1, contextlib.redirect_stderr(captured):
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
    if deprecated:
        _log.warning("xacro: %s", _deprecation_line(deprecated))
    return result


def xacro_file(
    path: str | Path,
    *,
    args: Mapping[str, str] | None = None,
    package_path: PackagePath | None = None,
    xacro_ns: bool = False,
) -> str:
    """Expand a xacro file: what ``xacro path name:=value ...`` prints.

    Args:
        path: the ``.xacro`` / ``.urdf.xacro`` file.
        args: xacro arguments (``laser_visual:=true`` is ``{"laser_visual": "true"}``).
        package_path: where ``$(find pkg)`` looks (default: environment + bundled).
        xacro_ns: ROS 1's ``--xacro-ns``: only ``xacro:``-prefixed tags are xacro's
            (default: ROS 1's un-prefixed forms are accepted, with its warning).

    Returns:
        The expanded XML document, formatted as xacro writes it.

    Raises:
        XacroError: one line naming the file (and macro) at fault.
    """
    p = Path(path)
    if not p.is_file():
        raise XacroError(f"{p}: no such file")
    return _expand(p.resolve(), None, args or {}, package_path or PackagePath(), xacro_ns)


def xacro_string(
    xml_text: str,
    *,
    args: Mapping[str, str] | None = None,
    package_path: PackagePath | None = None,
    xacro_ns: bool = False,
) -> str:
    """Expand a xacro document given as a string (relative includes resolve from the cwd).

    Raises:
        XacroError: one line naming the element or macro at fault.
    """
    return _expand(None, xml_text, args or {}, package_path or PackagePath(), xacro_ns)
