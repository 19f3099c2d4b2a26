"""What every networked CLI command shares: how to join the running system."""

from __future__ import annotations

import contextlib
import math
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated, Any

import typer

from roverlab.bag import BagRecorder
from roverlab.core import Context
from roverlab.core.errors import TransportError
from roverlab.core.transport.daemon import ensure_daemon
from roverlab.core.transport.interfaces import split_wildcard_listen
from roverlab.core.transport.ros1.transport import Ros1Transport, ros1_graph, ros_master_uri
from roverlab.core.transport.zenoh import (
    GraphEntity,
    ZenohOptions,
    ZenohTransport,
    query_graph,
)
from roverlab.core.transport.zenoh_stats import query_topic_counts
from roverlab.errors import RoverlabError
from roverlab.packages import BUNDLED_PACKAGES_DIR

__all__ = [
    "FOLLOWER_CLOCKS",
    "Connection",
    "HostOption",
    "NetworkOptions",
    "StartGuard",
    "choose_expose",
    "connect_following_clock",
    "expose_if_asked",
    "is_loopback_endpoint",
    "master_wait_note",
    "network_options",
    "run_context",
    "stop_on_signals",
]

#: ``--clock`` of commands that join a running system (``roverlab run``, ``patrol``).
FOLLOWER_CLOCKS = ("auto", "wall", "external")

#: ``--host`` of the commands that serve a browser or Foxglove (default "127.0.0.1").
HostOption = Annotated[
    str, typer.Option("--host", help="Address to bind; non-loopback needs a token.")
]

_SETTLE_S = 0.3
_LINK_WAIT_S = 2.0
_CONNECT_TIMEOUT_S = 5.0
_LOOPBACK_HOSTS = ("localhost", "::1", "ip6-localhost")


def is_loopback_endpoint(endpoint: str) -> bool:
    """Whether a Zenoh endpoint (``tcp/127.0.0.1:7447``, ``unixsock-stream/...``) can only
    be reached from this machine."""
    proto, _, addr = endpoint.partition("/")
    if proto.startswith("unixsock"):
        return True
    host = addr.split("#")[0].rpartition(":")[0].strip("[]")
    return host in _LOOPBACK_HOSTS or host.startswith("127.")


@dataclass(frozen=True)
class NetworkOptions:
    """Connection settings from the root command's options."""

    connect: tuple[str, ...] = ()
    listen: tuple[str, ...] = ("tcp/127.0.0.1:0",)
    user: str | None = None
    password: str | None = None
    tls_root_ca: str | None = None
    tls_cert: str | None = None
    tls_key: str | None = None
    multicast: bool = False
    insecure: bool = False
    client_of: str | None = None
    """A launch's script process: a Zenoh client of the launch's own endpoint (it then
    sees and is seen by exactly what the launch is joined to, however that joined)."""

    def zenoh_options(self) -> ZenohOptions:
        """The transport settings; an explicit ``--connect`` fails fast (5 s) with a clear
        error when the other side refuses the session or nothing listens there.

        Raises:
            RoverlabError: a non-loopback ``--listen`` without ``--user``/``--password``
                and without ``--insecure``.
        """
        if self.client_of is not None:
            return ZenohOptions(
                mode="client",
                listen=(),
                connect=(self.client_of,),
                user=self.user,
                password=self.password,
                connect_timeout_s=_CONNECT_TIMEOUT_S,
            )
        exposed = [ep for ep in self.listen if not is_loopback_endpoint(ep)]
        if exposed and self.user is None and not self.insecure:
            raise RoverlabError(
                f"refusing to listen on {', '.join(exposed)} without authentication: anyone "
                "on that network could read the robot's topics and drive it. Give --user and "
                "--password (the same on both machines), or --insecure on a network you trust"
            )
        opts = ZenohOptions(
            listen=self.listen,
            connect=self.connect,
            user=self.user,
            password=self.password,
            tls_root_ca=self.tls_root_ca,
            tls_cert=self.tls_cert,
            tls_key=self.tls_key,
            multicast_scouting=self.multicast,
            connect_timeout_s=_CONNECT_TIMEOUT_S if self.connect else None,
        )
        if not opts.connect and not self.multicast:
            daemon = ensure_daemon()
            # A robot listening with a password still joins its own machine's daemon
            # (which asks for none): it checks the password of sessions that come in and
            # offers none itself. ``tcp/0.0.0.0:7447`` becomes one endpoint per address of
            # the machine, leaving 127.0.0.1:7447 to the daemon.
            opts = replace(
                opts,
                connect=(daemon,),
                listen=split_wildcard_listen(opts.listen, daemon),
                present_credentials=False,
            )
        return opts


