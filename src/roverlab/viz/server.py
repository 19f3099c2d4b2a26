"""``DashboardServer``: rviz in the browser, served by FastAPI + uvicorn in one thread.

One page (``static/index.html`` + ``static/app.js``, no build step) and one websocket at
``/ws``. The server pushes binary frames (map, scan, camera JPEG; see
:mod:`roverlab.viz.protocol`) only when their data changed, and a JSON ``state`` message
at :attr:`DashboardServer.state_rate_hz`. The page sends JSON tool messages back:
``{"type": "goal" | "initialpose", "x", "y", "yaw"}``, ``{"type": "point", "x", "y"}``,
``{"type": "key", "key": "i"}`` and ``{"type": "image_topic", "topic": "/image_raw"}``.

Security: on a loopback host no token is needed. Any other host requires a token (made up
and printed once when not given), asked for by the page URL (``/?token=...``) and the
websocket (``/ws?token=...``); a wrong one gets HTTP 403.
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import ipaddress
import json
import secrets
import sys
import threading
import time
from pathlib import Path
from typing import Any, Final

import uvicorn
from fastapi import FastAPI, Request, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse, PlainTextResponse, Response
from fastapi.staticfiles import StaticFiles

from roverlab.core import Context
from roverlab.viz.bridge import Versioned, VizBridge
from roverlab.viz.errors import DashboardError

__all__ = ["DashboardServer", "is_loopback"]

STATIC_DIR: Final = Path(__file__).parent / "static"
_START_TIMEOUT_S: Final = 10.0


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
        fixed_frame: the displays' fixed frame (``odom`` while TF does not know it).
        state_rate_hz: how often poses and the robot outline are sent.

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
        state_rate_hz: float = 10.0,
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
        self.bridge = VizBridge(context=context, fixed_frame=fixed_frame)
        self.app = self._make_app()
        self._server: uvicorn.Server | None = None
        self._thread: threading.Thread | None = None

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
        sender = asyncio.create_task(self._send_loop(websocket))
        try:
            while True:
                text = await websocket.receive_text()
                with contextlib.suppress(ValueError, KeyError, TypeError):
                    self._handle(json.loads(text))
        except WebSocketDisconnect:
            pass
        finally:
            sender.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await sender

    def _handle(self, msg: dict[str, Any]) -> None:
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
        elif kind == "image_topic":
            topic = str(msg["topic"])
            if topic in bridge.image_topics():
                bridge.select_image(topic)

    async def _send_loop(self, websocket: WebSocket) -> None:
        bridge = self.bridge
        sent: dict[str, int] = {}
        period = 1.0 / self.state_rate_hz
        next_state = 0.0
        map_frame_id = ""

        async def send_new(key: str, item: Versioned | None) -> None:
            if item is not None and sent.get(key) != item.version:
                sent[key] = item.version
                await websocket.send_bytes(item.payload)

        while True:
            if bridge.map_frame_id != map_frame_id and bridge.map_frame is not None:
                map_frame_id = bridge.map_frame_id
                sent.pop("map", None)
            await send_new("map", bridge.map_frame)
            await send_new("scan", bridge.scan_frame)
            await send_new("image", await asyncio.to_thread(bridge.image_frame))
            now = time.monotonic()
            if now >= next_state:
                next_state = now + period
                state = await asyncio.to_thread(bridge.state)
                await websocket.send_text(json.dumps(state))
            await asyncio.sleep(0.02)

    # ------------------------------------------------------------- lifecycle
    @property
    def url(self) -> str:
        """The page's address (with the token when one is needed)."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        query = f"/?token={self.token}" if self.token else "/"
        return f"http://{host}:{self.port}{query}"

    def start(self) -> None:
        """Serve in a daemon thread; returns once the socket listens.

        Raises:
            DashboardError: the server did not come up (port in use, bad host).
        """
        if self._thread is not None:
            raise DashboardError("dashboard already started")
        config = uvicorn.Config(
            self.app, host=self.host, port=self.port, log_level="warning", ws="websockets-sansio"
        )
        server = uvicorn.Server(config)
        self._server = server
        self._thread = threading.Thread(target=server.run, name="roverlab-dashboard", daemon=True)
        self._thread.start()
        deadline = time.monotonic() + _START_TIMEOUT_S
        while not server.started:
            if not self._thread.is_alive() or time.monotonic() > deadline:
                raise DashboardError(f"dashboard could not listen on {self.host}:{self.port}")
            time.sleep(0.02)
        if self.port == 0:
            for srv in server.servers:
                for sock in srv.sockets:
                    self.port = int(sock.getsockname()[1])
                    break
        if self.generated_token:
            print(f"dashboard token (required by every client): {self.token}", file=sys.stderr)

    def stop(self) -> None:
        """Stop serving and wait for the thread."""
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
