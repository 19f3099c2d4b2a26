"""rospy for ROS 1 scripts run by ``roverlab run``: the same calls, on roverlab's runtime.

Covered: ``init_node`` (anonymous, ``__name:=``, ``__ns:=``, remaps ``a:=b``, private
parameters ``_p:=v``), ``Publisher`` (queue_size, latch; created before ``init_node`` too),
``Subscriber`` (callback_args), ``Rate``, ``sleep``, ``spin``, ``is_shutdown``,
``on_shutdown``, ``signal_shutdown``, ``get_param`` / ``set_param`` / ``has_param`` /
``delete_param`` / ``search_param`` (``~private``, global; ``/node/param`` reads a running
node's parameter), ``loginfo`` / ``logwarn`` / ``logerr`` / ``logdebug`` / ``logfatal``
(and ``_throttle`` / ``_once``), ``Time`` / ``Duration``, ``Timer``,
``wait_for_message``, ``Service`` / ``ServiceProxy`` / ``wait_for_service``,
``get_name``, ``get_namespace``, ``get_caller_id``, ``get_rostime``, ``get_time``,
``myargv``, ``remap_name``, ``resolve_name`` and rospy's exceptions.

Callbacks run on roverlab's executor thread (rospy runs one thread per subscriber). Time
is ROS time: sim time when the node follows ``/clock``. A sleep is interrupted by the
shutdown (Ctrl-C, SIGTERM, SIGHUP) with ``ROSInterruptException`` in every clock mode
(rospy does so only on sim time).
"""

from __future__ import annotations

import sys
import time as _time
from collections.abc import Callable
from typing import Any

from roverlab.core import Node, QoSProfile, ServiceError
from roverlab.core.services import ServiceTransport
from roverlab.msgs import get_service_type
from roverlab.ros1.rospy import exceptions
from roverlab.ros1.rospy.exceptions import (
    ROSException,
    ROSInitException,
    ROSInterruptException,
    ROSTimeMovedBackwardsException,
    ServiceException,
)
from roverlab.ros1.rospy.rostime import Duration, Time
from roverlab.ros1.rospy.runtime import RUNTIME

__all__ = [
    "DEBUG",
    "ERROR",
    "FATAL",
    "INFO",
    "WARN",
    "Duration",
    "Publisher",
    "ROSException",
    "ROSInitException",
    "ROSInterruptException",
    "ROSTimeMovedBackwardsException",
    "Rate",
    "Service",
    "ServiceException",
    "ServiceProxy",
    "Subscriber",
    "Time",
    "Timer",
    "TimerEvent",
    "delete_param",
    "exceptions",
    "get_caller_id",
    "get_name",
    "get_namespace",
    "get_param",
    "get_param_names",
    "get_rostime",
    "get_time",
    "has_param",
    "init_node",
    "is_shutdown",
    "logdebug",
    "logerr",
    "logerr_once",
    "logerr_throttle",
    "logfatal",
    "loginfo",
    "loginfo_once",
    "loginfo_throttle",
    "logwarn",
    "logwarn_once",
    "logwarn_throttle",
    "myargv",
    "on_shutdown",
    "remap_name",
    "resolve_name",
    "search_param",
    "set_param",
    "signal_shutdown",
    "sleep",
    "spin",
    "wait_for_message",
    "wait_for_service",
]

DEBUG, INFO, WARN, ERROR, FATAL = 1, 2, 4, 8, 16
_LEVEL_NAMES = {DEBUG: "DEBUG", INFO: "INFO", WARN: "WARN", ERROR: "ERROR", FATAL: "FATAL"}
_log_level = [INFO]