def _sigterm_interrupts() -> Any:
    """SIGTERM raises KeyboardInterrupt (as Ctrl-C), so a command killed by ``kill`` or
    ``timeout`` still leaves its ``with`` block and unregisters from a ROS 1 master (a
    rospy node does so too); the old handler, or None off the main thread."""
    if threading.current_thread() is not threading.main_thread():
        return None

    def interrupt(*_: Any) -> None:
        raise KeyboardInterrupt

    return signal.signal(signal.SIGTERM, interrupt)


def master_wait_note(line: str) -> None:
    """Where a command that runs as a ROS 1 node says it waits for the master."""
    typer.echo(f"warning: {line}", err=True)


class Connection:
    """A wall-clock context joined to the network, for one CLI command.

    With ``ROS_MASTER_URI`` set and no master answering, a one-shot tool (``node``
    False: topic, service, node, action, tf) fails at once, as rostopic does; a command
    that runs as a node (teleop, dashboard, bag, map_saver) waits for the master, saying
    so, as rospy and roscpp nodes do.
    """

    def __init__(self, options: NetworkOptions, *, clock: str = "wall", node: bool = False) -> None:
        self.context = Context(clock=clock, publish_clock=False)
        self.ros1: Ros1Transport | None = None
        self._old_sigterm: Any = None
        self._zenoh: ZenohTransport | None = None
        master = ros_master_uri()
        if master is not None:  # ROS_MASTER_URI: the command is a ROS 1 node
            self.ros1 = Ros1Transport(master, on_wait=master_wait_note if node else None)
            self.context.add_transport(self.ros1)
            self._old_sigterm = _sigterm_interrupts()
            return
        self._zenoh = ZenohTransport(options.zenoh_options())
        self.context.add_transport(self._zenoh)
        # A fresh session's first graph or parameter query can come back empty until it is
        # linked to the router (or a peer) and has the network's declarations: wait for
        # the link (a loaded machine can take a second), then give the declarations a
        # moment.
        info = self.transport.session.info
        deadline = time.monotonic() + _LINK_WAIT_S
        while not (list(info.routers_zid()) or list(info.peers_zid())):
            if time.monotonic() >= deadline:
                break
            time.sleep(0.02)
        time.sleep(_SETTLE_S)
        self._fresh_until = time.monotonic() + _LINK_WAIT_S

    @property
    def transport(self) -> ZenohTransport:
        """The Zenoh transport (commands that need Zenoh itself).

        Raises:
            TransportError: the command runs as a ROS 1 node (``ROS_MASTER_URI`` is set).
        """
        if self._zenoh is None:
            raise TransportError(
                "this command does not work over ROS 1 yet: unset ROS_MASTER_URI to use "
                "it on roverlab's own network"
            )
        return self._zenoh

    def graph(self, timeout_s: float = 1.0) -> list[GraphEntity]:
        """Nodes, publishers and subscriptions of the other processes. Shortly after
        joining, an empty answer is asked again (the declarations may still be on their
        way), so a busy machine does not make a running system look empty."""
        if self.ros1 is not None:
            return ros1_graph(self.ros1.master_uri, exclude=set(self.context.nodes))
        session, domain, me = self.transport.session, self.transport.domain, self.transport.zid
        while True:
            ents = [e for e in query_graph(session, domain, timeout_s) if e.zid != me]
            if ents or time.monotonic() >= self._fresh_until:
                return ents
            time.sleep(0.1)

    def topic_counts(self, timeout_s: float = 1.0) -> dict[str, dict[str, int]]:
        """Messages published per topic by each other process: ``{zid: {topic: n}}``."""
        counts = query_topic_counts(self.transport.session, self.transport.domain, timeout_s)
        counts.pop(self.transport.zid, None)
        return counts

    def close(self) -> None:
        self.context.shutdown()  # a ROS 1 node unregisters from the master here
        if self._old_sigterm is not None:
            signal.signal(signal.SIGTERM, self._old_sigterm)

    def __enter__(self) -> Connection:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def report_warnings(title: str, lines: list[str], strict: bool) -> None:
    """Print a loader's warnings loudly on stderr under a count; with ``--strict`` they
    are errors (exit status 2) rather than warnings."""
    if not lines:
        return
    label = "error" if strict else "warning"
    noun = "problem" if len(lines) == 1 else "problems"
    typer.echo(f"{label}: {title}: {len(lines)} {noun}:", err=True)
    for line in lines:
        typer.echo(f"  - {line}", err=True)
    if strict:
        typer.echo(f"error: --strict: {title} is not loaded as its files say", err=True)
        raise typer.Exit(2)


