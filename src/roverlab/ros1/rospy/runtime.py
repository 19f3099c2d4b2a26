"""The state behind rospy's global API: one node per process, its context, shutdown.

rospy's API is global (one node per process, module-level functions), so this module
keeps one :class:`Runtime`. ``roverlab run`` configures it with a context joined to the
running system before the script starts; a script run some other way gets a wall-clock
context joined to the local daemon at ``init_node``.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import yaml

from roverlab.core import Context, Node
from roverlab.core.executor import ClockMode
from roverlab.core.graph import resolve_name
from roverlab.core.transport.daemon import connect_context
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.core.transport.zenoh import ZenohTransport, query_parameters
from roverlab.ros1.rospy import rostime
from roverlab.ros1.rospy.exceptions import ROSException, ROSInitException, ROSInterruptException

__all__ = ["LAUNCH_PARAMS_ENV", "RUNTIME", "CommandLine", "Runtime", "parse_command_line"]

LAUNCH_PARAMS_ENV = "ROVERLAB_LAUNCH_PARAMS"
"""Names the YAML file (``{private: {...}, global: {...}}``) in which ``roverlab launch``
gives a script node the parameters roslaunch would set on the parameter server."""

_SPECIAL = ("__name", "__ns", "__log", "__ip", "__hostname", "__master")


@dataclass
class CommandLine:
    """What rospy reads from ``sys.argv``: remaps, private params, special keys."""

    remaps: dict[str, str] = field(default_factory=dict)
    params: dict[str, Any] = field(default_factory=dict)
    special: dict[str, str] = field(default_factory=dict)
    plain: list[str] = field(default_factory=list)


def parse_command_line(argv: list[str]) -> CommandLine:
    """Split ``name:=value`` arguments as rospy does: ``_p:=v`` private parameters (YAML
    values), ``__name:=n`` / ``__ns:=ns`` special keys, ``from:=to`` remaps; the rest is
    what ``rospy.myargv()`` returns."""
    out = CommandLine()
    for arg in argv:
        if ":=" not in arg:
            out.plain.append(arg)
            continue
        key, value = arg.split(":=", 1)
        if key in _SPECIAL:
            out.special[key] = value
        elif key.startswith("_") and not key.startswith("__"):
            try:
                out.params[key[1:]] = yaml.safe_load(value) if value else ""
            except yaml.YAMLError:
                out.params[key[1:]] = value
        elif key and not key.startswith("__"):
            out.remaps[key] = value
    return out


class Runtime:
    """The rospy layer's process-wide state."""

    def __init__(self) -> None:
        self._clear()

    def _clear(self) -> None:
        self.context: Context | None = None
        self.owns_context = False
        self.node: Node | None = None
        self.command_line = CommandLine()
        self.shutdown_flag = False
        self.in_shutdown = False
        self.shutdown_reason = ""
        self.hooks: list[Callable[..., Any]] = []
        self.pending: list[Callable[[Node], None]] = []
        self.params: dict[str, Any] = {}  # global parameters set in this process
        self.private: dict[str, Any] = {}
        self.lock = threading.RLock()
        self._signals: dict[int, Any] = {}
        self._interrupts = 0
        self._shutdown_request = threading.Event()
        self._hooks_done = threading.Event()
        self._hooks_thread: int | None = None
        self._watcher: threading.Thread | None = None

    # ----------------------------------------------------------------- set-up
    def configure(self, context: Context, argv: list[str]) -> None:
        """Use ``context`` (spinning or not) and the script's ``argv`` (``roverlab run``)."""
        self.context = context
        self.command_line = parse_command_line(argv)

    def require_node(self) -> Node:
        if self.node is None:
            raise ROSInitException("rospy.init_node() has not been called")
        return self.node

    def init_node(
        self, name: str, *, anonymous: bool, argv: list[str] | None, disable_signals: bool
    ) -> Node:
        with self.lock:
            if self.node is not None:
                raise ROSException(
                    "rospy.init_node() has already been called with different arguments"
                )
            if argv is not None:
                self.command_line = parse_command_line(argv)
            cl = self.command_line
            base = cl.special.get("__name", name.strip("/").split("/")[-1])
            if anonymous:
                base = f"{base}_{os.getpid()}_{int(time.time() * 1000)}"
            if self.context is None:
                self.context = _default_context()
                self.owns_context = True
            context = self.context
            node = context.create_node(
                base, namespace=cl.special.get("__ns", "/"), remappings=cl.remaps
            )
            self.node = node
            launched = _launch_params()
            self.params = {**launched.get("global", {}), **self.params}
            self.private = {**launched.get("private", {}), **cl.params}  # argv wins, as in ROS
            for name_, value in self.private.items():
                self._mirror(name_, value)
            rostime.set_clock(context.executor.clock_now_ns)
            for bind in self.pending:
                bind(node)
            self.pending.clear()
            if context.executor._thread_id is None:
                context.spin_in_thread()
            if not disable_signals and threading.current_thread() is threading.main_thread():
                self.install_signals()
            return node

    def _mirror(self, name: str, value: Any) -> None:
        """Show a private parameter as the node's parameter (roverlab param get)."""
        node = self.node
        if node is None:
            return
        pname = name.replace("/", ".")
        try:
            if node.has_parameter(pname):
                node.set_parameter(pname, value)
            else:
                node.declare_parameter(pname, value)
        except Exception:  # a value ROS 2 parameters cannot hold (a dict, ...): rospy-only
            pass

    # ----------------------------------------------------------------- time
    def now_ns(self) -> int:
        return self.require_context().executor.clock_now_ns()

    def require_context(self) -> Context:
        if self.context is None:
            raise ROSInitException("time is not initialized. Have you called init_node()?")
        return self.context

    def uses_wall_clock(self) -> bool:
        return self.require_context().clock_mode in (ClockMode.WALL,)

    def sleep_until(self, t_ns: int) -> None:
        """Sleep until the ROS clock reads ``t_ns``; a shutdown interrupts the sleep."""
        context = self.require_context()
        ex = context.executor
        start = ex.clock_now_ns()
        while True:
            self.hold_during_hooks()
            if self.shutdown_flag:
                raise ROSInterruptException("ROS shutdown request")
            now = ex.clock_now_ns()
            if now >= t_ns:
                return
            if now < start - 1_000_000_000:
                raise ROSInterruptException("ROS time moved backwards")
            wait_s = (t_ns - now) / 1e9
            if context.clock_mode is ClockMode.WALL:
                time.sleep(min(wait_s, 0.01))
            elif context.clock_mode is ClockMode.PACED:
                # the live paced clock runs at ex.rate x wall time: a fixed 2 ms poll would be
                # a whole 10 Hz period at 50x
                time.sleep(min(wait_s / ex.rate, 0.01))
            else:
                time.sleep(0.002)

    # ----------------------------------------------------------------- shutdown
    def signal_shutdown(self, reason: str) -> None:
        """Run the shutdown hooks (``rospy.on_shutdown``), then mark the node shut down.

        As in rospy, hooks run while ``is_shutdown()`` is still False, so they may sleep
        and publish (slam.py cancels its goal, waits, then stops the robot).
        """
        with self.lock:
            if self.in_shutdown:
                return
            self.in_shutdown = True
            self.shutdown_reason = reason
            self._hooks_thread = threading.get_ident()
        for hook in list(self.hooks):
            try:
                try:
                    hook(reason)
                except TypeError:
                    hook()
            except Exception as err:  # a broken hook must not stop the others
                print(f"[ERROR] shutdown hook raised {type(err).__name__}: {err}", file=sys.stderr)
        self.shutdown_flag = True
        self._hooks_done.set()

    def hold_during_hooks(self) -> None:
        """A blocking rospy call of another thread waits here while the shutdown hooks run
        (rospy runs them in the signal handler, which suspends the main thread: the same
        order, without running user code inside a signal handler)."""
        busy = self.in_shutdown and not self.shutdown_flag
        if busy and threading.get_ident() != self._hooks_thread:
            self._hooks_done.wait()

    def wait_for_hooks(self, timeout_s: float) -> None:
        if self.in_shutdown:
            self._hooks_done.wait(timeout_s)

    def install_signals(self) -> None:
        """SIGINT, SIGTERM and SIGHUP shut the node down; a second SIGINT interrupts.

        The handler only raises a flag: a watcher thread runs the hooks, so a hook that
        sleeps or publishes never runs inside code the signal interrupted (which may hold a
        lock the executor needs to advance the clock that very sleep waits for).
        """

        def handler(signum: int, _frame: Any) -> None:
            self._interrupts += 1
            if self._interrupts > 1 and signum == signal.SIGINT:
                raise KeyboardInterrupt
            self.shutdown_reason = self.shutdown_reason or f"signal-{signum}"
            self._shutdown_request.set()

        def watch() -> None:
            self._shutdown_request.wait()
            self.signal_shutdown(self.shutdown_reason or "signal")

        if self._watcher is None:
            self._watcher = threading.Thread(target=watch, name="rospy-shutdown", daemon=True)
            self._watcher.start()
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            self._signals[sig] = signal.signal(sig, handler)

    def restore_signals(self) -> None:
        for sig, old in self._signals.items():
            signal.signal(sig, old)
        self._signals.clear()

    def flush(self, timeout_s: float = 1.0) -> None:
        """Let what the script published leave (the executor's queue drained)."""
        context = self.context
        if context is None or context.executor._thread_id is None:
            return
        done = threading.Event()
        context.executor.call_soon_threadsafe(done.set)
        done.wait(timeout_s)
        if context.transports:
            time.sleep(0.1)

    def reset(self) -> None:
        """Forget everything (tests; ``roverlab run`` at exit)."""
        self.restore_signals()
        if self.owns_context and self.context is not None:
            self.context.shutdown()
        rostime.set_clock(None)
        self._clear()

    # ----------------------------------------------------------------- parameters
    def resolve(self, name: str) -> str:
        node = self.node
        if name.startswith("~"):
            if node is None:
                raise ROSInitException("private names need rospy.init_node() first")
            return node.get_fully_qualified_name() + "/" + name[1:].lstrip("/")
        ns = node.get_namespace() if node is not None else "/"
        return resolve_name(name, ns) if name != "/" else "/"

    def get_param(self, name: str) -> Any:
        """The value of a parameter (a namespace as a dictionary, as rospy), or KeyError."""
        if name.startswith("~"):
            return _lookup(self.private, name[1:].strip("/"), name)
        full = self.resolve(name)
        try:
            return _lookup(self.params, full.rstrip("/") or "/", name)
        except KeyError:
            pass
        own = self.node.get_fully_qualified_name() + "/" if self.node is not None else None
        if own is not None and full.startswith(own):
            try:
                return _lookup(self.private, full[len(own) :].strip("/"), name)
            except KeyError:
                pass
        return self._remote_param(full)

    def _remote_param(self, full: str) -> Any:
        """``/node/param`` (or ``/node/group/param``) read from a running node."""
        parts = full.strip("/").split("/")
        context = self.context
        for transport in context.transports if context is not None else []:
            if isinstance(transport, Ros1Transport):  # a ROS 1 graph: its parameter server
                try:
                    return transport.get_param(full)
                except KeyError:
                    pass
        for cut in range(len(parts) - 1, 0, -1):
            node_name = "/" + "/".join(parts[:cut])
            pname = ".".join(parts[cut:])
            if context is not None and node_name in context.nodes:
                local = context.nodes[node_name]
                if local.has_parameter(pname):
                    return local.get_parameter_value(pname)
                continue
            for transport in context.transports if context is not None else []:
                if isinstance(transport, ZenohTransport):
                    try:
                        answer = query_parameters(
                            transport.session,
                            node_name,
                            {"op": "get", "name": pname},
                            transport.domain,
                            timeout_s=1.0,
                        )
                    except Exception:
                        continue
                    if "value" in answer:
                        return answer["value"]
        raise KeyError(full)

    def set_param(self, name: str, value: Any) -> None:
        if name.startswith("~"):
            key = name[1:].lstrip("/")
            self.private[key] = value
            self._mirror(key, value)
        else:
            full = self.resolve(name)
            self.params[full] = value
            for transport in self.context.transports if self.context is not None else []:
                if isinstance(transport, Ros1Transport):  # rospy sets it on the master
                    transport.set_param(full, value)


