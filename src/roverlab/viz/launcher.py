"""``<node pkg="rviz" type="rviz" args="-d FILE.rviz"/>``: the dashboard started by a launch.

The launch registry maps ``("rviz", "rviz")`` to :func:`start_rviz`. rviz's own command
line is honoured: ``-d`` / ``--display-config FILE`` (an ``.rviz`` or a saved dashboard
``.json``) and ``-f`` / ``--fixed-frame FRAME``; other rviz options are reported and
ignored. The web server binds ``$ROVERLAB_DASHBOARD_HOST`` (default ``127.0.0.1``) and the
port of :func:`~roverlab.viz.ports.choose_port` (``$ROVERLAB_DASHBOARD_PORT``, else 8080 or
the next free port after it; ``0`` picks a free port); it stops when the launch's context
shuts down.
"""

from __future__ import annotations

import os
import shlex
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Final

from roverlab.core import Context, Node
from roverlab.core.transport.zenoh import GraphEntity, ZenohTransport, query_graph
from roverlab.core.transport.zenoh_stats import query_topic_counts
from roverlab.viz.config import (
    ConfigError,
    DashboardConfig,
    DisplayConfig,
    default_config,
    load_config,
)
from roverlab.viz.errors import DashboardError
from roverlab.viz.ports import PortChoice, choose_port, start_page

if TYPE_CHECKING:
    from roverlab.viz.server import DashboardServer

__all__ = [
    "RvizArgs",
    "image_view_config",
    "parse_rviz_args",
    "start_image_view",
    "start_rviz",
]

_FLAGS_WITH_VALUE: Final = ("-l", "--log-config", "-s", "--splash-screen", "--opengl")


class RvizArgs:
    """rviz's command line, as far as the dashboard uses it."""

    def __init__(self) -> None:
        self.display_config: str | None = None
        self.fixed_frame: str | None = None
        self.ignored: list[str] = []


def parse_rviz_args(args: str) -> RvizArgs:
    """``-d FILE``, ``--display-config FILE``, ``-f FRAME``, ``--fixed-frame FRAME``.

    Raises:
        DashboardError: an option without its value.
    """
    out = RvizArgs()
    argv = shlex.split(args)
    i = 0
    while i < len(argv):
        a = argv[i]
        name, eq, value = a.partition("=")
        if name in ("-d", "--display-config", "-f", "--fixed-frame"):
            if not eq:
                if i + 1 >= len(argv):
                    raise DashboardError(f"rviz option {a} needs a value")
                value = argv[i + 1]
                i += 1
            if name in ("-d", "--display-config"):
                out.display_config = value
            else:
                out.fixed_frame = value.lstrip("/")
        elif name in _FLAGS_WITH_VALUE and not eq and i + 1 < len(argv):
            out.ignored += [a, argv[i + 1]]
            i += 1
        else:
            out.ignored.append(a)
        i += 1
    return out


def start_rviz(
    context: Context,
    args: str,
    *,
    node_name: str = "rviz",
    source: str = "",
    warn: Callable[[str], None],
) -> Node | None:
    """Start the dashboard on ``context`` for an rviz ``<node>``; returns its node.

    A missing or bad display config is reported through ``warn`` and the default
    displays are used (rviz starts with its defaults too); a ``$ROVERLAB_DASHBOARD_PORT``
    that is taken is reported and the dashboard is not started (None); the default port,
    when taken, gives way to the next free one (reported).

    Raises:
        DashboardError: malformed ``args`` or a bad ``$ROVERLAB_DASHBOARD_PORT``.
    """
    where = f"{source}: " if source else ""
    parsed = parse_rviz_args(args)
    if parsed.ignored:
        warn(f"{where}rviz options not used by the dashboard: {' '.join(parsed.ignored)}")
    config: DashboardConfig | None = None
    if parsed.display_config is not None:
        try:
            config = load_config(Path(parsed.display_config))
        except ConfigError as err:
            warn(f"{where}rviz: {err}; using the default displays")
    if config is None:
        config = default_config(parsed.fixed_frame or "map")
    elif parsed.fixed_frame:
        config.fixed_frame = parsed.fixed_frame
    server, choice = _launch_server(context, config, node_name)
    try:
        start_page(server, choice, say=lambda text: warn(f"{where}rviz: {text}"))
    except DashboardError as err:
        warn(f"{where}rviz/rviz not started: {err}")
        server.bridge.node.destroy_node()
        return None
    server.bridge.node.get_logger().info(f"rviz: the web dashboard is at {server.url}")
    return server.bridge.node