def report_notes(lines: list[str]) -> None:
    """Print what a file sets that roverlab reads and does not act on, ``note:`` a line
    (not warnings: ``--strict`` does not refuse them). A file of a bundled package is
    named as ``PKG/path`` and one below the working folder by its relative path, so that a
    note fits a terminal line."""
    cwd = f"{Path.cwd()}{os.sep}"
    bundled = f"{BUNDLED_PACKAGES_DIR}{os.sep}"
    for line in lines:
        line = line.replace(bundled, "").replace(cwd, "")
        typer.echo(f"note: {line}", err=True)


def network_options(ctx: typer.Context) -> NetworkOptions:
    """The root command's connection options (``roverlab --connect ... CMD``)."""
    obj = ctx.find_root().obj
    return obj if isinstance(obj, NetworkOptions) else NetworkOptions()


@contextlib.contextmanager
def stop_on_signals(
    stop: threading.Event, on_stop: Callable[[], None] | None = None
) -> Iterator[threading.Event]:
    """Inside the block SIGINT, SIGTERM and SIGHUP set ``stop`` (and call ``on_stop``, e.g.
    an executor's ``stop``: the command then finishes its output files and returns) instead
    of killing the process; the old handlers come back at the end. A second SIGINT
    interrupts (KeyboardInterrupt). Off the main thread (where Python cannot install signal
    handlers) the block runs unchanged."""

    def on_signal(signum: int, _frame: Any) -> None:
        if signum == signal.SIGINT and stop.is_set():
            raise KeyboardInterrupt
        stop.set()
        if on_stop is not None:
            on_stop()

    if threading.current_thread() is not threading.main_thread():
        yield stop
        return
    sigs = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
    old = {s: signal.signal(s, on_signal) for s in sigs}
    try:
        yield stop
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)


def run_context(
    context: Context,
    duration_s: float | None,
    before_shutdown: Callable[[], None] | None = None,
    *,
    until: Callable[[], bool] | None = None,
) -> float:
    """Spin until ``duration_s`` of clock time (or forever), ``until()`` holds, SIGINT /
    SIGTERM / SIGHUP, or shutdown; then call ``before_shutdown`` (a launch stops its script
    processes while its network still routes their last messages) and shut the context
    down (which finishes recordings). Returns the wall seconds it ran."""
    started = time.monotonic()
    try:
        with stop_on_signals(threading.Event(), context.executor.stop):
            if duration_s is None and until is not None:
                context.spin_until_condition(until)
            elif duration_s is None:
                context.spin()
            else:
                context.spin_for(duration_s)
    except KeyboardInterrupt:
        pass
    finally:
        try:
            if before_shutdown is not None:
                before_shutdown()
        finally:
            context.shutdown()
    return time.monotonic() - started


