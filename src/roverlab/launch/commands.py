"""``<param command="...">``: xacro in-process (ROS 1's spellings), other commands as
roslaunch runs them: split with :func:`shlex.split` and run without a shell (``$VAR``,
pipes, ``;`` and ``>`` are not interpreted)."""

from __future__ import annotations

import shlex
import subprocess
from pathlib import Path

from roverlab.description import robot_description
from roverlab.description.errors import DescriptionError
from roverlab.launch.errors import LaunchError

__all__ = ["command_value", "xacro_argv", "xacro_input"]


def command_value(command: str, where: str, package_path: tuple[str, ...] = ()) -> str:
    """The output of ``command`` (``where`` names the file and element in errors): xacro
    runs in-process (roverlab's hooked xacro); others as roslaunch runs them, split with
    ``shlex`` and without a shell.

    Raises:
        LaunchError: the command cannot be parsed, is not found or exits non-zero.
    """
    try:
        argv = shlex.split(command)
    except ValueError as err:
        raise LaunchError(f"{where}: cannot parse command {command!r}: {err}") from err
    if not argv:
        raise LaunchError(f"{where}: empty command")
    xacro = xacro_argv(argv)
    if xacro is not None:
        return _xacro(xacro, where, package_path)
    try:
        done = subprocess.run(argv, capture_output=True, text=True, check=False)
    except OSError as err:
        what = "no such command" if isinstance(err, FileNotFoundError) else err.strerror
        raise LaunchError(f"{where}: command {command!r}: {argv[0]}: {what}") from err
    if done.returncode != 0:
        first = (done.stderr.strip().splitlines() or ["no output"])[0]
        raise LaunchError(f"{where}: command {command!r} exited {done.returncode}: {first}")
    return done.stdout


def xacro_input(command: str) -> str | None:
    """The file a ``command=`` running xacro reads (as its messages name it), else
    ``None`` (another command, or one :func:`command_value` refuses)."""
    try:
        xacro = xacro_argv(shlex.split(command))
        return None if xacro is None else _xacro_options(xacro, "")[0]
    except (ValueError, LaunchError):
        return None


def _xacro(argv: list[str], where: str, package_path: tuple[str, ...]) -> str:
    path, mappings, xacro_ns = _xacro_options(argv, where)
    try:
        return robot_description(Path(path), mappings, package_path=package_path, xacro_ns=xacro_ns)
    except DescriptionError as err:
        raise LaunchError(f"{where}: {err}") from err


def _xacro_options(argv: list[str], where: str) -> tuple[str, dict[str, str], bool]:
    """ROS 1's xacro command line: ``--inorder`` / ``-i`` (the default since melodic,
    accepted and ignored), ``--xacro-ns``, ``-o FILE`` (the output is the parameter
    anyway), ``name:=value`` mappings and one input file: the file, the mappings and
    ``--xacro-ns``."""
    files: list[str] = []
    mappings: dict[str, str] = {}
    xacro_ns = False
    skip = False
    for a in argv:
        if skip:
            skip = False
        elif a in ("--inorder", "-i", "--legacy", "--check-order"):
            continue
        elif a == "--xacro-ns":
            xacro_ns = True
        elif a in ("-o", "--output"):
            skip = True
        elif ":=" in a:
            name, value = a.split(":=", 1)
            mappings[name] = value
        elif a.startswith("-"):
            raise LaunchError(f"{where}: xacro option {a!r} is not supported")
        else:
            files.append(a)
    if len(files) != 1:
        raise LaunchError(f"{where}: xacro command needs one input file")
    return files[0], mappings, xacro_ns


def xacro_argv(argv: list[str]) -> list[str] | None:
    """The xacro arguments of a ``command=`` running xacro in any of ROS 1's spellings
    (``xacro``, ``xacro.py``, ``$(find xacro)/xacro[.py]``, ``python[3] .../xacro.py``,
    ``rosrun xacro xacro[.py]``), else ``None``."""
    rest = list(argv)
    if rest and Path(rest[0]).name in ("python", "python2", "python3"):
        rest = rest[1:]
    if len(rest) >= 3 and rest[0] == "rosrun" and rest[1] == "xacro":
        rest = rest[2:]
    if rest and Path(rest[0]).name in ("xacro", "xacro.py"):
        return rest[1:]
    return None