# ----------------------------------------------------------------------------- node
def init_node(
    name: str,
    argv: list[str] | None = None,
    anonymous: bool = False,
    log_level: int | None = None,
    disable_rostime: bool = False,
    disable_rosout: bool = False,
    disable_signals: bool = False,
    xmlrpc_port: int = 0,
    tcpros_port: int = 0,
) -> None:
    """Start this process's node (rospy.init_node)."""
    if log_level is not None:
        _log_level[0] = int(log_level)
    RUNTIME.init_node(name, anonymous=anonymous, argv=argv, disable_signals=disable_signals)


def get_name() -> str:
    return RUNTIME.require_node().get_fully_qualified_name()


get_caller_id = get_name


def get_namespace() -> str:
    ns = RUNTIME.require_node().get_namespace()
    return ns if ns.endswith("/") else ns + "/"


def myargv(argv: list[str] | None = None) -> list[str]:
    """``argv`` without the ``name:=value`` arguments."""
    return [a for a in (sys.argv if argv is None else argv) if ":=" not in a]


def resolve_name(name: str, caller_id: str | None = None) -> str:
    return RUNTIME.resolve(name)


def remap_name(name: str, caller_id: str | None = None, resolved: bool = True) -> str:
    node = RUNTIME.node
    return node.resolve_topic_name(name) if node is not None else name


def is_shutdown() -> bool:
    return RUNTIME.shutdown_flag


def on_shutdown(h: Callable[..., Any]) -> None:
    """Call ``h()`` when the node shuts down (before ``is_shutdown()`` turns True)."""
    RUNTIME.hooks.append(h)


def signal_shutdown(reason: str) -> None:
    RUNTIME.signal_shutdown(reason)


def spin() -> None:
    """Block until the node shuts down."""
    RUNTIME.require_node()
    while not RUNTIME.shutdown_flag:
        _time.sleep(0.05)
        RUNTIME.hold_during_hooks()


# ----------------------------------------------------------------------------- time
def get_rostime() -> Time:
    return Time.now()


def get_time() -> float:
    return Time.now().to_sec()


def _seconds(duration: Any) -> float:
    if hasattr(duration, "to_sec"):
        return float(duration.to_sec())
    return float(duration)


def sleep(duration: Any) -> None:
    """Sleep ``duration`` (seconds or a Duration) of ROS time; a shutdown raises
    ROSInterruptException."""
    seconds = _seconds(duration)
    if seconds <= 0:
        if RUNTIME.shutdown_flag:
            raise ROSInterruptException("ROS shutdown request")
        return
    RUNTIME.sleep_until(RUNTIME.now_ns() + round(seconds * 1e9))


class Rate:
    """Loop at ``hz`` of ROS time (rospy.Rate)."""

    def __init__(self, hz: float, reset: bool = False) -> None:
        if not hz > 0:
            raise ROSException(f"rate must be > 0 Hz, got {hz}")
        self.sleep_dur_ns = round(1e9 / hz)
        self.last_ns = RUNTIME.now_ns()
        self._reset = reset

    def remaining(self) -> Duration:
        return Duration.from_nsec(self.last_ns + self.sleep_dur_ns - RUNTIME.now_ns())

    def sleep(self) -> None:
        # As rospy: sleep until last + period, then judge "too slow" by the time of the
        # call, so a late wake-up is made up by the next iterations (they return at once)
        # instead of pushing the whole schedule back.
        curr = RUNTIME.now_ns()
        if curr < self.last_ns:  # time jumped back
            self.last_ns = curr
        RUNTIME.sleep_until(self.last_ns + self.sleep_dur_ns)
        self.last_ns += self.sleep_dur_ns
        if curr - self.last_ns > 2 * self.sleep_dur_ns:  # time jumped ahead / loop too slow
            self.last_ns = curr


class TimerEvent:
    """What a Timer callback receives."""

    def __init__(
        self,
        last_expected: Any,
        last_real: Any,
        current_expected: Any,
        current_real: Any,
        last_duration: float | None,
    ) -> None:
        self.last_expected = last_expected
        self.last_real = last_real
        self.current_expected = current_expected
        self.current_real = current_real
        self.last_duration = last_duration


