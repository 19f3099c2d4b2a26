"""Run a ROS 1 Python script against roverlab (``roverlab run SCRIPT.py``)."""

from __future__ import annotations

import os
import runpy
import sys
import traceback
from pathlib import Path

from roverlab.core import Context
from roverlab.ros1.importer import install
from roverlab.ros1.rospy.runtime import RUNTIME

__all__ = ["run_script"]


def _exit_code(code: object) -> int:
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)
    return 1


_PY2_HINTS = (
    ("Missing parentheses in call to 'print'", "a print statement: write print(...)"),
    ("Missing parentheses in call to 'exec'", "an exec statement: write exec(...)"),
    ("leading zeros in decimal integer", "an octal literal like 0777: write 0o777"),
    ("multiple exception types must be parenthesized", "'except E, e:': write 'except E as e:'"),
)


def python2_problem(path: Path) -> str | None:
    """One line naming the file, the line and the Python 3 fix if ``path`` is Python 2 code
    (or does not compile at all), else ``None``."""
    try:
        source = path.read_bytes()
    except OSError as err:
        return f"{path}: cannot read: {err.strerror or err}"
    try:
        compile(source, str(path), "exec")
    except SyntaxError as err:
        msg = err.msg or "invalid syntax"
        text = (err.text or "").strip()
        where = f"{path}:{err.lineno}"
        for needle, fix in _PY2_HINTS:
            if needle in msg:
                return f"{where}: Python 2 code, {fix} (roverlab runs Python 3, as ROS noetic)"
        if text.startswith(("print ", "print>>")):
            return f"{where}: Python 2 code, a print statement: write print(...) (Python 3)"
        if "`" in text:
            return f"{where}: Python 2 code, backquotes: write repr(...) (Python 3)"
        if "<>" in text:
            return f"{where}: Python 2 code, '<>': write '!=' (Python 3)"
        if text.startswith("raise ") and "," in text:
            return f"{where}: Python 2 code, 'raise E, msg': write 'raise E(msg)' (Python 3)"
        return f"{where}: {msg}: {text}"
    return None


def run_script(path: str | os.PathLike[str], argv: list[str], context: Context) -> int:
    """Run ``path`` as ``__main__`` with ``sys.argv = [path, *argv]`` on ``context``.

    The script's ``rospy.init_node`` joins ``context`` (which the caller created, with its
    clock and transports, and shuts down afterwards). When the script ends the node shuts
    down as rospy's does (``on_shutdown`` hooks run), and what it published is flushed.

    Returns:
        The exit status: the script's ``sys.exit`` code, 1 after an uncaught exception
        (its traceback printed, as ``python SCRIPT.py`` would), 130 after a second Ctrl-C.
    """
    script = Path(path)
    problem = python2_problem(script)
    if problem is not None:
        print(f"error: {problem}", file=sys.stderr)
        return 1
    install()
    RUNTIME.configure(context, list(argv))
    old_argv, old_path = sys.argv, list(sys.path)
    sys.argv = [str(script), *argv]
    sys.path.insert(0, str(script.resolve().parent))  # what `python SCRIPT.py` does
    code = 0
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as stop:
        code = _exit_code(stop.code)
    except KeyboardInterrupt:
        code = 130
    except Exception:
        traceback.print_exc()
        code = 1
    finally:
        try:
            if RUNTIME.node is not None and not RUNTIME.in_shutdown:
                RUNTIME.signal_shutdown("the script ended")
            RUNTIME.wait_for_hooks(30.0)
            RUNTIME.flush()
        finally:
            sys.argv = old_argv
            sys.path[:] = old_path
            RUNTIME.reset()
    return code
