"""A roverlab node's declared parameters on the master's parameter server, as a rospy or
roscpp node's private parameters are there (``rosparam get /amcl/min_particles``).

As in ROS 1, a value already on the master when the node starts (``rosparam set
/amcl/min_particles 200`` before it, or a previous run's) wins over the node's default;
a launch's or the command line's override wins over both. The node's namespace is read
once, when it declares its first parameter (one ``getParam``; a value of the wrong type
is one warning line and the default stays). A parameter declared before the ROS 1
transport came (``roverlab sim`` builds its nodes first) takes the master's value through
``set_parameter``, so the node's set-parameters callbacks see it.

Each declared parameter ``a.b`` of node ``/amcl`` is then set as ``/amcl/a/b`` (by one worker
thread, so a slow master never holds up a node's constructor further), and the node
subscribes to its namespace (``subscribeParam``) with its own slave URI: a ``rosparam set``
of one of them reaches the node as ``paramUpdate`` and is applied with ``set_parameter``
on the executor thread (validated and passed to the node's set-parameter callbacks, as
``roverlab param set`` does; a refused value is one warning line).
"""

from __future__ import annotations

import logging
import queue
import threading
from typing import TYPE_CHECKING, Any

from roverlab.core.transport.ros1.errors import MasterError
from roverlab.core.transport.ros1.xmlrpc import call
from roverlab.errors import RoverlabError

if TYPE_CHECKING:
    from roverlab.core.context import Context
    from roverlab.core.node import Node
    from roverlab.core.parameters import Parameter

__all__ = ["ParamMirror"]

_log = logging.getLogger("roverlab.ros1")


def _key(node: str, name: str) -> str:
    return f"{node.rstrip('/')}/{name.replace('.', '/')}"


_MISSING: Any = object()


def _lookup(tree: dict[str, Any] | None, name: str) -> Any:
    """The value of ``a.b`` in a namespace tree (``{"a": {"b": 1}}``), or _MISSING."""
    node: Any = tree
    for part in name.split("."):
        if not isinstance(node, dict) or part not in node:
            return _MISSING
        node = node[part]
    return node


class ParamMirror:
    def __init__(self, master_uri: str) -> None:
        self.master_uri = master_uri
        self._jobs: queue.SimpleQueue[tuple[str, tuple[Any, ...]] | None] = queue.SimpleQueue()
        self._subscribed: set[str] = set()
        self._initial: dict[str, dict[str, Any]] = {}  # node -> its namespace at start
        self._thread = threading.Thread(target=self._work, daemon=True, name="ros1-params")
        self._thread.start()

    def declared(
        self, node: Node, param: Parameter, slave_uri: str, *, running: bool = False
    ) -> None:
        """``param`` was declared on ``node`` (whose slave API is at ``slave_uri``):
        it takes the master's value if there is one and no override, then goes there.
        ``running``: the node declared it before the transport came (set through
        ``set_parameter`` instead of at declaration)."""
        fq = node.get_fully_qualified_name()
        if fq not in self._subscribed:
            self._subscribed.add(fq)
            self._initial[fq] = self._read_namespace(fq)
            self._jobs.put(("subscribeParam", (fq, slave_uri, fq.rstrip("/") + "/")))
        value = _lookup(self._initial.get(fq), param.name)
        if value is not _MISSING and not node.has_parameter_override(param.name):
            self._adopt(node, param, value, running)
        if param.value is not None:  # declared without a default and not overridden
            self._jobs.put(("setParam", (fq, _key(fq, param.name), param.value)))

    def _read_namespace(self, fq: str) -> dict[str, Any]:
        """The node's private parameters on the master now ({} if none or no answer)."""
        try:
            tree = call(self.master_uri, "getParam", fq, fq, timeout_s=3.0)
        except (MasterError, OverflowError, TypeError):
            return {}  # nothing under the node's name (the master says "not set")
        return tree if isinstance(tree, dict) else {}

    def _adopt(self, node: Node, param: Parameter, value: Any, running: bool) -> None:
        where = f"the master's {_key(node.get_fully_qualified_name(), param.name)}"
        try:
            if running:
                result = node.set_parameter(param.name, value)
                if not result.successful:
                    _log.warning("%s = %r refused: %s", where, value, result.reason)
            else:
                param.value = param.validate(value)
        except (RoverlabError, ValueError, TypeError) as err:
            _log.warning("%s = %r not used (%s); keeping %r", where, value, err, param.value)

    def forget(self, node: str, slave_uri: str) -> None:
        self._initial.pop(node, None)
        if node in self._subscribed:
            self._subscribed.discard(node)
            self._jobs.put(("unsubscribeParam", (node, slave_uri, node.rstrip("/") + "/")))

    def update(self, context: Context | None, node: str, key: str, value: Any) -> None:
        """The master's ``paramUpdate`` for ``key`` to ``node`` (a slave thread): set the
        declared parameter it names, on the executor thread."""
        target = context.nodes.get(node) if context is not None else None
        prefix = node.rstrip("/") + "/"
        if target is None or not key.startswith(prefix) or context is None:
            return
        name = key[len(prefix) :].rstrip("/").replace("/", ".")

        def apply() -> None:
            if not target.has_parameter(name) or target.get_parameter_value(name) == value:
                return  # not ours, or our own setParam coming back
            try:
                result = target.set_parameter(name, value)
            except (RoverlabError, ValueError, TypeError) as err:
                _log.warning("%s: rosparam set %s refused: %s", node, key, err)
                return
            if not result.successful:
                _log.warning("%s: rosparam set %s refused: %s", node, key, result.reason)

        context.executor.call_soon_threadsafe(apply)

    def _work(self) -> None:
        while (job := self._jobs.get()) is not None:
            method, args = job
            try:
                call(self.master_uri, method, *args, timeout_s=5.0)
            except (MasterError, OverflowError, TypeError) as err:
                _log.debug("%s%s on %s: %s", method, args[1:2], self.master_uri, err)

    def close(self) -> None:
        self._jobs.put(None)
        self._thread.join(timeout=5.0)