class Timer:
    """Call ``callback(TimerEvent)`` every ``period`` of ROS time, on the executor."""

    def __init__(
        self,
        period: Any,
        callback: Callable[[TimerEvent], Any],
        oneshot: bool = False,
        reset: bool = False,
    ) -> None:
        node = RUNTIME.require_node()
        self._callback = callback
        self._oneshot = oneshot
        self._last: Time | None = None
        self._timer = node.create_timer(_seconds(period), self._fire)

    def _fire(self) -> None:
        now = Time.now()
        self._callback(TimerEvent(self._last, self._last, now, now, None))
        self._last = now
        if self._oneshot:
            self.shutdown()

    def shutdown(self) -> None:
        self._timer.destroy()


# ----------------------------------------------------------------------------- logging
def _log(level: int, msg: Any, args: tuple[Any, ...]) -> None:
    if level < _log_level[0]:
        return
    text = str(msg) % args if args else str(msg)
    wall = _time.time()
    stamp = f"{wall:.6f}"
    ctx = RUNTIME.context
    if ctx is not None and not RUNTIME.uses_wall_clock():
        stamp += f", {ctx.executor.clock_now_ns() / 1e9:.6f}"
    stream = sys.stdout if level <= INFO else sys.stderr
    # one write per line: a shutdown hook logging from the signal handler must not land
    # between a line and its newline
    stream.write(f"[{_LEVEL_NAMES[level]}] [{stamp}]: {text}\n")
    stream.flush()


def logdebug(msg: Any, *args: Any, **kwargs: Any) -> None:
    _log(DEBUG, msg, args)


def loginfo(msg: Any, *args: Any, **kwargs: Any) -> None:
    _log(INFO, msg, args)


def logwarn(msg: Any, *args: Any, **kwargs: Any) -> None:
    _log(WARN, msg, args)


def logerr(msg: Any, *args: Any, **kwargs: Any) -> None:
    _log(ERROR, msg, args)


def logfatal(msg: Any, *args: Any, **kwargs: Any) -> None:
    _log(FATAL, msg, args)


_THROTTLE: dict[tuple[int, str], float] = {}
_ONCE: set[tuple[int, str]] = set()


def _throttled(level: int) -> Callable[..., None]:
    def log(period: float, msg: Any, *args: Any) -> None:
        key = (level, str(msg))
        now = _time.monotonic()
        if now - _THROTTLE.get(key, -1e300) >= period:
            _THROTTLE[key] = now
            _log(level, msg, args)

    return log


def _once(level: int) -> Callable[..., None]:
    def log(msg: Any, *args: Any) -> None:
        key = (level, str(msg))
        if key not in _ONCE:
            _ONCE.add(key)
            _log(level, msg, args)

    return log


loginfo_throttle, logwarn_throttle, logerr_throttle = (_throttled(x) for x in (INFO, WARN, ERROR))
loginfo_once, logwarn_once, logerr_once = (_once(x) for x in (INFO, WARN, ERROR))


# ----------------------------------------------------------------------------- parameters
_MISSING = object()


def get_param(param_name: str, default: Any = _MISSING) -> Any:
    """A parameter's value; ``default`` (or KeyError) when it is not set."""
    try:
        return RUNTIME.get_param(param_name)
    except KeyError:
        if default is _MISSING:
            raise
        if param_name.startswith("~"):
            RUNTIME.set_param(param_name, default)  # visible as the node's parameter
        return default


def set_param(param_name: str, param_value: Any) -> None:
    RUNTIME.set_param(param_name, param_value)


def has_param(param_name: str) -> bool:
    try:
        RUNTIME.get_param(param_name)
    except KeyError:
        return False
    return True


def delete_param(param_name: str) -> None:
    if param_name.startswith("~"):
        key = param_name[1:].lstrip("/")
        if key not in RUNTIME.private:
            raise KeyError(param_name)
        del RUNTIME.private[key]
        return
    full = RUNTIME.resolve(param_name)
    if full not in RUNTIME.params:
        raise KeyError(param_name)
    del RUNTIME.params[full]


