"""``roverlab launch``: run a roslaunch ``.launch`` file with roverlab's nodes."""

from __future__ import annotations

import contextlib
import glob
import math
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated

import typer

from roverlab.cli.common import (
    StartGuard,
    expose_if_asked,
    report_notes,
    report_warnings,
    run_context,
)
from roverlab.cli.roscore import ensure_master
from roverlab.cli.sim import parse_rate
from roverlab.core import Context, configure_logging
from roverlab.core.transport.ros1.master import Master
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.description import find_package
from roverlab.launch import LaunchError, LaunchSpec, build_launch, find_launch_scripts, load_launch
from roverlab.launch.process import launch_endpoint

CLOCKS = ("auto", "sim", "external", "wall")
_SIMULATOR_NODES = {("gazebo_ros", "gzserver"), ("gazebo_ros", "spawn_model")}
_DEVICE_NODES = {
    ("arbotix_python", "arbotix_driver"),
    ("rplidar_ros", "rplidarNode"),
    ("rplidar_ros", "rplidar_node"),
    ("usb_cam", "usb_cam_node"),
    ("ros_arduino_python", "arduino_node.py"),
    ("roborts_base", "roborts_base_node"),
}


def choose_clock(spec: LaunchSpec, clock: str, pace: float) -> tuple[str, str]:
    """The context's clock mode for a launch, and a note saying why.

    ``auto``: a launch with a simulator (gzserver / spawn_model) runs it on its own clock
    (paced by ``--rate``); one without follows ``/clock`` from another process (a
    ``roverlab sim`` in another terminal: what ROS does with ``/use_sim_time`` true, which
    a Gazebo launch sets for everybody), unless the file sets ``/use_sim_time`` false or
    starts a driver node (arbotix, a lidar, a camera, a serial base: a real robot or
    arbotix's fake one), which means wall time.
    """
    if clock not in CLOCKS:
        raise LaunchError(f"unknown --clock {clock!r} ({', '.join(CLOCKS)})")
    own = "sim" if math.isinf(pace) else "paced"
    if clock == "sim":
        return own, ""
    if clock != "auto":
        return clock, ""
    if any((n.pkg, n.type) in _SIMULATOR_NODES for n in spec.nodes):
        return own, ""
    if spec.params.get("/use_sim_time") is False:
        return "wall", "no simulator in this launch and /use_sim_time is false: wall time"
    if any((n.pkg, n.type) in _DEVICE_NODES for n in spec.nodes):
        return "wall", (
            "driver nodes (arbotix, a lidar, a camera, a serial base) and no simulator in this "
            "launch: wall time, as ROS without /use_sim_time"
        )
    return "external", (
        "no simulator in this launch: following /clock from another process "
        "(start `roverlab sim` elsewhere, or pass --clock wall)"
    )


@contextlib.contextmanager
def _stopping(master: Master | None) -> Iterator[None]:
    """Stop the ROS master this launch started (if any) when the launch ends."""
    try:
        yield
    finally:
        if master is not None:
            master.stop()


@contextlib.contextmanager
def _script_endpoint(needed: bool) -> Iterator[tuple[str, ...]]:
    """The endpoint the launch's script processes join it by (a Unix socket in a private
    temporary folder, removed at the end), when it has script nodes."""
    if not needed:
        yield ()
        return
    folder = Path(tempfile.mkdtemp(prefix="roverlab-launch-"))
    try:
        yield (launch_endpoint(folder),)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _resolve(target: list[str]) -> tuple[Path, dict[str, str]]:
    """``PKG FILE`` or ``PATH``, followed by ``name:=value`` arguments (as roslaunch)."""
    plain = [t for t in target if ":=" not in t]
    args = dict(t.split(":=", 1) for t in target if ":=" in t)
    if len(plain) == 1:
        return Path(plain[0]), args
    if len(plain) == 2:
        pkg_dir = find_package(plain[0])
        matches = sorted(pkg_dir.rglob(glob.escape(plain[1])))  # the exact name, no pattern
        if not matches:
            raise LaunchError(
                f"launch file {plain[1]!r} not found in package {plain[0]} ({pkg_dir})"
            )
        return matches[0], args
    raise LaunchError("usage: roverlab launch PKG FILE.launch [name:=value ...] or PATH.launch")


