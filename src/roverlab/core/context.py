"""Context: one process's node graph, its executor and clock, and optional transports."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from typing import Any, Protocol

from roverlab.core.errors import GraphError
from roverlab.core.executor import ClockMode, Executor
from roverlab.core.graph import TopicGraph
from roverlab.core.log import NodeLogger
from roverlab.core.node import Node, Publisher, Subscription, pausing_timer
from roverlab.core.qos import QoSProfile
from roverlab.core.services import Client, Future, Service, ServiceTransport
from roverlab.core.time import Duration, Time
from roverlab.msgs import classes as mc

__all__ = ["Context", "Transport"]


class Transport(Protocol):
    """What a context tells a transport (e.g. Zenoh) about its graph."""

    def attach(self, context: Context) -> None: ...
    def on_node(self, node: Node, added: bool) -> None: ...
    def on_publisher(self, pub: Publisher, added: bool) -> None: ...
    def on_subscription(self, sub: Subscription, added: bool) -> None: ...
    def close(self) -> None: ...


class Context:
    """The graph, executor and clock shared by the nodes of one process.

    Args:
        clock: ``"sim"`` (default: deterministic, as fast as possible), ``"paced"``
            (sim time at ``rate`` x wall clock), ``"wall"`` (system time) or
            ``"external"`` (follow ``/clock`` from another process).
        rate: pacing factor for ``"paced"``; ``math.inf`` is the same as ``"sim"``.
        publish_clock: publish ``/clock`` (default: yes for ``sim`` and ``paced``).
        clock_period_s: sim-time period of ``/clock`` messages.
        start_time_s: initial sim time.
    """

    def __init__(
        self,
        *,
        clock: str = "sim",
        rate: float = 1.0,
        publish_clock: bool | None = None,
        clock_period_s: float = 0.01,
        start_time_s: float = 0.0,
    ) -> None:
        try:
            mode = ClockMode(clock)
        except ValueError:
            raise GraphError(
                f"unknown clock mode {clock!r} (use sim, paced, wall or external)"
            ) from None
        if mode is ClockMode.PACED and math.isinf(rate):
            mode = ClockMode.SIM
        self.executor = Executor(
            mode=mode,
            rate=rate,
            start_ns=Time.from_seconds(start_time_s).nanoseconds,
            on_error=self._callback_error,
        )
        self.graph = TopicGraph()
        self.nodes: dict[str, Node] = {}
        self.transports: list[Transport] = []
        self._unchecked: list[Node] = []
        self._closed = False
        self._logger = NodeLogger("roverlab", lambda: self.executor.now_ns / 1e9)
        self._spin_thread: threading.Thread | None = None
        if publish_clock is None:
            publish_clock = mode in (ClockMode.SIM, ClockMode.PACED)
        self._clock_period_s = clock_period_s
        self._clock_node: Node | None = None
        if publish_clock:
            self._start_clock_publisher()
        if mode is ClockMode.EXTERNAL:
            self._start_clock_follower()

    # ----------------------------------------------------------------- clock
    @property
    def clock_mode(self) -> ClockMode:
        return self.executor.mode

    @property
    def uses_sim_time(self) -> bool:
        return self.executor.mode is not ClockMode.WALL

    def now(self) -> Time:
        return Time(self.executor.now_ns)

    def _start_clock_publisher(self) -> None:
        node = Node("clock_publisher", context=self)
        pub = node.create_publisher(mc.Clock, "/clock", 10)
        ex = self.executor

        def tick() -> None:
            pub.publish(mc.Clock(clock=Time(ex.now_ns).to_msg()))

        # /clock pauses while nobody listens here or in another process
        pausing_timer(node, self._clock_period_s, pub, tick)
        self._clock_node = node

    def _start_clock_follower(self) -> None:
        node = Node("clock_follower", context=self)
        ex = self.executor

        def on_clock(msg: Any) -> None:
            ex.set_external_time(Time.from_msg(msg.clock).nanoseconds)

        node.create_subscription(mc.Clock, "/clock", on_clock, QoSProfile(depth=1))

    # ----------------------------------------------------------------- nodes
    def create_node(self, node_name: str, **kwargs: Any) -> Node:
        return Node(node_name, context=self, **kwargs)

    def _add_node(self, node: Node) -> None:
        fq = node.get_fully_qualified_name()
        if fq in self.nodes:
            raise GraphError(f"a node named '{fq}' already exists in this process")
        self.nodes[fq] = node
        self._unchecked.append(node)
        for t in self.transports:
            t.on_node(node, True)

    def _remove_node(self, node: Node) -> None:
        self.nodes.pop(node.get_fully_qualified_name(), None)
        for t in self.transports:
            t.on_node(node, False)

    def _on_parameter(self, node: Node, param: Any) -> None:
        """A parameter declared on ``node``: transports that keep a parameter server
        (ROS 1's master) mirror it there."""
        for t in self.transports:
            mirror = getattr(t, "on_parameter", None)
            if mirror is not None:
                mirror(node, param)

    def _on_publisher(self, pub: Publisher) -> None:
        for t in self.transports:
            t.on_publisher(pub, True)

    def _on_publisher_removed(self, pub: Publisher) -> None:
        for t in self.transports:
            t.on_publisher(pub, False)
        self.graph.prune(pub.topic)

    def _on_subscription(self, sub: Subscription) -> None:
        for t in self.transports:
            t.on_subscription(sub, True)

    def _on_subscription_removed(self, sub: Subscription) -> None:
        for t in self.transports:
            t.on_subscription(sub, False)
        self.graph.prune(sub.topic)

    def _on_service(self, service: Service, added: bool) -> None:
        for t in self.transports:
            if isinstance(t, ServiceTransport):
                t.on_service(service, added)

    def _on_client(self, client: Client, added: bool) -> None:
        for t in self.transports:
            if isinstance(t, ServiceTransport):
                t.on_client(client, added)

    def _callback_error(self, owner: Any, err: BaseException) -> None:
        node = getattr(owner, "node", None)
        logger = node.get_logger() if node is not None else self._logger
        what = "callback"
        topic = getattr(owner, "topic_name", None)
        if topic is not None:
            what = f"subscription callback on {topic}"
        elif type(owner).__name__ == "Timer":
            what = "timer callback"
        logger.error(f"{what} raised {type(err).__name__}: {err}", exc_info=True)

    # ----------------------------------------------------------------- transports
    def add_transport(self, transport: Transport) -> None:
        """Attach a transport and tell it about everything that already exists."""
        transport.attach(self)
        self.transports.append(transport)
        for node in list(self.nodes.values()):
            transport.on_node(node, True)
            for pub in node.publishers:
                transport.on_publisher(pub, True)
            for sub in node.subscriptions:
                transport.on_subscription(sub, True)
            if isinstance(transport, ServiceTransport):
                for service in node.services:
                    transport.on_service(service, True)
                for client in node.clients:
                    transport.on_client(client, True)

    # ----------------------------------------------------------------- spinning
    def _check_nodes(self) -> None:
        while self._unchecked:
            node = self._unchecked.pop()
            node.check_parameter_overrides()

    def spin(self) -> None:
        """Run until :meth:`shutdown` (or, in ``sim`` mode, until nothing is left to do)."""
        self._check_nodes()
        self.executor.spin()

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Run at most one event; wait up to ``timeout_sec`` wall seconds for one."""
        self._check_nodes()
        self.executor.spin(max_events=1, wall_timeout_s=timeout_sec)

    def spin_for(self, seconds: float) -> None:
        """Run for ``seconds`` of clock time (sim time in ``sim``/``paced`` mode)."""
        self.spin_until(Time(self.executor.now_ns) + Duration.from_seconds(seconds))

    def spin_until(self, t: Time) -> None:
        self._check_nodes()
        self.executor.spin(until_ns=t.nanoseconds)

    def spin_until_condition(
        self, condition: Callable[[], bool], *, timeout_sec: float | None = None
    ) -> bool:
        """Spin until ``condition()`` holds (True) or a wall timeout passes (False)."""
        self._check_nodes()
        self.executor.spin(stop_when=condition, wall_timeout_s=timeout_sec)
        return condition()

    def spin_until_future_complete(self, future: Future, timeout_sec: float | None = None) -> bool:
        """Spin until ``future`` is done or a wall timeout passes; True if done (rclpy's
        ``spin_until_future_complete``)."""
        return self.spin_until_condition(future.done, timeout_sec=timeout_sec)

    def wait_for(self, condition: Callable[[], bool], timeout_sec: float | None = None) -> bool:
        """Block until ``condition()`` holds or ``timeout_sec`` of *clock* time passes (sim
        time in a simulation; None: no timeout); True if it holds.

        With an executor spinning in another thread this polls; with none spinning it spins
        the executor here (in ``sim`` mode the wait costs no wall time). Called from a
        callback it would block the executor that must make ``condition`` true: that is a
        RuntimeError, not a deadlock.

        From another thread the clock time that counts is the time the executor has lived
        (in ``sim`` and ``paced`` modes): a callback that holds the executor for seconds
        of wall time (a costmap's first inflation on a loaded machine) does not use up a
        sim-time timeout while the simulation stands still.
        """
        ex = self.executor
        tid = ex._thread_id
        if tid == threading.get_ident():
            raise RuntimeError(
                "a blocking wait inside a callback would stop the executor it waits for; "
                "use a callback (done_cb, add_done_callback) instead"
            )
        lived = ex.mode in (ClockMode.SIM, ClockMode.PACED)
        start = ex.now_ns if lived and tid is not None else ex.clock_now_ns()
        deadline = None if timeout_sec is None else start + round(timeout_sec * 1e9)
        if tid is None:
            self._check_nodes()
            ex.spin(until_ns=deadline, stop_when=condition)
            return condition()
        while not condition():
            if self._closed or ex.stopped:
                return False
            now = ex.now_ns if lived else ex.clock_now_ns()
            if deadline is not None and now >= deadline:
                return condition()
            time.sleep(0.002)
        return True

    def spin_in_thread(self) -> threading.Thread:
        """Spin in a daemon thread (for scripts and CLIs); :meth:`shutdown` stops it."""
        self._check_nodes()
        thread = threading.Thread(target=self.executor.spin, name="roverlab-executor", daemon=True)
        self._spin_thread = thread
        thread.start()
        return thread

    def is_shutdown(self) -> bool:
        """Whether :meth:`shutdown` was called."""
        return self._closed

    def shutdown(self) -> None:
        """Stop spinning, destroy the nodes and close the transports."""
        if self._closed:
            return
        self._closed = True
        self.executor.stop()
        if self._spin_thread is not None and self._spin_thread is not threading.current_thread():
            self._spin_thread.join(timeout=5)
        for node in list(self.nodes.values()):
            node.destroy_node()
        for t in self.transports:
            t.close()
        self.transports.clear()

    def __enter__(self) -> Context:
        return self

    def __exit__(self, *exc: object) -> None:
        self.shutdown()
