"""``DashboardServer``: rviz in the browser, served by FastAPI + uvicorn in one thread.

One page, no build step: ``static/index.html`` and its scripts, in the order it loads them:
``redraw.js`` (when the views draw: only on change), ``panel.js`` (the side panels),
``view2d.js`` (the 2D view and its tools), ``app.js`` (the websocket, the data it brings,
``window.viz``), then the 3D view's modules ``view3d.js`` (renderer and cameras),
``displays3d.js`` (each display's objects in the scene) and ``markers3d.js`` (markers), on
three.js in ``static/vendor``; its icon is ``static/favicon.svg`` (also at
``/favicon.ico``). One websocket at ``/ws``: the server pushes each display's binary frame
(map or map patch, points, poses, path, camera image; see :mod:`roverlab.viz.protocol`)
only when its data changed, marker lists as JSON ``{"type": "markers", "slot", "items"}``,
the configuration as JSON ``{"type": "config", "config"}`` whenever it changes, and a JSON
``state`` message (frames, robot outline, status tree; the topic list with rates once a
second) at :attr:`DashboardServer.state_rate_hz`.

The page sends JSON back: tools ``{"type": "goal" | "initialpose", "x", "y", "yaw"}``,
``{"type": "point", "x", "y"}``; joint sliders ``{"type": "joint", "name", "position"}``;
drive ``{"type": "key", "key": "i"}``,
``{"type": "speed", "speed", "turn"}``; ``{"type": "config", "config": {...}}`` (the
whole configuration, :meth:`DashboardConfig.to_dict` form), ``{"type": "save_config"}``,
``{"type": "save_map", "name": "map"}`` and ``{"type": "image_topic", "topic"}``. Replies
to a save come back as ``{"type": "notice", "level", "text"}``.

The configuration is shared by every page of one server (like one rviz window).

Security: on a loopback host no token is needed. Any other host requires a token (made up
and printed once when not given), asked for by the page URL (``/?token=...``), the
websocket (``/ws?token=...``), ``/config`` and ``/mesh/N`` (the page adds its own token:
``viz.withToken`` of app.js); a wrong one gets HTTP 403. The static files and the icon are
public.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import hmac
import ipaddress
import json
import secrets
import socket
import struct
import sys
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Final

import uvicorn
from fastapi import FastAPI, Request, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse, PlainTextResponse, Response
from fastapi.staticfiles import StaticFiles

from roverlab.core import Context
from roverlab.description.packages import resolve_uri
from roverlab.errors import RoverlabError
from roverlab.viz.bridge import DisplayState, VizBridge
from roverlab.viz.config import DashboardConfig, config_from_dict, save_config
from roverlab.viz.errors import DashboardError
from roverlab.viz.ports import NEXT_FREE_TRIES, PortTakenError

__all__ = ["DashboardServer", "is_loopback"]

STATIC_DIR: Final = Path(__file__).parent / "static"
_START_TIMEOUT_S: Final = 10.0
_TOPICS_EVERY_S: Final = 1.0
_REMOTE_GRAPH_EVERY_S: Final = 2.0
_REMOTE_COUNTS_EVERY_S: Final = 1.0
DEFAULT_CONFIG_NAME: Final = "dashboard.json"


def is_loopback(host: str) -> bool:
    """True for ``localhost`` and loopback addresses (127.0.0.0/8, ::1)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _number(msg: dict[str, Any], key: str) -> float:
    value = float(msg[key])
    if value != value or value in (float("inf"), float("-inf")):
        raise ValueError(f"{key} is not finite")
    return value


