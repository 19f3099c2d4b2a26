"""``roverlab topic``: list, echo, pub, hz, info — the rostopic / ros2 topic habits."""

from __future__ import annotations

import math
import sys
import time
from typing import Annotated, Any

import numpy as np
import typer
import yaml

from roverlab.cli.common import Connection, network_options
from roverlab.core import QoSProfile
from roverlab.core.errors import GraphError
from roverlab.core.graph import resolve_name
from roverlab.core.transport.zenoh import GraphEntity
from roverlab.msgs import normalize_type_name, parse_yaml_message, to_dict, to_yaml

app = typer.Typer(help="Inspect and publish topics (rostopic / ros2 topic).", no_args_is_help=True)


def _topic_types(ents: list[GraphEntity]) -> dict[str, set[str]]:
    out: dict[str, set[str]] = {}
    for e in ents:
        if e.kind in ("publisher", "subscription"):
            out.setdefault(e.topic, set()).add(e.typename)
    return out


@app.command("list")
def list_topics(
    ctx: typer.Context,
    show_types: Annotated[
        bool, typer.Option("--show-types", "-t", help="Also print each topic's type.")
    ] = False,
    verbose: Annotated[
        bool, typer.Option("--verbose", "-v", help="Group by published / subscribed.")
    ] = False,
) -> None:
    """List the topics of every running roverlab process."""
    with Connection(network_options(ctx)) as conn:
        ents = conn.graph()
    types = _topic_types(ents)
    if verbose:
        for kind, title in (
            ("publisher", "Published topics"),
            ("subscription", "Subscribed topics"),
        ):
            typer.echo(f"{title}:")
            counts: dict[tuple[str, str], int] = {}
            for e in ents:
                if e.kind == kind:
                    counts[(e.topic, e.typename)] = counts.get((e.topic, e.typename), 0) + 1
            for (topic, tname), n in sorted(counts.items()):
                noun = "publisher" if kind == "publisher" else "subscriber"
                typer.echo(f" * {topic} [{tname}] {n} {noun}{'s' if n > 1 else ''}")
            typer.echo("")
        return
    for topic in sorted(types):
        if show_types:
            typer.echo(f"{topic} [{', '.join(sorted(types[topic]))}]")
        else:
            typer.echo(topic)


@app.command("info")
def info(
    ctx: typer.Context,
    topic: Annotated[str, typer.Argument(help="Topic name, e.g. /scan.")],
    verbose: Annotated[bool, typer.Option("--verbose", "-v", help="List the nodes.")] = False,
) -> None:
    """Print a topic's type and its publishers and subscriptions."""
    name = resolve_name(topic)
    with Connection(network_options(ctx)) as conn:
        ents = [e for e in conn.graph() if e.topic == name]
    if not ents:
        raise GraphError(f"unknown topic '{name}' (no process publishes or subscribes to it)")
    pubs = [e for e in ents if e.kind == "publisher"]
    subs = [e for e in ents if e.kind == "subscription"]
    typer.echo(f"Type: {', '.join(sorted({e.typename for e in ents}))}")
    typer.echo(f"Publisher count: {len(pubs)}")
    if verbose:
        for e in pubs:
            typer.echo(f"  * {e.node}" + (" (latched)" if e.latched else ""))
    typer.echo(f"Subscription count: {len(subs)}")
    if verbose:
        for e in subs:
            typer.echo(f"  * {e.node}")


def _discover_type(conn: Connection, name: str, wait_s: float | None) -> str:
    warned = False
    deadline = None if wait_s is None else time.monotonic() + wait_s
    while True:
        types = _topic_types(
            [e for e in conn.graph(timeout_s=0.5) if e.kind == "publisher" and e.topic == name]
        ).get(name)
        if types:
            if len(types) > 1:
                raise GraphError(
                    f"topic '{name}' is published with several types: {', '.join(sorted(types))}"
                )
            return next(iter(types))
        if not warned:
            typer.echo(f"WARNING: topic [{name}] does not appear to be published yet", err=True)
            warned = True
        if deadline is not None and time.monotonic() >= deadline:
            raise GraphError(f"no publisher of '{name}' appeared within {wait_s:g} s")
        time.sleep(0.2)


def _strip_arrays(data: Any) -> Any:
    if isinstance(data, dict):
        return {k: _strip_arrays(v) for k, v in data.items()}
    if isinstance(data, list):
        return f"<array of length {len(data)}>"
    return data