def _lookup(store: dict[str, Any], key: str, name: str) -> Any:
    """``store[key]``, or the parameters under ``key/`` as a nested dictionary (rospy's
    answer for a namespace), else KeyError(name)."""
    if key in store:
        return store[key]
    prefix = "" if key in ("", "/") else key + "/"
    found: dict[str, Any] = {}
    for k, v in store.items():
        if k.startswith(prefix) and k != prefix:
            *path, leaf = k[len(prefix) :].strip("/").split("/")
            where = found
            for part in path:
                nxt = where.setdefault(part, {})
                if not isinstance(nxt, dict):
                    break
                where = nxt
            else:
                where[leaf] = v
    if not found:
        raise KeyError(name)
    return found


def _launch_params() -> dict[str, Any]:
    """The parameters ``roverlab launch`` gave this script (:data:`LAUNCH_PARAMS_ENV`)."""
    path = os.environ.get(LAUNCH_PARAMS_ENV)
    if not path:
        return {}
    try:
        with open(path, encoding="utf-8") as f:
            data = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as err:
        raise ROSInitException(f"{LAUNCH_PARAMS_ENV}={path}: cannot read: {err}") from err
    return data if isinstance(data, dict) else {}


def _default_context() -> Context:
    context = Context(clock="wall", publish_clock=False)
    connect_context(context)
    return context


RUNTIME = Runtime()
