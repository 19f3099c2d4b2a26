"""Services with rclpy's semantics: Future, Service (server) and Client.

A call finds its server in this process first (the request is passed by reference and the
server's callback runs on the executor), then over a transport (Zenoh: CDR request and
response, see :mod:`roverlab.core.transport.zenoh_services`).

Differences from rclpy, on purpose:

* ``call_async`` on a service nobody serves fails at once with
  :class:`~roverlab.core.errors.ServiceUnavailableError` (rclpy's future never completes);
* a server callback that raises gives the caller a :class:`ServiceError` naming the
  service and the exception, and the server keeps serving (rclpy's server dies with it);
* ``call`` from the executor's own thread, or while nothing spins, does not deadlock: a
  server in this process is run inline; a remote answer is waited for on the caller's
  thread.
"""

from __future__ import annotations

import functools
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from roverlab.core.errors import ServiceError, ServiceUnavailableError
from roverlab.msgs import ServiceType
from roverlab.msgs._values import from_dict

if TYPE_CHECKING:
    from roverlab.core.executor import Executor
    from roverlab.core.node import Node

__all__ = ["Client", "Future", "Service", "ServiceTransport"]

ServiceCallback = Callable[[Any, Any], Any]


class Future:
    """The outcome of an asynchronous call, as rclpy.task.Future.

    ``result()`` returns the result, or raises the exception the call ended with. Done
    callbacks run on the executor thread (at once if the executor is not known).
    """

    def __init__(self, executor: Executor | None = None) -> None:
        self._executor = executor
        self._lock = threading.Lock()
        self._event = threading.Event()
        self._result: Any = None
        self._exception: BaseException | None = None
        self._cancelled = False
        self._callbacks: list[Callable[[Future], Any]] = []

    def done(self) -> bool:
        return self._event.is_set()

    def cancelled(self) -> bool:
        return self._cancelled

    def cancel(self) -> None:
        """Stop caring about the outcome: the future is done and a late answer ignored."""
        self._finish(None, None, cancelled=True)

    def result(self) -> Any:
        """The result (None while not done, or when cancelled); raises the call's error."""
        if self._exception is not None:
            raise self._exception
        return self._result

    def exception(self) -> BaseException | None:
        return self._exception

    def set_result(self, result: Any) -> None:
        self._finish(result, None)

    def set_exception(self, exception: BaseException) -> None:
        self._finish(None, exception)

    def wait(self, timeout_s: float | None = None) -> bool:
        """Block the calling thread until done (wall ``timeout_s``); True if done."""
        return self._event.wait(timeout_s)

    def add_done_callback(self, callback: Callable[[Future], Any]) -> None:
        """Call ``callback(future)`` once done (right away, scheduled, if already done)."""
        with self._lock:
            if not self._event.is_set():
                self._callbacks.append(callback)
                return
        self._schedule([callback])

    def _finish(
        self, result: Any, exception: BaseException | None, cancelled: bool = False
    ) -> None:
        with self._lock:
            if self._event.is_set():
                return  # the first outcome wins (a late reply after a timeout, ...)
            self._result = result
            self._exception = exception
            self._cancelled = cancelled
            self._event.set()
            callbacks, self._callbacks = self._callbacks, []
        if callbacks:
            self._schedule(callbacks)

    def _schedule(self, callbacks: list[Callable[[Future], Any]]) -> None:
        ex = self._executor
        for cb in callbacks:
            if ex is None:
                cb(self)
            elif ex.on_executor_thread():
                ex.call_soon(functools.partial(cb, self))
            else:
                ex.call_soon_threadsafe(functools.partial(cb, self))


@runtime_checkable
class ServiceTransport(Protocol):
    """What a transport offers for services in other processes."""

    def on_service(self, service: Service, added: bool) -> None: ...
    def on_client(self, client: Client, added: bool) -> None: ...
    def service_available(self, name: str) -> bool: ...
    def call_service(self, client: Client, request: Any, future: Future) -> bool:
        """Send ``request`` to a remote server and complete ``future`` with its answer;
        False if no remote server is known."""
        ...


def _check_message(value: Any, factory: Any, what: str) -> Any:
    if isinstance(value, factory.cls):
        return value
    if isinstance(value, dict):
        return from_dict(factory.typename, value)
    raise ServiceError(f"{what}: expected {factory.typename}, got {type(value).__name__}")


