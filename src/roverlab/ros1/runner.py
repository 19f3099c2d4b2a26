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
