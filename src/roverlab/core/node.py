"""Node, Publisher, Subscription, Timer and Clock with the rclpy vocabulary."""

from __future__ import annotations

import difflib
import heapq
import threading
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any

from roverlab.core.errors import ParameterError
from roverlab.core.graph import Topic, resolve_name, validate_node_name
from roverlab.core.log import NodeLogger
from roverlab.core.parameters import (
    Parameter,
    ParameterDescriptor,
    ParameterType,
    SetCallback,
    SetParametersResult,
)
from roverlab.core.qos import QoSProfile, qos_profile
from roverlab.core.services import Client, Service, ServiceCallback
from roverlab.core.time import Duration, Time
from roverlab.msgs import get_service_type, normalize_type_name, type_name

if TYPE_CHECKING:
    from roverlab.core.context import Context
    from roverlab.core.executor import Executor

__all__ = ["Clock", "Node", "Publisher", "Subscription", "Timer"]


def message_type_name(msg_type: Any) -> str:
    """Full ROS 2 type name of a factory, a rosbags class or a (ROS 1 or 2) type string."""
    if isinstance(msg_type, str):
        return normalize_type_name(msg_type)
    return type_name(msg_type)


class Clock:
    """The node's view of the executor clock (ROS time: sim time inside a simulation).

    Inside a callback it reads the event's time; from another thread, in the real-time
    modes, the live clock (:meth:`Executor.clock_now_ns`).
    """

    def __init__(self, executor: Executor) -> None:
        self._executor = executor

    def now(self) -> Time:
        return Time(self._executor.clock_now_ns())

    def now_ns(self) -> int:
        return self._executor.clock_now_ns()


class Publisher:
    """Publishes on one topic; delivery to local subscriptions is by reference."""

    def __init__(self, node: Node, topic: Topic, qos: QoSProfile) -> None:
        self.node = node
        self.topic = topic
        self.topic_name = topic.name
        self.qos = qos
        # a latched publisher's last messages, each with its place in the topic's order
        # (``Topic.published`` when it was published), for late subscribers
        self.history: deque[tuple[int, Any]] | None = (
            deque(maxlen=qos.depth) if qos.latched else None
        )
        self._executor = node.context.executor

    def publish(self, msg: Any) -> None:
        """Deliver ``msg`` to every subscription of the topic (and remote listeners).

        Messages are passed by reference: treat a published message as read-only.
        Safe to call from any thread; off the executor thread it runs in the caller's
        thread while the executor is parked with nothing to do (the message leaves for
        other processes without a thread hand-off; local callbacks still run on the
        executor), else it is queued in.
        """
        ex = self._executor
        tid = ex._thread_id
        if tid is not None and tid != threading.get_ident():
            ex.run_now_or_soon(lambda: self.publish(msg), drain=False)
            return
        topic = self.topic
        topic.published += 1
        for sub in topic.subscriptions:
            # Subscription._enqueue, inlined (this runs for every delivery)
            q = sub._queue
            if len(q) == sub.depth:
                sub.dropped += 1
            q.append(msg)
            sub._ready.append((next(sub._seq), sub._take_ref))
        if self.history is not None:
            self.history.append((topic.published, msg))
        send = topic.remote_send
        if send is not None:
            send(msg)

    def get_subscription_count(self) -> int:
        return len(self.topic.subscriptions)

    @property
    def has_listeners(self) -> bool:
        """Whether anyone (here or in another process) would receive a message now.

        Publishers of expensive or optional data check it to skip building messages
        nobody reads, as Gazebo's ROS plugins do.
        """
        return bool(self.topic.subscriptions) or self.topic.remote_send is not None

    def when_listened(self, callback: Callable[[], Any]) -> None:
        """Call ``callback`` (on the executor thread) once someone subscribes here or in
        another process: lets a publisher stop its timer while nobody listens."""
        self.topic.listener_watchers.append(callback)

    def destroy(self) -> None:
        self.node.destroy_publisher(self)


def pausing_timer(
    node: Node, period_s: float, publisher: Publisher, tick: Callable[[], Any]
) -> Timer:
    """A timer calling ``tick`` only while ``publisher`` has listeners; it stops while
    nobody listens and restarts when someone subscribes (in this process or another)."""
    timer: Timer

    def fire() -> None:
        if publisher.has_listeners:
            tick()
        else:
            timer.cancel()
            publisher.when_listened(timer.reset)

    timer = node.create_timer(period_s, fire)
    return timer


