"""``roverlab run``: rosrun — a ROS 1 Python script, or a node of roverlab's registry."""

from __future__ import annotations

import os
import shlex
from pathlib import Path
from typing import Annotated

import typer

from roverlab.cli.common import connect_following_clock, network_options, run_context
from roverlab.core import Context, Node, configure_logging
from roverlab.errors import RoverlabError
from roverlab.launch.process import ScriptLookupError, find_script
from roverlab.launch.registry import REGISTRY, LaunchState, rosrun_name
from roverlab.launch.xml import NodeSpec
from roverlab.ros1 import run_script
from roverlab.ros1.rospy.runtime import parse_command_line
from roverlab.ros1.runner import python2_problem


class RunError(RoverlabError):
    """``roverlab run`` cannot start what it was asked to."""


def _resolve(target: list[str]) -> tuple[Path | None, NodeSpec | None, list[str]]:
    """A script path, or a registry node, and the rest of the arguments."""
    first = target[0]
    if Path(first).is_file():
        return Path(first), None, target[1:]
    if len(target) < 2:
        raise RunError(f"{first}: no such file (usage: roverlab run SCRIPT.py | PKG TYPE)")
    pkg, type_ = target[0], target[1]
    rest = target[2:]
    if (pkg, type_) in REGISTRY:
        cl = parse_command_line(rest)
        spec = NodeSpec(
            pkg=pkg,
            type=type_,
            name=cl.special.get("__name", rosrun_name(pkg, type_)),
            namespace=cl.special.get("__ns", "/"),
            args=" ".join(shlex.quote(a) for a in cl.plain),
            params=dict(cl.params),
            remaps=dict(cl.remaps),
            source=f"roverlab run {pkg} {type_}",
        )
        return None, spec, rest
    return _package_script(pkg, type_), None, rest


def _package_script(pkg: str, type_: str) -> Path:
    """The one file named ``type_`` (or at the path ``type_`` inside it) in package ``pkg``
    (``roverlab launch``'s lookup), as rosrun picks it; a file without the executable bit,
    which rosrun refuses, is noted.

    Raises:
        RunError: no such package or file, a path outside the package, several files of
            that name, not a Python script.
    """
    try:
        script = find_script(pkg, type_)
    except ScriptLookupError as err:
        joint = " not a roverlab node, and" if err.missing else ""
        raise RunError(f"{pkg} {type_}:{joint} {err}") from None
    if not os.access(script, os.X_OK):  # rosrun: "Couldn't find executable named ..."
        typer.echo(
            f"note: {script} is not executable (rosrun refuses it; chmod +x it for ROS): "
            "run anyway",
            err=True,
        )
    return script


def run(
    ctx: typer.Context,
    target: Annotated[
        list[str],
        typer.Argument(
            metavar="SCRIPT.py [ARGS...] | PKG TYPE [ARGS...]",
            help="A ROS 1 Python script, a script in a package, or a roverlab node "
            "(e.g. map_server map_server maze.yaml). ARGS may hold name:=value remaps, "
            "_param:=value private parameters, __name:= and __ns:=.",
        ),
    ],
    clock: Annotated[
        str,
        typer.Option(
            "--clock",
            help="auto: sim time from /clock when something publishes it, else wall time; "
            "wall; external (wait for /clock).",
        ),
    ] = "auto",
) -> None:
    """Run a rospy script unchanged (import rospy, actionlib, ..._msgs) or a node (rosrun).

    Options for roverlab go before the target; everything after it goes to the script.
    """
    script, spec, rest = _resolve(list(target) + list(ctx.args))
    problem = None if script is None else python2_problem(script)
    if problem is not None:  # refused before joining the network (or starting its daemon)
        typer.echo(f"error: {problem}", err=True)
        raise typer.Exit(1)
    transport, mode, note = connect_following_clock(network_options(ctx), clock)
    if note:
        typer.echo(f"note: {note}", err=True)
    context = Context(clock=mode, publish_clock=False)
    context.add_transport(transport)  # the context closes it on shutdown
    if script is not None:
        try:
            code = run_script(script, rest, context)
        finally:
            context.shutdown()
        if code:
            raise typer.Exit(code)
        return
    assert spec is not None
    configure_logging()
    try:
        node: Node | None = REGISTRY[(spec.pkg, spec.type)](
            LaunchState(context=context, params={}), spec
        )
    except BaseException:
        context.shutdown()
        raise
    if node is not None:
        unused = node.unused_parameter_overrides()
        if unused:
            typer.echo(
                f"warning: parameters not used by {spec.pkg}/{spec.type}: "
                f"{', '.join(sorted(unused))}",
                err=True,
            )
            node.discard_parameter_overrides(unused)
    if node is None:
        run_context(context, None)
        return
    # a node that ends itself (map_saver once the map is written) ends the run, as its
    # ROS process exits
    run_context(context, None, until=node.is_destroyed)
    if node.exit_code:
        raise typer.Exit(node.exit_code)