def _launch_server(
    context: Context, config: DashboardConfig, node_name: str
) -> tuple[DashboardServer, PortChoice]:
    """A launch's page (not started): on ``$ROVERLAB_DASHBOARD_HOST`` (default 127.0.0.1)
    and the port rule's port, reading the other processes through the launch's transport.

    Raises:
        DashboardError: the port is not a number.
    """
    from roverlab.viz.server import DashboardServer  # FastAPI: only when a node asks for it

    choice = choose_port(None)
    graph, counts = _remote_sources(context)
    server = DashboardServer(
        context,
        os.environ.get("ROVERLAB_DASHBOARD_HOST", "127.0.0.1"),
        choice.port,
        config=config,
        node_name=node_name,
        remote_graph=graph,
        remote_counts=counts,
    )
    return server, choice


def _remote_sources(
    context: Context,
) -> tuple[Callable[[], list[GraphEntity]], Callable[[], dict[str, dict[str, int]]]]:
    """The other processes' graph and message counts, through the launch's Zenoh transport
    (when its topics are exposed; looked up at each call: it may be added after the node),
    so a launch's rviz shows what other terminals publish as ``roverlab dashboard`` does."""

    def transport() -> ZenohTransport | None:
        return next((t for t in context.transports if isinstance(t, ZenohTransport)), None)

    def graph() -> list[GraphEntity]:
        t = transport()
        if t is None:
            return []
        return [e for e in query_graph(t.session, t.domain) if e.zid != t.zid]

    def counts() -> dict[str, dict[str, int]]:
        t = transport()
        if t is None:
            return {}
        out = query_topic_counts(t.session, t.domain)
        out.pop(t.zid, None)
        return out

    return graph, counts


def image_view_config(topic: str | None) -> DashboardConfig:
    """rqt_image_view's view: the default displays with the image panel on ``topic``
    (None: the panel's topic picker, as rqt_image_view starts with an empty choice)."""
    config = default_config()
    for d in config.displays:
        if d.kind == "image":
            d.topic = topic or ""
            d.enabled = True
            break
    else:
        config.displays.append(DisplayConfig("image", "Image", True, topic or "", {}))
    return config


def start_image_view(
    context: Context,
    args: str,
    *,
    remaps: dict[str, str],
    node_name: str = "rqt_image_view",
    source: str = "",
    warn: Callable[[str], None],
) -> Node | None:
    """``<node pkg="rqt_image_view" type="rqt_image_view" args="/usb_cam/image_raw"/>``:
    the dashboard's image panel on the topic given as the argument (or remapped from
    ``image``), served on ``$ROVERLAB_DASHBOARD_PORT`` or, when that is taken (an rviz in
    the same launch), on a free port; the URL is logged.

    Raises:
        DashboardError: a bad ``$ROVERLAB_DASHBOARD_PORT``.
    """
    where = f"{source}: " if source else ""
    positional = [a for a in shlex.split(args) if not a.startswith("-")]
    topic = positional[0] if positional else remaps.get("image") or remaps.get("/image")
    server, _ = _launch_server(context, image_view_config(topic), node_name)
    try:
        server.start(next_free=True)  # beside an rviz of the same launch on that port
    except DashboardError as err:
        server.bridge.node.destroy_node()
        warn(f"{where}rqt_image_view not started: {err}")
        return None
    server.bridge.node.get_logger().info(
        f"rqt_image_view: the image panel is at {server.url}" + (f" ({topic})" if topic else "")
    )
    return server.bridge.node