def launch(
    ctx: typer.Context,
    target: Annotated[
        list[str],
        typer.Argument(
            metavar="[PKG] FILE [name:=value ...]", help="A package and launch file, or a path."
        ),
    ],
    rate: Annotated[
        str, typer.Option("--rate", help="Sim seconds per wall second, or 'max'.")
    ] = "1",
    duration: Annotated[
        float | None, typer.Option("--duration", help="Stop after this many sim seconds.")
    ] = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed of every random draw.")] = 0,
    record: Annotated[
        Path | None, typer.Option("--record", help="Record every topic to this MCAP file.")
    ] = None,
    expose: Annotated[
        bool | None,
        typer.Option(
            "--expose/--no-expose",
            help="Make the topics visible to other processes. Default: yes, except at "
            "--rate max, which runs privately.",
        ),
    ] = None,
    clock: Annotated[
        str,
        typer.Option(
            "--clock",
            help="auto: the launch's own clock when it starts a simulator, else follow /clock "
            "from another process (wall time if the file sets /use_sim_time false); sim: "
            "always its own clock (paced by --rate); external; wall.",
        ),
    ] = "auto",
    strict: Annotated[
        bool,
        typer.Option(
            "--strict",
            help="Make every warning (a node roverlab does not have, an unused parameter, "
            "a world model or mesh not found, an unsupported robot plugin) an error.",
        ),
    ] = False,
) -> None:
    """Run a .launch file (roslaunch): its nodes, its Gazebo world and spawned robot."""
    path, args = _resolve(target)
    pace = parse_rate(rate)
    configure_logging()
    spec = load_launch(path, args)  # read once: <param command=...> runs commands (xacro)
    mode, note = choose_clock(spec, clock, pace)
    if note:
        typer.echo(f"note: {note}", err=True)
    # script nodes run in processes of their own, clients of this one (a private run too);
    # each looked up once, here, and started from that by build_launch
    scripts = find_launch_scripts(spec)
    runs_scripts = any(isinstance(found, Path) for found in scripts.values())
    context = Context(clock=mode, rate=1.0 if math.isinf(pace) else pace)
    guard = StartGuard(context)
    ros_master = ensure_master()  # ROS_MASTER_URI and nobody there: start one, as roslaunch
    with _script_endpoint(runs_scripts) as also_listen, _stopping(ros_master):
        with guard:
            if record is not None:
                guard.record(record)
            expose_if_asked(ctx, context, expose, pace, also_listen=also_listen)
            for t in context.transports:  # a ROS 1 graph: the parameters go to its master
                if isinstance(t, Ros1Transport):
                    report_warnings("ROS 1 parameters", t.set_params(spec.params), strict)
            started = build_launch(spec, context=context, seed=seed, scripts=scripts)
        with guard:
            report_warnings(f"launch {path.name}", started.warnings, strict)
            report_warnings("Gazebo world", started.world_warnings, strict)
            report_warnings("spawned robot", started.robot_warnings, strict)
            report_notes(started.notes)
        names = ", ".join(n.get_fully_qualified_name() for n in started.nodes)
        typer.echo(f"started {len(started.nodes)} nodes: {names}", err=True)
        for name, (_, proc) in started.processes.items():
            typer.echo(f"started process [{name}] (pid {proc.pid}): {proc.script}", err=True)
        started.supervise()
        wall = run_context(context, duration, started.stop_processes)
    ran = "" if mode == "wall" else f"{context.now().seconds:.1f} sim s, "
    typer.echo(f"launch stopped after {ran}{wall:.1f} s wall", err=True)