def search_param(param_name: str) -> str | None:
    """The closest set parameter of that name, from the node's namespace upwards."""
    node = RUNTIME.node
    ns = node.get_fully_qualified_name() if node is not None else ""
    parts = ns.strip("/").split("/") if ns.strip("/") else []
    for cut in range(len(parts), -1, -1):
        candidate = "/" + "/".join([*parts[:cut], param_name.strip("/")])
        if has_param(candidate):
            return candidate
    return None


def get_param_names() -> list[str]:
    own = get_name() + "/" if RUNTIME.node is not None else "~"
    return sorted([*RUNTIME.params, *(own + k for k in RUNTIME.private)])


# ----------------------------------------------------------------------------- topics
def _bind(make: Callable[[Node], None]) -> None:
    if RUNTIME.node is not None:
        make(RUNTIME.node)
    else:
        RUNTIME.pending.append(make)


class Publisher:
    """rospy.Publisher: ``Publisher("cmd_vel", Twist, queue_size=1, latch=False)``."""

    def __init__(
        self,
        name: str,
        data_class: Any,
        subscriber_listener: Any = None,
        tcp_nodelay: bool = False,
        latch: bool = False,
        headers: Any = None,
        queue_size: int | None = None,
    ) -> None:
        self.name = name
        self.data_class = data_class
        self.type = getattr(data_class, "_type", str(data_class))
        depth = max(1, int(queue_size or 10))
        self._qos = QoSProfile(depth=depth, durability="transient_local" if latch else "volatile")
        self._pub: Any = None
        _bind(self._create)

    def _create(self, node: Node) -> None:
        self._pub = node.create_publisher(self.data_class, self.name, self._qos)
        self.resolved_name = self._pub.topic_name

    def publish(self, *args: Any, **kwds: Any) -> None:
        """Publish a message, or build one from ``args`` / ``kwds`` and publish it."""
        if self._pub is None:
            raise ROSException("ROS node has not been initialized (call rospy.init_node)")
        if len(args) == 1 and not kwds and isinstance(args[0], self.data_class):
            msg = args[0]
        else:
            msg = self.data_class(*args, **kwds)
        self._pub.publish(msg)

    def get_num_connections(self) -> int:
        if self._pub is None:
            return 0
        return self._pub.get_subscription_count() + (1 if self._pub.topic.remote_send else 0)

    def unregister(self) -> None:
        if self._pub is not None:
            self._pub.destroy()
            self._pub = None


class Subscriber:
    """rospy.Subscriber: ``Subscriber("scan", LaserScan, callback, callback_args=None)``."""

    def __init__(
        self,
        name: str,
        data_class: Any,
        callback: Callable[..., Any] | None = None,
        callback_args: Any = None,
        queue_size: int | None = None,
        buff_size: int = 65536,
        tcp_nodelay: bool = False,
    ) -> None:
        self.name = name
        self.data_class = data_class
        self.callback = callback
        self.callback_args = callback_args
        self._depth = max(1, int(queue_size or 100))
        self._sub: Any = None
        _bind(self._create)

    def _create(self, node: Node) -> None:
        self._sub = node.create_subscription(
            self.data_class, self.name, self._deliver, QoSProfile(depth=self._depth)
        )
        self.resolved_name = self._sub.topic_name

    def _deliver(self, msg: Any) -> None:
        if self.callback is None:
            return
        if self.callback_args is None:
            self.callback(msg)
        else:
            self.callback(msg, self.callback_args)

    def get_num_connections(self) -> int:
        return 0 if self._sub is None else len(self._sub.topic.publishers)

    def unregister(self) -> None:
        if self._sub is not None:
            self._sub.destroy()
            self._sub = None