def choose_expose(expose: bool | None, pace: float) -> bool:
    """Whether a run joins the network: as asked, else yes for a paced run and no for
    ``--rate max`` (a batch run must neither feed nor hear another system on the machine:
    its sim time would mix with theirs)."""
    if expose is not None:
        return expose
    if math.isinf(pace):
        typer.echo(
            "note: --rate max runs privately (other processes neither see nor feed it); "
            "--expose to attach",
            err=True,
        )
        return False
    return True


def expose_if_asked(
    ctx: typer.Context,
    context: Context,
    expose: bool | None,
    pace: float,
    *,
    also_listen: tuple[str, ...] = (),
) -> None:
    """Attach ``context`` to the network (Zenoh, the command's network options) when
    :func:`choose_expose` says so, listening on ``also_listen`` too (the endpoint a
    launch's script processes join it by)."""
    master = ros_master_uri()
    if master is not None and choose_expose(expose, pace):
        # ROS_MASTER_URI (or --ros-master): the run is a ROS 1 participant instead of a
        # Zenoh one; a launch's own script processes still join it over Zenoh
        context.add_transport(Ros1Transport(master, on_wait=master_wait_note))
        if also_listen:
            context.add_transport(ZenohTransport(ZenohOptions(listen=also_listen, connect=())))
    elif choose_expose(expose, pace):
        options = network_options(ctx)
        options = replace(options, listen=(*options.listen, *also_listen))
        context.add_transport(ZenohTransport(options.zenoh_options()))
    elif also_listen:  # a private run: only its own script processes join it, there
        context.add_transport(ZenohTransport(ZenohOptions(listen=also_listen, connect=())))


class StartGuard:
    """Undoes a run's start-up when a block under ``with guard:`` raises anything (Ctrl-C
    included): aborts the recording, if any, and shuts the context down; then re-raises.

    Args:
        context: the run's context.
        recorder: a recording already attached, if any (or attach one with :meth:`record`).
    """

    def __init__(self, context: Context, recorder: BagRecorder | None = None) -> None:
        self.context = context
        self.recorder = recorder

    def record(self, path: Any) -> None:
        """Record the run to ``path`` (its extension decides the format: .bag, .mcap, ...)."""
        self.recorder = BagRecorder(path)
        self.context.add_transport(self.recorder)

    def __enter__(self) -> StartGuard:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, *_: object) -> None:
        if exc_type is not None:
            if self.recorder is not None:
                self.recorder.abort()
            self.context.shutdown()


def connect_following_clock(
    options: NetworkOptions, clock: str
) -> tuple[ZenohTransport | Ros1Transport, str, str]:
    """The transport, and the clock mode (``auto``: follow /clock when someone publishes
    it, as a ROS node with /use_sim_time does next to a simulator; else wall time). With
    ``ROS_MASTER_URI`` the transport is ROS 1 and ``auto`` is rospy's rule: sim time when
    the master's ``/use_sim_time`` is true."""
    if clock not in FOLLOWER_CLOCKS:
        raise TransportError(f"unknown --clock {clock!r} ({', '.join(FOLLOWER_CLOCKS)})")
    master = ros_master_uri()
    if master is not None:
        ros1 = Ros1Transport(master, on_wait=master_wait_note)
        if clock != "auto":
            return ros1, clock, ""
        if ros1.get_param("/use_sim_time", False) is True:
            return ros1, "external", f"following /clock ({master} has /use_sim_time true)"
        return ros1, "wall", ""
    transport = ZenohTransport(options.zenoh_options())
    if clock != "auto":
        return transport, clock, ""
    time.sleep(0.3)  # the router's declarations reach a fresh session first
    deadline = time.monotonic() + 1.0
    while True:
        clocks = [
            e
            for e in query_graph(transport.session, transport.domain, 0.5)
            if e.kind == "publisher" and e.topic == "/clock"
        ]
        if clocks:
            return transport, "external", f"following /clock from {clocks[0].node} (sim time)"
        if time.monotonic() >= deadline:
            return transport, "wall", ""
        time.sleep(0.2)
