"""``roverlab patrol``: seed 002's slam.py as a command — patrol places through move_base."""

from __future__ import annotations

import math
import signal
import sys
import time
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from roverlab.cli.common import connect_following_clock, network_options
from roverlab.core import Context
from roverlab.description import find_package
from roverlab.msgs import Twist
from roverlab.navigation.patrol import PatrolError, load_places
from roverlab.navigation.patrol_client import Patroller


def _default_locations() -> Path:
    return find_package("robot_navigation") / "config" / "patrol.yaml"


def patrol(
    ctx: typer.Context,
    locations: Annotated[
        Path | None,
        typer.Option(
            "--locations",
            help="YAML of places (frame_id, locations: {name: {x, y, yaw}}); default: six "
            "places in seed 003's maze (robot_navigation/config/patrol.yaml).",
        ),
    ] = None,
    goals: Annotated[
        int, typer.Option("--goals", help="Stop after this many goals (0: until Ctrl-C).")
    ] = 0,
    rest_time: Annotated[
        float, typer.Option("--rest-time", help="Seconds to rest at each place (slam.py: 2).")
    ] = 2.0,
    timeout: Annotated[
        float, typer.Option("--timeout", help="Seconds per goal before it is canceled (300).")
    ] = 300.0,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the random order.")] = 0,
    action: Annotated[
        str, typer.Option("--action", help="The move_base action's name.")
    ] = "move_base",
    clock: Annotated[
        str,
        typer.Option(
            "--clock",
            help="auto: sim time from /clock when something publishes it, else wall; "
            "wall; external.",
        ),
    ] = "auto",
) -> None:
    """Patrol places in random order through move_base, as seed 002's slam.py: per-goal
    timeout with cancel, the goal state's name on failure, success rate, time and distance;
    a zero Twist on exit. Exit status 0 when every goal succeeded, else 1."""
    for name, value in (("--rest-time", rest_time), ("--timeout", timeout)):
        if not (math.isfinite(value) and value >= 0):
            raise PatrolError(f"{name} must be a number >= 0, got {value}")
    if goals < 0:
        raise PatrolError(f"--goals must be >= 0, got {goals}")
    frame, places = load_places(locations or _default_locations())
    transport, mode, note = connect_following_clock(network_options(ctx), clock)
    if note:
        typer.echo(f"note: {note}", err=True)
    context = Context(clock=mode, publish_clock=False)
    context.add_transport(transport)
    try:
        code = _run(context, frame, places, goals, rest_time, timeout, seed, action)
    finally:
        context.shutdown()
    if code:
        raise typer.Exit(code)


def _run(
    context: Context,
    frame: str,
    places: list[Any],
    goals: int,
    rest_time: float,
    timeout: float,
    seed: int,
    action: str,
) -> int:
    node = context.create_node("patrol")
    cmd_pub = node.create_publisher(Twist, "cmd_vel", 5)

    def log(text: str) -> None:
        now = context.executor.clock_now_ns() / 1e9
        sys.stdout.write(f"[INFO] [{now:.6f}]: {text}\n")
        sys.stdout.flush()

    patroller = Patroller(
        node,
        places,
        frame,
        rng=np.random.default_rng(seed),
        rest_time=rest_time,
        timeout=timeout,
        log=log,
        action=action,
    )
    context.spin_in_thread()

    def on_signal(signum: int, _frame: Any) -> None:
        patroller.stop.set()

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        patroller.wait_for_server()
        if not patroller.stop.is_set():
            patroller.run(goals)
    finally:
        patroller.shutdown(lambda: cmd_pub.publish(Twist()))
        time.sleep(0.2)  # let the cancel and the zero Twist leave
        for s, handler in old.items():
            signal.signal(s, handler)
    stats = patroller.stats
    typer.echo(
        f"patrol: {stats.successes}/{stats.goals} goals succeeded, "
        f"{stats.distance_m:.1f} m between the places reached",
        err=True,
    )
    return 0 if stats.goals and stats.successes == stats.goals else 1