def wait_for_message(topic: str, topic_type: Any, timeout: Any = None) -> Any:
    """The next message on ``topic`` (ROSException after ``timeout`` wall seconds)."""
    got: list[Any] = []
    sub = Subscriber(topic, topic_type, got.append, queue_size=1)
    deadline = None if timeout is None else _time.monotonic() + _seconds(timeout)
    try:
        while not got:
            RUNTIME.hold_during_hooks()
            if RUNTIME.shutdown_flag:
                raise ROSInterruptException("rospy shutdown")
            if deadline is not None and _time.monotonic() >= deadline:
                raise ROSException(f"timeout exceeded while waiting for message on topic {topic}")
            _time.sleep(0.005)
    finally:
        sub.unregister()
    return got[0]


# ----------------------------------------------------------------------------- services
def _response(srv: Any, value: Any) -> Any:
    """rospy's accepted handler returns: a response, a dict, a tuple/list, one value."""
    cls = srv.Response
    if isinstance(value, cls):
        return value
    if value is None:
        raise ServiceException("service handler returned None")
    if isinstance(value, dict):
        return cls(**value)
    fields = cls.fields
    if isinstance(value, list | tuple):
        return cls(**dict(zip(fields, value, strict=True)))
    if len(fields) == 1:
        return cls(**{fields[0]: value})
    raise ServiceException(f"service handler returned {type(value).__name__}, not a response")


class Service:
    """rospy.Service: ``Service("add_two_ints", AddTwoInts, handler)``; ``handler(req)``
    returns the response."""

    def __init__(self, name: str, service_class: Any, handler: Callable[[Any], Any]) -> None:
        self.resolved_name = name
        srv = get_service_type(service_class)

        def callback(request: Any, _response_template: Any) -> Any:
            return _response(srv, handler(request))

        self._service = RUNTIME.require_node().create_service(srv, name, callback)
        self.resolved_name = self._service.srv_name

    def shutdown(self, reason: str = "") -> None:
        self._service.destroy()


class ServiceProxy:
    """rospy.ServiceProxy: call it with a request, its fields positionally or by keyword."""

    def __init__(
        self, name: str, service_class: Any, persistent: bool = False, headers: Any = None
    ) -> None:
        self._srv = get_service_type(service_class)
        self._client = RUNTIME.require_node().create_client(self._srv, name)
        self.resolved_name = self._client.srv_name

    def __call__(self, *args: Any, **kwds: Any) -> Any:
        return self.call(*args, **kwds)

    def call(self, *args: Any, **kwds: Any) -> Any:
        req_cls = self._srv.Request
        if len(args) == 1 and not kwds and isinstance(args[0], req_cls.cls):
            request = args[0]
        elif args:
            request = req_cls(**dict(zip(req_cls.fields, args, strict=True)))
        else:
            request = req_cls(**kwds)
        try:
            return self._client.call(request)
        except ServiceError as err:
            raise ServiceException(
                f"service [{self.resolved_name}] responded with an error: {err}"
            ) from err

    def wait_for_service(self, timeout: Any = None) -> None:
        wait_for_service(self.resolved_name, timeout)

    def close(self) -> None:
        self._client.destroy()


def wait_for_service(service: str, timeout: Any = None) -> None:
    """Wait (wall seconds) until ``service`` is served; ROSException on timeout."""
    node = RUNTIME.require_node()
    full = node.resolve_topic_name(service)
    deadline = None if timeout is None else _time.monotonic() + _seconds(timeout)
    ctx = node.context
    transports = [t for t in ctx.transports if isinstance(t, ServiceTransport)]
    while not (full in ctx.graph.services or any(t.service_available(full) for t in transports)):
        RUNTIME.hold_during_hooks()
        if RUNTIME.shutdown_flag:
            raise ROSInterruptException("rospy shutdown")
        if deadline is not None and _time.monotonic() >= deadline:
            raise ROSException(f"timeout exceeded while waiting for service {full}")
        _time.sleep(0.01)