class Subscription:
    """A callback on one topic with a bounded queue (QoS history depth).

    When more than ``depth`` messages wait for the callback, the oldest is dropped and
    counted in ``dropped``.
    """

    def __init__(
        self, node: Node, topic: Topic, callback: Callable[[Any], Any], qos: QoSProfile
    ) -> None:
        self.node = node
        self.topic = topic
        self.topic_name = topic.name
        self.callback = callback
        self.qos = qos
        self.depth = qos.depth
        self.dropped = 0
        self.received = 0
        self._queue: deque[Any] = deque(maxlen=qos.depth)
        self._ready = node.context.executor._ready
        self._seq = node.context.executor._seq
        self._take_ref = self._take
        self.active = True

    def _enqueue(self, msg: Any) -> None:
        q = self._queue
        if len(q) == self.depth:
            self.dropped += 1
        q.append(msg)
        self._ready.append((next(self._seq), self._take_ref))

    @property
    def pending(self) -> int:
        """Messages waiting for the callback."""
        return len(self._queue)

    def _take(self) -> None:
        if self._queue and self.active:
            self.received += 1
            self.callback(self._queue.popleft())

    def destroy(self) -> None:
        self.node.destroy_subscription(self)


class _TimerFire:
    """One timer generation: its bound :meth:`fire` is the heap entry's callable, and
    firing runs the timer unless it was cancelled or reset since (a new generation has its
    own). A bound method, not ``__call__``: the interpreter calls a bound Python method
    without the C detour an instance's ``__call__`` takes."""

    __slots__ = ("__self__", "generation")

    def __init__(self, timer: Timer) -> None:
        self.__self__ = timer  # lets the executor's error report name the owner
        self.generation = timer._generation

    def fire(self) -> None:
        timer = self.__self__
        if timer.cancelled or self.generation != timer._generation:
            return
        period = timer.period_ns
        nxt = timer._next_ns + period
        ex = timer._executor
        now = ex.now_ns
        if nxt <= now:  # the clock jumped past whole periods: skip them, as rcl does
            nxt += ((now - nxt) // period + 1) * period
        timer._next_ns = nxt
        entry: tuple[int, int, Callable[[], Any]] = (nxt, next(ex._seq), self.fire)
        heapq.heappush(ex._heap, entry)  # ex.call_at, inlined
        timer.callback()


class Timer:
    """Calls ``callback()`` every ``period`` of clock time, without drift."""

    def __init__(self, node: Node, period_ns: int, callback: Callable[[], Any]) -> None:
        self.node = node
        self.period_ns = period_ns
        self.callback = callback
        self._executor = node.context.executor
        self._generation = 0
        self.cancelled = False
        self._start(self._executor.now_ns + period_ns)

    @property
    def timer_period_ns(self) -> int:
        return self.period_ns

    def _start(self, t_ns: int) -> None:
        ex = self._executor
        if not ex.clock_received:  # following a /clock that has not come yet: start then
            delay, generation = t_ns - ex.now_ns, self._generation
            ex.when_clock_starts(lambda: self._start_late(generation, delay))
            return
        self._next_ns = t_ns
        ex.call_at(t_ns, _TimerFire(self).fire)

    def _start_late(self, generation: int, delay_ns: int) -> None:
        if generation == self._generation and not self.cancelled:
            self._start(self._executor.now_ns + delay_ns)

    def cancel(self) -> None:
        self.cancelled = True
        self._generation += 1

    def reset(self) -> None:
        """Restart the period from now (and un-cancel), as rclpy Timer.reset."""
        self.cancelled = False
        self._generation += 1
        self._start(self._executor.now_ns + self.period_ns)

    def is_canceled(self) -> bool:
        return self.cancelled

    def time_until_next_call(self) -> int:
        return max(0, self._next_ns - self._executor.now_ns)

    def destroy(self) -> None:
        self.node.destroy_timer(self)


class Node:
    """A ROS node: publishers, subscriptions, timers, parameters, clock and logger.

    Args:
        node_name: the node's name (letters, digits, ``_``).
        context: the :class:`~roverlab.core.context.Context` (graph + executor) it joins.
        namespace: prefix of relative topic names.
        parameter_overrides: values for parameters this node declares (from a launch file
            or YAML). An override the node never declares is an error when the context
            starts spinning (:meth:`check_parameter_overrides`).
        remappings: ``{from: to}`` topic renames, as ``<remap>`` in a launch file.
    """

    def __init__(
        self,
        node_name: str,
        *,
        context: Context,
        namespace: str = "/",
        parameter_overrides: Mapping[str, Any] | None = None,
        remappings: Mapping[str, str] | None = None,
    ) -> None:
        self._name = validate_node_name(node_name)
        self._namespace = "/" + namespace.strip("/") if namespace.strip("/") else "/"
        self.context = context
        self._clock = Clock(context.executor)
        self._logger = NodeLogger(self.get_fully_qualified_name(), self._stamp)
        self._overrides = dict(parameter_overrides or {})
        self._remap = {
            resolve_name(k, self._namespace, node_name): resolve_name(v, self._namespace, node_name)
            for k, v in (remappings or {}).items()
        }
        self._parameters: dict[str, Parameter] = {}
        self._set_callbacks: list[SetCallback] = []
        self.publishers: list[Publisher] = []
        self.subscriptions: list[Subscription] = []
        self.timers: list[Timer] = []
        self.services: list[Service] = []
        self.clients: list[Client] = []
        self._destroyed = False
        self.exit_code: int | None = None
        """Set by a node that ends itself as a ROS 1 process exits (``map_saver`` once the
        map is written: 0, or 1 when writing failed); None while it runs."""
        context._add_node(self)
        self.declare_parameter("use_sim_time", context.uses_sim_time)

    # ----------------------------------------------------------------- names
    def get_name(self) -> str:
        return self._name

    def get_namespace(self) -> str:
        return self._namespace

    def get_fully_qualified_name(self) -> str:
        return self._namespace.rstrip("/") + "/" + self._name

    def resolve_topic_name(self, topic: str) -> str:
        full = resolve_name(topic, self._namespace, self._name)
        return self._remap.get(full, full)

    def _stamp(self) -> float:
        return self.context.executor.now_ns / 1e9

    def get_clock(self) -> Clock:
        return self._clock

    def get_logger(self) -> NodeLogger:
        return self._logger

    # ----------------------------------------------------------------- pub/sub/timers
    def create_publisher(
        self, msg_type: Any, topic: str, qos_profile_or_depth: QoSProfile | int = 10
    ) -> Publisher:
        qos = qos_profile(qos_profile_or_depth)
        t = self.context.graph.get(self.resolve_topic_name(topic), message_type_name(msg_type))
        pub = Publisher(self, t, qos)
        t.publishers.append(pub)
        self.publishers.append(pub)
        self.context._on_publisher(pub)
        return pub

    def create_subscription(
        self,
        msg_type: Any,
        topic: str,
        callback: Callable[[Any], Any],
        qos_profile_or_depth: QoSProfile | int = 10,
    ) -> Subscription:
        qos = qos_profile(qos_profile_or_depth)
        t = self.context.graph.get(self.resolve_topic_name(topic), message_type_name(msg_type))
        sub = Subscription(self, t, callback, qos)
        t.subscriptions.append(sub)
        self.subscriptions.append(sub)
        # Latched (transient-local) history reaches every late subscriber, as ROS 1's
        # latched topics do (ROS 2 also wants the subscriber transient-local; being
        # lenient here saves the usual "why is /map empty" question).
        history = t.latched_history()
        if history:
            ex = self.context.executor
            if ex.on_executor_thread():
                for msg in history:
                    sub._enqueue(msg)
            else:  # another thread: hand it in, so the executor wakes for it
                ex.run_now_or_soon(lambda: [sub._enqueue(msg) for msg in history])
        self.context._on_subscription(sub)
        if t.listener_watchers:
            t.notify_listeners()
        return sub

    def create_timer(self, timer_period_sec: float, callback: Callable[[], Any]) -> Timer:
        period = Duration.from_seconds(timer_period_sec).nanoseconds
        if period <= 0:
            raise ValueError(f"timer period must be > 0 s, got {timer_period_sec}")
        timer = Timer(self, period, callback)
        self.timers.append(timer)
        return timer

    def create_service(self, srv_type: Any, srv_name: str, callback: ServiceCallback) -> Service:
        """Serve ``srv_name``: ``callback(request, response)`` returns the response.

        ``srv_type`` is a :class:`~roverlab.msgs.ServiceType` or its name in the ROS 1 or 2
        spelling (``"std_srvs/Empty"``, ``"std_srvs/srv/Empty"``). A second server of the
        same name in a process takes over from the first until it is destroyed, with a
        warning (ROS 1's rule).
        """
        service = Service(
            self, get_service_type(srv_type), self.resolve_topic_name(srv_name), callback
        )
        replaced = self.context.graph.add_service(service)
        if replaced is not None:
            self.get_logger().warning(
                f"service '{service.srv_name}' was served by "
                f"'{replaced.node.get_fully_qualified_name()}': this node serves it now"
            )
        self.services.append(service)
        self.context._on_service(service, True)
        return service

    def create_client(self, srv_type: Any, srv_name: str) -> Client:
        """A client of ``srv_name`` (``call``, ``call_async``, ``wait_for_service``)."""
        client = Client(self, get_service_type(srv_type), self.resolve_topic_name(srv_name))
        self.clients.append(client)
        self.context._on_client(client, True)
        return client

    def destroy_service(self, service: Service) -> None:
        if service in self.services:
            self.services.remove(service)
            self.context.graph.remove_service(service)
            self.context._on_service(service, False)

    def destroy_client(self, client: Client) -> None:
        if client in self.clients:
            self.clients.remove(client)
            self.context._on_client(client, False)

    def destroy_publisher(self, pub: Publisher) -> None:
        if pub in self.publishers:
            self.publishers.remove(pub)
            pub.topic.publishers.remove(pub)
            self.context._on_publisher_removed(pub)

    def destroy_subscription(self, sub: Subscription) -> None:
        if sub in self.subscriptions:
            sub.active = False
            self.subscriptions.remove(sub)
            sub.topic.subscriptions.remove(sub)
            self.context._on_subscription_removed(sub)

    def destroy_timer(self, timer: Timer) -> None:
        timer.cancel()
        if timer in self.timers:
            self.timers.remove(timer)

    def is_destroyed(self) -> bool:
        """Whether :meth:`destroy_node` was called (by the node itself or its context)."""
        return self._destroyed

    def destroy_node(self) -> None:
        if self._destroyed:
            return
        for pub in list(self.publishers):
            self.destroy_publisher(pub)
        for sub in list(self.subscriptions):
            self.destroy_subscription(sub)
        for timer in list(self.timers):
            self.destroy_timer(timer)
        for service in list(self.services):
            self.destroy_service(service)
        for client in list(self.clients):
            self.destroy_client(client)
        self._destroyed = True
        self.context._remove_node(self)

    # ----------------------------------------------------------------- parameters
    def declare_parameter(
        self,
        name: str,
        value: Any = None,
        descriptor: ParameterDescriptor | None = None,
        *,
        ignore_override: bool = False,
    ) -> Parameter:
        """Declare a parameter; its type is the default's type and is fixed from then on.

        An override from a launch file or YAML replaces the default (validated).
        """
        if name in self._parameters:
            raise ParameterError(f"node '{self._name}': parameter '{name}' declared twice")
        ptype = ParameterType.of(value)
        param = Parameter(name, ptype, value, descriptor or ParameterDescriptor())
        if ptype is not ParameterType.NOT_SET:
            param.value = param.validate(value)
        if not ignore_override and name in self._overrides:
            try:
                param.value = param.validate(self._overrides[name])
            except ParameterError as err:
                raise ParameterError(f"node '{self._name}': {err}") from err
        self._parameters[name] = param
        self.context._on_parameter(self, param)
        return param

    def declare_parameters(
        self, namespace: str, parameters: Iterable[tuple[str, Any]]
    ) -> list[Parameter]:
        prefix = f"{namespace}." if namespace else ""
        return [self.declare_parameter(prefix + n, v) for n, v in parameters]

    def has_parameter(self, name: str) -> bool:
        return name in self._parameters

    def get_parameter(self, name: str) -> Parameter:
        try:
            return self._parameters[name]
        except KeyError:
            raise ParameterError(self._unknown_parameter(name)) from None

    def get_parameters(self, names: Iterable[str]) -> list[Parameter]:
        return [self.get_parameter(n) for n in names]

    def get_parameter_value(self, name: str) -> Any:
        return self.get_parameter(name).value

    @property
    def parameters(self) -> Mapping[str, Parameter]:
        return self._parameters

    def set_parameter(self, name: str, value: Any) -> SetParametersResult:
        """Set one declared parameter; raises ParameterError if unknown or mistyped."""
        param = self.get_parameter(name)
        if param.descriptor.read_only:
            raise ParameterError(f"node '{self._name}': parameter '{name}' is read-only")
        new = Parameter(name, param.type, param.validate(value), param.descriptor)
        for cb in self._set_callbacks:
            result = cb([new])
            if not result.successful:
                return result
        param.value = new.value
        return SetParametersResult(True)

    def set_parameters(self, parameters: Iterable[Parameter]) -> list[SetParametersResult]:
        return [self.set_parameter(p.name, p.value) for p in parameters]

    def add_on_set_parameters_callback(self, callback: SetCallback) -> None:
        self._set_callbacks.append(callback)

    def _unknown_parameter(self, name: str) -> str:
        near = difflib.get_close_matches(name, list(self._parameters), n=1)
        hint = f" (did you mean '{near[0]}'?)" if near else ""
        return f"node '{self._name}' has no parameter '{name}'{hint}"

    def has_parameter_override(self, name: str) -> bool:
        """Whether a launch file, YAML or ``_name:=value`` gave parameter ``name``."""
        return name in self._overrides

    def unused_parameter_overrides(self) -> list[str]:
        """Overrides (from a launch file or YAML) that name no declared parameter."""
        return [name for name in self._overrides if name not in self._parameters]

    def discard_parameter_overrides(self, names: Iterable[str]) -> None:
        """Forget overrides, e.g. ROS parameters a roverlab node does not implement."""
        for name in names:
            self._overrides.pop(name, None)

    def check_parameter_overrides(self) -> None:
        """Raise ParameterError for an override that names no declared parameter."""
        for name in self._overrides:
            if name not in self._parameters:
                raise ParameterError(self._unknown_parameter(name))
