"""Services over Zenoh: a server is a queryable, a call is a query.

Keys (``D`` is the domain):

=======================================  ==============================================
``rl/D/v/<service>``                     the server's queryable: ``/add_two_ints`` ->
                                         ``rl/0/v/add_two_ints``. Query payload = CDR of
                                         the request, encoding
                                         ``application/cdr;<pkg>/srv/<Name>_Request``;
                                         reply = CDR of the response, or an error reply
                                         whose payload is the one-line error text
``rl/D/g/<zid>/v/<node>/<service>/<type>``  liveliness token of a server (``type`` is
                                         ``pkg/srv/Name``; ``/`` written ``%``)
``rl/D/g/<zid>/c/<node>/<service>/<type>``  liveliness token of a client
=======================================  ==============================================

The server answers from its executor thread: the query is handed to the executor, the
callback runs there like any other, and the reply leaves from there.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any, Final

import zenoh

from roverlab.core.errors import ServiceError
from roverlab.msgs import deserialize, serialize

if TYPE_CHECKING:
    from roverlab.core.services import Client, Future, Service
    from roverlab.core.transport.zenoh import ZenohTransport

__all__ = ["CALL_TIMEOUT_S", "ZenohServices", "service_key"]

#: How long a remote call may take before its future fails (a Zenoh query's lifetime).
CALL_TIMEOUT_S: Final = 60.0


def service_key(service: str, domain: int = 0) -> str:
    return f"rl/{domain}/v/{service.lstrip('/')}"


class ZenohServices:
    """The service half of a :class:`~roverlab.core.transport.zenoh.ZenohTransport`."""

    def __init__(self, transport: ZenohTransport) -> None:
        self._t = transport
        self._lock = threading.Lock()
        self._servers: dict[Service, list[Any]] = {}
        self._clients: dict[Client, Any] = {}
        self._queriers: dict[str, Any] = {}
        self._remote: dict[str, set[str]] = {}  # service name -> liveliness keys
        self._watch: Any = None

    # ----------------------------------------------------------------- discovery
    def _ensure_watch(self) -> None:
        """Follow the servers of other processes (liveliness tokens, with history)."""
        if self._watch is not None:
            return
        t = self._t
        prefix = f"rl/{t.domain}/g/"

        def on_token(sample: Any) -> None:
            key = str(sample.key_expr)
            parts = key[len(prefix) :].split("/")
            # zid / v / node / service / type
            if len(parts) != 5 or parts[1] != "v" or parts[0] == t.zid:
                return
            name = parts[3].replace("%", "/")
            with self._lock:
                keys = self._remote.setdefault(name, set())
                if sample.kind == zenoh.SampleKind.PUT:
                    keys.add(key)
                else:
                    keys.discard(key)

        self._watch = t.session.liveliness().declare_subscriber(
            f"rl/{t.domain}/g/*/v/*/*/*", on_token, history=True
        )

    def service_available(self, name: str) -> bool:
        self._ensure_watch()
        with self._lock:
            return bool(self._remote.get(name))

    # ----------------------------------------------------------------- servers
    def on_service(self, service: Service, added: bool) -> None:
        t = self._t
        with self._lock:
            if added:
                queryable = t.session.declare_queryable(
                    service_key(service.srv_name, t.domain),
                    lambda query: self._on_query(service, query),
                )
                token = t.session.liveliness().declare_token(
                    t.graph_key(
                        "v",
                        service.node.get_fully_qualified_name(),
                        service.srv_name,
                        service.srv_type.typename,
                    )
                )
                self._servers[service] = [queryable, token]
            else:
                for ent in self._servers.pop(service, []):
                    ent.undeclare()

    def _on_query(self, service: Service, query: Any) -> None:
        """Zenoh's thread: decode, then serve on the executor thread and reply from there."""
        ctx = self._t.context
        request_type = service.srv_type.Request.typename
        encoding = str(query.encoding) if query.encoding is not None else ""
        sent_type = encoding.partition(";")[2]
        try:
            if sent_type and sent_type != request_type:
                raise ServiceError(
                    f"service '{service.srv_name}' takes {request_type}, got a {sent_type}"
                )
            if query.payload is None:
                raise ServiceError(f"service '{service.srv_name}': a query without a request")
            request = deserialize(query.payload.to_bytes(), request_type)
        except Exception as err:
            _reply_error(query, str(err))
            return
        if ctx is None:
            _reply_error(query, f"service '{service.srv_name}' is shutting down")
            return

        def serve() -> None:
            try:
                response = service.serve(request)
                query.reply(query.key_expr, serialize(response))
            except Exception as err:  # the callback's error, or a response that will not encode
                _reply_error(query, str(err))
            finally:
                query.drop()

        ctx.executor.call_soon_threadsafe(serve)

    # ----------------------------------------------------------------- clients
    def on_client(self, client: Client, added: bool) -> None:
        t = self._t
        with self._lock:
            if added:
                self._clients[client] = t.session.liveliness().declare_token(
                    t.graph_key(
                        "c",
                        client.node.get_fully_qualified_name(),
                        client.srv_name,
                        client.srv_type.typename,
                    )
                )
            else:
                token = self._clients.pop(client, None)
                if token is not None:
                    token.undeclare()
        if added:
            self._ensure_watch()

    def _querier(self, name: str) -> Any:
        with self._lock:
            querier = self._queriers.get(name)
            if querier is None:
                t = self._t
                querier = t.session.declare_querier(
                    service_key(name, t.domain),
                    target=zenoh.QueryTarget.BEST_MATCHING,
                    timeout=CALL_TIMEOUT_S,
                    allowed_destination=zenoh.Locality.REMOTE,
                )
                self._queriers[name] = querier
            return querier

    def call_service(self, client: Client, request: Any, future: Future) -> bool:
        if not self.service_available(client.srv_name):
            return False
        name = client.srv_name
        response_type = client.srv_type.Response.typename
        answered = [False]

        def on_reply(reply: Any) -> None:
            answered[0] = True
            if reply.ok is not None:
                try:
                    future.set_result(deserialize(reply.ok.payload.to_bytes(), response_type))
                except Exception as err:
                    future.set_exception(
                        ServiceError(
                            f"service '{name}': an answer that is not a {response_type}: {err}"
                        )
                    )
            else:
                text = reply.err.payload.to_bytes().decode("utf-8", "replace")
                future.set_exception(ServiceError(text or f"service '{name}' failed"))

        def on_done() -> None:
            if not answered[0]:
                future.set_exception(
                    ServiceError(f"service '{name}' did not answer within {CALL_TIMEOUT_S:g} s")
                )

        payload = serialize(request)
        self._querier(name).get(
            zenoh.handlers.Callback(on_reply, on_done, indirect=False),
            payload=payload,
            encoding=zenoh.Encoding.APPLICATION_CDR.with_schema(client.srv_type.Request.typename),
        )
        return True

    def close(self) -> None:
        with self._lock:
            self._servers.clear()
            self._clients.clear()
            self._queriers.clear()
            self._watch = None


def _reply_error(query: Any, text: str) -> None:
    try:
        query.reply_err(text.encode("utf-8"))
    finally:
        query.drop()