class DashboardServer:
    """The web dashboard attached to ``context`` (its nodes see the dashboard's topics).

    Args:
        context: the context to attach to; spin it yourself (``spin_in_thread``).
        host: address to bind; anything but loopback requires a token.
        port: TCP port (0 picks a free one; see :attr:`port` after :meth:`start`).
        token: access token; made up when binding a non-loopback host without one.
        fixed_frame: the displays' fixed frame when ``config`` is not given.
        config: the displays (from :func:`~roverlab.viz.config.load_config`); the
            default set when None.
        config_path: where the page's *Save config* writes (the dashboard's JSON); by
            default the loaded file if it was one of ours, else ``./dashboard.json``.
        map_dir: where the page's *Save map* writes ``NAME.pgm`` + ``NAME.yaml``.
        remote_graph: the other processes' graph (:meth:`Connection.graph`), polled
            every 2 s for the topic list; None in-process.
        remote_counts: the other processes' messages per topic
            (:meth:`Connection.topic_counts`), polled every second for the topics' rates.
        state_rate_hz: how often poses and the robot outline are sent.
        node_name: the dashboard node's name (destroying it stops the server).

    Raises:
        DashboardError: ``port`` out of range or ``state_rate_hz`` not positive.
    """

    def __init__(
        self,
        context: Context,
        host: str = "127.0.0.1",
        port: int = 8080,
        token: str | None = None,
        *,
        fixed_frame: str = "map",
        config: DashboardConfig | None = None,
        config_path: str | Path | None = None,
        map_dir: str | Path = ".",
        remote_graph: Callable[[], Sequence[Any]] | None = None,
        remote_counts: Callable[[], dict[str, dict[str, int]]] | None = None,
        state_rate_hz: float = 10.0,
        node_name: str = "rviz",
    ) -> None:
        if not 0 <= port <= 65535:
            raise DashboardError(f"port must be 0..65535, got {port}")
        if not state_rate_hz > 0:
            raise DashboardError(f"state_rate_hz must be > 0, got {state_rate_hz}")
        self.host = host
        self.port = port
        self.generated_token = token is None and not is_loopback(host)
        self.token = secrets.token_urlsafe(16) if self.generated_token else token
        self.state_rate_hz = state_rate_hz
        if config_path is None:
            src = Path(config.source) if config is not None and config.source else None
            ours = src is not None and src.suffix == ".json"
            config_path = src if ours and src is not None else Path(DEFAULT_CONFIG_NAME)
        self.config_path = Path(config_path)
        self.bridge = VizBridge(
            context=context,
            fixed_frame=fixed_frame,
            config=config,
            map_dir=map_dir,
            remote_graph=remote_graph,
            remote_counts=remote_counts,
            node_name=node_name,
        )
        self.bridge.node.on_destroy.append(self.stop)
        self.bridge.node.server = self
        self.app = self._make_app()
        self._server: uvicorn.Server | None = None
        self._thread: threading.Thread | None = None
        self._graph_thread: threading.Thread | None = None
        self._stopping = threading.Event()

    # ------------------------------------------------------------------ HTTP
    def _authorised(self, given: str | None) -> bool:
        if self.token is None:
            return True
        return given is not None and hmac.compare_digest(given.encode(), self.token.encode())

    def _make_app(self) -> FastAPI:
        app = FastAPI(title="roverlab dashboard", docs_url=None, redoc_url=None, openapi_url=None)

        @app.get("/")
        def index(request: Request) -> Response:
            if not self._authorised(request.query_params.get("token")):
                return PlainTextResponse("forbidden: wrong or missing token", status_code=403)
            return FileResponse(STATIC_DIR / "index.html", headers={"Cache-Control": "no-store"})

        @app.get("/config")
        def config(request: Request) -> Response:
            if not self._authorised(request.query_params.get("token")):
                return PlainTextResponse("forbidden: wrong or missing token", status_code=403)
            return Response(
                json.dumps(self.bridge.config.to_dict(), indent=2),
                media_type="application/json",
                headers={"Content-Disposition": f'attachment; filename="{DEFAULT_CONFIG_NAME}"'},
            )

        @app.get("/mesh/{index}")
        def mesh(index: int, request: Request) -> Response:
            """The mesh file of the robot model's ``index``-th visual (only those files)."""
            if not self._authorised(request.query_params.get("token")):
                return PlainTextResponse("forbidden: wrong or missing token", status_code=403)
            shapes = self.bridge.shapes
            if not 0 <= index < len(shapes) or shapes[index]["geometry"]["type"] != "mesh":
                return PlainTextResponse(f"no mesh visual {index}", status_code=404)
            uri = str(shapes[index]["geometry"]["filename"])
            try:
                path = resolve_uri(uri)
            except RoverlabError as err:
                return PlainTextResponse(f"{uri}: {err}", status_code=404)
            if not path.is_file():
                return PlainTextResponse(f"{uri}: no such file {path}", status_code=404)
            return FileResponse(path)

        @app.get("/favicon.ico")
        def favicon() -> Response:
            """The icon, for a browser that asks before (or without) reading the page."""
            return FileResponse(STATIC_DIR / "favicon.svg", media_type="image/svg+xml")

        app.mount("/static", StaticFiles(directory=STATIC_DIR), name="static")

        @app.websocket("/ws")
        async def ws(websocket: WebSocket) -> None:
            if not self._authorised(websocket.query_params.get("token")):
                await websocket.close(code=1008)  # before accept: HTTP 403
                return
            await websocket.accept()
            await self._serve_client(websocket)

        return app

    # ------------------------------------------------------------- websocket
    async def _serve_client(self, websocket: WebSocket) -> None:
        replies: asyncio.Queue[dict[str, Any]] = asyncio.Queue()
        sender = asyncio.create_task(self._send_loop(websocket, replies))
        try:
            while True:
                text = await websocket.receive_text()
                try:
                    msg = json.loads(text)
                    reply = await asyncio.to_thread(self._handle, msg)
                except (ValueError, KeyError, TypeError, RoverlabError) as err:
                    reply = {"type": "notice", "level": "error", "text": str(err)}
                if reply is not None:
                    replies.put_nowait(reply)
        except WebSocketDisconnect:
            pass
        finally:
            sender.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await sender

    def _handle(self, msg: dict[str, Any]) -> dict[str, Any] | None:
        """One message from a page; returns the reply for that page, if any.

        Raises:
            ValueError, KeyError, TypeError, RoverlabError: a malformed message or a
                failed action (the page is told).
        """
        kind = msg.get("type")
        bridge = self.bridge
        if kind == "goal":
            bridge.publish_goal(_number(msg, "x"), _number(msg, "y"), _number(msg, "yaw"))
        elif kind == "initialpose":
            bridge.publish_initialpose(_number(msg, "x"), _number(msg, "y"), _number(msg, "yaw"))
        elif kind == "point":
            bridge.publish_point(_number(msg, "x"), _number(msg, "y"))
        elif kind == "key":
            bridge.drive_key(str(msg["key"])[:1])
        elif kind == "speed":
            bridge.set_speeds(_number(msg, "speed"), _number(msg, "turn"))
        elif kind == "joint":
            bridge.set_joint(str(msg["name"]), _number(msg, "position"))
        elif kind == "image_topic":
            bridge.select_image(str(msg["topic"]))
        elif kind == "config":
            bridge.set_config(config_from_dict(msg["config"], "configuration from the page"))
        elif kind == "save_config":
            path = save_config(bridge.config, self.config_path)
            return {"type": "notice", "level": "ok", "text": f"saved the configuration to {path}"}
        elif kind == "save_map":
            path = bridge.save_map(str(msg.get("name") or "map"))
            return {"type": "notice", "level": "ok", "text": f"saved the map to {path}"}
        return None

    @staticmethod
    def _slotted(payload: bytes, slot: int) -> bytes:
        return payload[:2] + struct.pack("<H", slot) + payload[4:]

    async def _send_display(
        self, websocket: WebSocket, d: DisplayState, sent: dict[tuple[int, int], int]
    ) -> None:
        key = (id(d), d.slot)
        have = sent.get(key)
        if d.kind == "map":
            base = d.map_base
            if base is None:
                return
            patches = d.map_patches
            current = patches[-1].version if patches else base.version
            if have == current:
                return
            known = have is not None and (
                have == base.version or any(p.version == have for p in patches)
            )
            if not known:
                await websocket.send_bytes(self._slotted(base.payload, d.slot))
                have = base.version
            for p in patches:
                if have is not None and p.version > have:
                    await websocket.send_bytes(self._slotted(p.payload, d.slot))
            sent[key] = current
            return
        if d.kind == "image":
            item = d.image_jpeg
            if d.image_msg is not None and (item is None or item.version != d.image_msg.version):
                if sent.get(key) == d.image_msg.version:
                    return
                item = await asyncio.to_thread(self.bridge.image_frame, d)
        else:
            item = d.frame
        if item is None or have == item.version:
            return
        sent[key] = item.version
        if isinstance(item.payload, str):
            # the payload is a JSON object {"items": [...], ...}: merged into the message
            await websocket.send_text(
                f'{{"type": "markers", "slot": {d.slot}, {item.payload.lstrip()[1:]}'
            )
        else:
            await websocket.send_bytes(self._slotted(item.payload, d.slot))

    async def _send_loop(
        self, websocket: WebSocket, replies: asyncio.Queue[dict[str, Any]]
    ) -> None:
        bridge = self.bridge
        sent: dict[tuple[int, int], int] = {}
        period = 1.0 / self.state_rate_hz
        next_state = next_topics = 0.0
        config_version = 0
        displays: list[DisplayState] = []
        while True:
            while not replies.empty():
                await websocket.send_text(json.dumps(replies.get_nowait()))
            if bridge.config_version != config_version or bridge.displays is not displays:
                config_version = bridge.config_version
                displays = bridge.displays
                # a display that moved to another slot is resent under its new number
                live = {(id(d), d.slot) for d in displays}
                sent = {k: v for k, v in sent.items() if k in live}
                await websocket.send_text(
                    json.dumps(
                        {
                            "type": "config",
                            "version": config_version,
                            "config": bridge.config.to_dict(),
                        }
                    )
                )
            for d in displays:
                if d.config.enabled:
                    await self._send_display(websocket, d, sent)
            now = time.monotonic()
            if now >= next_state:
                next_state = now + period
                with_topics = now >= next_topics
                if with_topics:
                    next_topics = now + _TOPICS_EVERY_S
                state = await asyncio.to_thread(bridge.state, with_topics=with_topics)
                await websocket.send_text(json.dumps(state))
            await asyncio.sleep(0.02)

    # ------------------------------------------------------------- lifecycle
    @property
    def url(self) -> str:
        """The page's address (with the token when one is needed)."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        query = f"/?token={self.token}" if self.token else "/"
        return f"http://{host}:{self.port}{query}"

    def start(self, *, next_free: bool = False) -> None:
        """Serve in a daemon thread; returns once the socket listens.

        Args:
            next_free: when :attr:`port` is taken, serve on the next free port after it
                (see :attr:`port` afterwards) instead of failing.

        Raises:
            PortTakenError: the port is in use (and ``next_free`` is not set).
            DashboardError: the server did not come up (bad host).
        """
        if self._thread is not None:
            raise DashboardError("dashboard already started")
        sock = self._listen(next_free)
        self.port = int(sock.getsockname()[1])
        config = uvicorn.Config(self.app, log_level="warning", ws="websockets-sansio")
        server = uvicorn.Server(config)
        self._server = server
        self._thread = threading.Thread(
            target=server.run, kwargs={"sockets": [sock]}, name="roverlab-dashboard", daemon=True
        )
        self._thread.start()
        deadline = time.monotonic() + _START_TIMEOUT_S
        while not server.started:
            if not self._thread.is_alive() or time.monotonic() > deadline:
                sock.close()
                raise DashboardError(f"dashboard could not serve on {self.host}:{self.port}")
            time.sleep(0.02)
        if self.bridge._remote_graph is not None or self.bridge._remote_counts is not None:
            self._graph_thread = threading.Thread(
                target=self._poll_graph, name="roverlab-dashboard-graph", daemon=True
            )
            self._graph_thread.start()
        if self.generated_token:
            print(f"dashboard token (required by every client): {self.token}", file=sys.stderr)

    def _listen(self, next_free: bool) -> socket.socket:
        candidates = [self.port]
        if next_free and self.port:
            top = min(65535, self.port + NEXT_FREE_TRIES)
            candidates += [*range(self.port + 1, top + 1), 0]
        for port in candidates:
            try:
                return self._bind(port)
            except PortTakenError:
                if port == candidates[-1]:
                    raise
        raise AssertionError("unreachable")  # pragma: no cover

    def _bind(self, port: int) -> socket.socket:
        try:
            infos = socket.getaddrinfo(self.host, port, type=socket.SOCK_STREAM)
        except OSError as err:
            raise DashboardError(f"dashboard: bad host {self.host!r}: {err}") from err
        family, _, _, _, address = infos[0]
        sock = socket.socket(family, socket.SOCK_STREAM)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.bind(address)
            sock.listen(128)
        except OSError as err:
            sock.close()
            text = f"dashboard cannot listen on {self.host}:{port}: {err.strerror or err}"
            if err.errno == errno.EADDRINUSE:
                raise PortTakenError(text, port) from err
            raise DashboardError(text) from err
        sock.setblocking(False)
        return sock

    def _poll_graph(self) -> None:
        next_graph = 0.0
        while not self._stopping.is_set():
            if time.monotonic() >= next_graph:
                next_graph = time.monotonic() + _REMOTE_GRAPH_EVERY_S
                with contextlib.suppress(Exception):  # a network hiccup: keep the last graph
                    self.bridge.refresh_remote_graph()
            with contextlib.suppress(Exception):
                self.bridge.refresh_remote_counts()
            self._stopping.wait(_REMOTE_COUNTS_EVERY_S)

    def stop(self) -> None:
        """Stop serving and wait for the thread."""
        self._stopping.set()
        if self._server is not None:
            self._server.should_exit = True
        if self._thread is not None:
            self._thread.join(timeout=5)
        self._server = None
        self._thread = None

    def __enter__(self) -> DashboardServer:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