@app.command("echo")
def echo(
    ctx: typer.Context,
    topic: Annotated[str, typer.Argument(help="Topic name, e.g. /cmd_vel.")],
    msg_type: Annotated[
        str | None,
        typer.Argument(help="Message type; looked up from the publishers if omitted."),
    ] = None,
    once: Annotated[bool, typer.Option("--once", help="Print one message and exit.")] = False,
    count: Annotated[
        int | None, typer.Option("--count", "-n", help="Exit after this many messages.")
    ] = None,
    no_arr: Annotated[
        bool, typer.Option("--no-arr", help="Print array fields as their length only.")
    ] = False,
    qos_depth: Annotated[int, typer.Option("--qos-depth", help="Subscription queue depth.")] = 10,
    timeout: Annotated[
        float | None,
        typer.Option("--timeout", help="Give up (exit 1) if nothing arrives within S seconds."),
    ] = None,
) -> None:
    """Print the messages of a topic as YAML, separated by '---'."""
    name = resolve_name(topic)
    tname = normalize_type_name(msg_type) if msg_type else None
    limit = 1 if once else count
    with Connection(network_options(ctx)) as conn:
        if tname is None:
            tname = _discover_type(conn, name, timeout)
        node = conn.context.create_node("roverlab_topic_echo")
        seen = [0]

        def on_msg(msg: Any) -> None:
            if limit is not None and seen[0] >= limit:
                return
            seen[0] += 1
            if no_arr:
                text = yaml.safe_dump(_strip_arrays(to_dict(msg)), sort_keys=False).rstrip()
            else:
                text = to_yaml(msg).rstrip()
            sys.stdout.write(text + "\n---\n")
            sys.stdout.flush()

        node.create_subscription(tname, name, on_msg, QoSProfile(depth=qos_depth))
        try:
            conn.context.spin_until_condition(
                lambda: limit is not None and seen[0] >= limit, timeout_sec=timeout
            )
        except KeyboardInterrupt:
            return
        if timeout is not None and seen[0] == 0:
            typer.echo(f"no message on '{name}' within {timeout:g} s", err=True)
            raise typer.Exit(1)


@app.command("pub")
def pub(
    ctx: typer.Context,
    topic: Annotated[str, typer.Argument(help="Topic name, e.g. /cmd_vel.")],
    msg_type: Annotated[
        str, typer.Argument(help="Message type, e.g. geometry_msgs/Twist (ROS 1 or 2 name).")
    ],
    values: Annotated[
        str,
        typer.Argument(help='Field values as YAML, e.g. "{linear: {x: 0.2}, angular: {z: 0.5}}".'),
    ] = "{}",
    rate: Annotated[
        float, typer.Option("--rate", "-r", help="Publishing rate in Hz (default 1).")
    ] = 1.0,
    once: Annotated[
        bool, typer.Option("--once", "-1", help="Publish one message and exit.")
    ] = False,
    times: Annotated[
        int | None, typer.Option("--times", "-t", help="Publish this many messages, then exit.")
    ] = None,
    wait_matching: Annotated[
        float,
        typer.Option(
            "--wait", help="With --once/--times: wait up to S seconds for a subscriber first."
        ),
    ] = 2.0,
) -> None:
    """Publish a message repeatedly (until Ctrl-C), once, or N times."""
    if not (rate > 0 and math.isfinite(rate)):
        raise typer.BadParameter(f"rate must be a positive number, got {rate}", param_hint="--rate")
    name = resolve_name(topic)
    tname = normalize_type_name(msg_type)
    msg = parse_yaml_message(tname, values)  # validate before touching the network
    limit = 1 if once else times
    with Connection(network_options(ctx)) as conn:
        node = conn.context.create_node("roverlab_topic_pub")
        publisher = node.create_publisher(tname, name, 10)
        if limit is not None:
            deadline = time.monotonic() + wait_matching
            while publisher.topic.remote_send is None and time.monotonic() < deadline:
                time.sleep(0.02)
        sent = [0]

        def tick() -> None:
            if limit is not None and sent[0] >= limit:
                return
            publisher.publish(msg)
            sent[0] += 1

        tick()
        node.create_timer(1.0 / rate, tick)
        if limit is None:
            typer.echo(f"publishing {tname} on {name} at {rate:g} Hz (Ctrl-C to stop)", err=True)
        try:
            conn.context.spin_until_condition(lambda: limit is not None and sent[0] >= limit)
        except KeyboardInterrupt:
            return
        time.sleep(0.2)  # let the last message leave before the session closes


@app.command("hz")
def hz(
    ctx: typer.Context,
    topic: Annotated[str, typer.Argument(help="Topic name.")],
    window: Annotated[
        int, typer.Option("--window", "-w", help="Number of intervals averaged.")
    ] = 10000,
    duration: Annotated[
        float | None, typer.Option("--duration", help="Stop after S seconds.")
    ] = None,
    msg_type: Annotated[
        str | None, typer.Option("--type", help="Message type (looked up if omitted).")
    ] = None,
) -> None:
    """Print the publishing rate of a topic every second, as rostopic hz."""
    name = resolve_name(topic)
    with Connection(network_options(ctx)) as conn:
        tname = normalize_type_name(msg_type) if msg_type else _discover_type(conn, name, None)
        node = conn.context.create_node("roverlab_topic_hz")
        stamps: list[float] = []

        def on_msg(_msg: Any) -> None:
            stamps.append(time.monotonic())
            if len(stamps) > window + 1:
                del stamps[: len(stamps) - window - 1]

        def report() -> None:
            if len(stamps) < 2:
                typer.echo("no new messages")
                return
            d = np.diff(np.asarray(stamps))
            typer.echo(
                f"average rate: {1.0 / d.mean():.3f}\n"
                f"\tmin: {d.min():.3f}s max: {d.max():.3f}s std dev: {d.std():.5f}s "
                f"window: {len(d)}"
            )

        node.create_subscription(tname, name, on_msg, QoSProfile(depth=100))
        node.create_timer(1.0, report)
        end = None if duration is None else time.monotonic() + duration
        try:
            conn.context.spin_until_condition(lambda: end is not None and time.monotonic() >= end)
        except KeyboardInterrupt:
            return