class Service:
    """A service server: ``callback(request, response) -> response`` on the executor.

    Created with :meth:`roverlab.core.Node.create_service`.
    """

    def __init__(
        self, node: Node, srv_type: ServiceType, srv_name: str, callback: ServiceCallback
    ) -> None:
        self.node = node
        self.srv_type = srv_type
        self.srv_name = srv_name
        self.callback = callback
        self.calls = 0
        self.failures = 0

    def serve(self, request: Any) -> Any:
        """Run the callback on ``request`` and return the checked response.

        Raises:
            ServiceError: the callback raised, or returned something else than a response.
        """
        self.calls += 1
        name = self.srv_name
        try:
            response = self.callback(request, self.srv_type.Response())
        except Exception as err:
            self.failures += 1
            text = f"service '{name}' failed: callback raised {type(err).__name__}: {err}"
            self.node.get_logger().error(text)
            raise ServiceError(text) from err
        try:
            return _check_message(
                response, self.srv_type.Response, f"service '{name}': the callback's return"
            )
        except Exception as err:
            self.failures += 1
            self.node.get_logger().error(str(err))
            raise ServiceError(str(err)) from err

    def serve_into(self, request: Any, future: Future) -> None:
        """Serve ``request`` and complete ``future`` (the executor's event for one call)."""
        if future.done():
            return  # cancelled by the caller meanwhile
        try:
            future.set_result(self.serve(request))
        except ServiceError as err:
            future.set_exception(err)

    def destroy(self) -> None:
        self.node.destroy_service(self)


class Client:
    """A service client, created with :meth:`roverlab.core.Node.create_client`."""

    def __init__(self, node: Node, srv_type: ServiceType, srv_name: str) -> None:
        self.node = node
        self.srv_type = srv_type
        self.srv_name = srv_name
        self._context = node.context

    # ----------------------------------------------------------------- availability
    def _local_server(self) -> Service | None:
        server = self._context.graph.services.get(self.srv_name)
        if server is not None and server.srv_type.typename != self.srv_type.typename:
            raise ServiceError(
                f"service '{self.srv_name}' is of type {server.srv_type.typename}, "
                f"not {self.srv_type.typename}"
            )
        return server

    def _transports(self) -> list[ServiceTransport]:
        return [t for t in self._context.transports if isinstance(t, ServiceTransport)]

    def service_is_ready(self) -> bool:
        """Whether a server is known now, in this process or another."""
        if self.srv_name in self._context.graph.services:
            return True
        return any(t.service_available(self.srv_name) for t in self._transports())

    def wait_for_service(self, timeout_sec: float | None = None) -> bool:
        """Wait (wall seconds; forever when None) until a server is known; False on timeout."""
        deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
        while not self.service_is_ready():
            if deadline is not None and time.monotonic() >= deadline:
                return False
            time.sleep(0.01)
        return True

    # ----------------------------------------------------------------- calls
    def _request(self, request: Any) -> Any:
        return _check_message(request, self.srv_type.Request, f"call of '{self.srv_name}'")

    def call_async(self, request: Any) -> Future:
        """Send ``request``; the returned future completes with the response (or a
        :class:`ServiceError`) on the executor."""
        future = Future(self._context.executor)
        try:
            request = self._request(request)
            server = self._local_server()
        except ServiceError as err:
            future.set_exception(err)
            return future
        if server is not None:
            ex = self._context.executor
            job = functools.partial(server.serve_into, request, future)
            if ex.on_executor_thread():
                ex.call_soon(job)
            else:
                ex.call_soon_threadsafe(job)
            return future
        for transport in self._transports():
            if transport.call_service(self, request, future):
                return future
        future.set_exception(ServiceUnavailableError(f"service '{self.srv_name}' is not available"))
        return future

    def call(self, request: Any, timeout_sec: float | None = None) -> Any:
        """Send ``request`` and wait (wall ``timeout_sec``) for the response.

        Returns the response, or None when the timeout passes first (as rclpy).

        Raises:
            ServiceError: the call failed (server error, bad request, no server).
        """
        ex = self._context.executor
        server = self._local_server() if ex.on_executor_thread() else None
        if server is not None:  # nothing else can run it: serve it on this thread
            return server.serve(self._request(request))
        future = self.call_async(request)
        if not future.wait(timeout_sec):
            future.cancel()
            return None
        return future.result()

    def remove_pending_request(self, future: Future) -> None:
        """Forget a call (rclpy): its future is cancelled and a late answer ignored."""
        future.cancel()

    def destroy(self) -> None:
        self.node.destroy_client(self)
