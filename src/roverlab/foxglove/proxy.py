"""The dashboard's access rule for the Foxglove server off loopback: a token in the URL.

The Foxglove protocol has no authentication, so off loopback the SDK's server listens on a
private loopback port and this relay, on the public address, lets a WebSocket through only
with ``?token=...`` (as the dashboard's ``/ws?token=...``); anything else gets HTTP 403.
Frames pass unchanged both ways, with the subprotocol the client asked for.
"""

from __future__ import annotations

import asyncio
import hmac
import threading
from typing import Any
from urllib.parse import parse_qs, urlsplit

from websockets.asyncio.client import connect
from websockets.asyncio.server import ServerConnection, serve
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response

__all__ = ["TokenRelay"]

SUBPROTOCOLS = ["foxglove.sdk.v1", "foxglove.websocket.v1"]


class TokenRelay:
    """Relays WebSockets from ``host:port`` to ``ws://127.0.0.1:upstream_port`` if the
    request carries ``token``."""

    def __init__(self, host: str, port: int, upstream_port: int, token: str) -> None:
        self.host, self.port, self.upstream_port, self.token = host, port, upstream_port, token
        self._loop = asyncio.new_event_loop()
        self._ready = threading.Event()
        self._stop: asyncio.Future[None] | None = None
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, daemon=True, name="foxglove-relay")
        self._thread.start()
        self._ready.wait(10)
        if self._error is not None:
            raise self._error

    def _authorised(self, path: str) -> bool:
        given = parse_qs(urlsplit(path).query).get("token", [""])[0]
        return hmac.compare_digest(given.encode(), self.token.encode())

    def _check(self, conn: ServerConnection, request: Request) -> Response | None:
        if not self._authorised(request.path):
            return conn.respond(403, "forbidden: wrong or missing token\n")
        return None

    async def _relay(self, conn: ServerConnection) -> None:
        proto = conn.subprotocol
        uri = f"ws://127.0.0.1:{self.upstream_port}/"
        async with connect(
            uri,
            subprotocols=[proto] if proto else None,
            max_size=None,
        ) as up:

            async def pump(src: Any, dst: Any) -> None:
                try:
                    async for frame in src:
                        await dst.send(frame)
                except ConnectionClosed:
                    pass
                await dst.close()

            await asyncio.gather(pump(conn, up), pump(up, conn))

    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)

        async def main() -> None:
            try:
                server = await serve(
                    self._relay,
                    self.host,
                    self.port,
                    subprotocols=SUBPROTOCOLS,  # type: ignore[arg-type]
                    process_request=self._check,
                    max_size=None,
                )
            except OSError as err:
                self._error = err
                self._ready.set()
                return
            self.port = server.sockets[0].getsockname()[1]
            self._stop = self._loop.create_future()
            self._ready.set()
            async with server:
                await self._stop

        self._loop.run_until_complete(main())

    def stop(self) -> None:
        if self._stop is not None:
            self._loop.call_soon_threadsafe(self._stop.set_result, None)
        self._thread.join(5)
