"""Node parameters for Foxglove clients (foxglove_bridge's parameter interface).

A parameter is named as foxglove_bridge names ROS 2 parameters: the node's fully
qualified name, a dot, the parameter's name (``/amcl.max_particles``,
``/move_base.controller_frequency``). Nodes of this process are read and set directly
(a set runs on the executor thread, as a node's own callbacks do); nodes of other
processes through their Zenoh parameter service (``roverlab param``'s path).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from typing import Any, Final

import foxglove

from roverlab.core import Context, Node
from roverlab.core.errors import ParameterError
from roverlab.core.transport.zenoh import GraphEntity, ZenohTransport, query_parameters

__all__ = ["NodeParameters", "split_name", "to_foxglove"]

_REMOTE_TIMEOUT_S: Final = 2.0
_LOCAL_TIMEOUT_S: Final = 5.0


def split_name(name: str) -> tuple[str, str]:
    """``/node.param`` -> ``("/node", "param")`` (a parameter name may hold dots, a node
    name may not).

    Raises:
        ParameterError: no ``.`` separates a node from a parameter.
    """
    node, dot, param = name.partition(".")
    if not dot or not node or not param:
        raise ParameterError(f"parameter {name!r} is not '/node.parameter'")
    return (node if node.startswith("/") else "/" + node), param


def to_foxglove(name: str, value: Any) -> foxglove.Parameter:
    """A Foxglove parameter of a roverlab value (floats keep their type on the wire)."""
    if isinstance(value, float):
        return foxglove.Parameter(name, value=value, type=foxglove.ParameterType.Float64)
    if isinstance(value, list | tuple) and value and all(isinstance(v, float) for v in value):
        return foxglove.Parameter(name, value=list(value), type=foxglove.ParameterType.Float64Array)
    if isinstance(value, tuple):
        value = list(value)
    if value is None:
        return foxglove.Parameter(name)
    return foxglove.Parameter(name, value=value)


class NodeParameters:
    """Read and set the parameters of every node, here and in other processes.

    Args:
        context: the bridge's context (its nodes, and its Zenoh transport if any).
        own: the bridge's node (left out: it has no parameters worth showing).
        remote_graph: the other processes' graph, for their node names.
    """

    def __init__(
        self,
        context: Context,
        own: Node,
        remote_graph: Callable[[], list[GraphEntity]] | None = None,
    ) -> None:
        self.context = context
        self.own = own
        self.remote_graph = remote_graph

    def _zenoh(self) -> ZenohTransport | None:
        for t in self.context.transports:
            if isinstance(t, ZenohTransport):
                return t
        return None

    def _local(self, node: str) -> Node | None:
        found = self.context.nodes.get(node)
        return found if found is not self.own else None

    def node_names(self) -> list[str]:
        """Every node: this process's, then the others' (sorted, no duplicates)."""
        names = {n for n, node in list(self.context.nodes.items()) if node is not self.own}
        if self.remote_graph is not None:
            names |= {e.node for e in self.remote_graph() if e.kind == "node"}
        return sorted(names)

    def _remote(self, node: str, request: dict[str, Any]) -> dict[str, Any]:
        zenoh = self._zenoh()
        if zenoh is None:
            raise ParameterError(f"node '{node}' is not in this process (no network)")
        answer = query_parameters(
            zenoh.session, node, request, zenoh.domain, timeout_s=_REMOTE_TIMEOUT_S
        )
        if "error" in answer:
            raise ParameterError(str(answer["error"]))
        return answer

    def dump(self, node: str) -> dict[str, Any]:
        """All parameters of one node, ``name -> value``."""
        local = self._local(node)
        if local is not None:
            return {n: p.value for n, p in sorted(local.parameters.items())}
        return dict(self._remote(node, {"op": "dump"})["parameters"])

    def get(self, names: Iterable[str]) -> list[foxglove.Parameter]:
        """The named parameters (``/node.param``), or every node's when ``names`` is empty.
        Names that do not exist are left out (as foxglove_bridge does)."""
        wanted = list(names)
        out: list[foxglove.Parameter] = []
        if not wanted:
            for node in self.node_names():
                try:
                    values = self.dump(node)
                except Exception:  # a node that went away or does not answer
                    continue
                out += [to_foxglove(f"{node}.{k}", v) for k, v in values.items()]
            return out
        cache: dict[str, dict[str, Any]] = {}
        for name in wanted:
            try:
                node, param = split_name(name)
                if node not in cache:
                    cache[node] = self.dump(node)
            except Exception:
                continue
            if param in cache[node]:
                out.append(to_foxglove(name, cache[node][param]))
        return out

    def set(self, name: str, value: Any) -> None:
        """Set ``/node.param`` to ``value``.

        Raises:
            ParameterError: unknown node or parameter, wrong type, refused by the node.
        """
        node, param = split_name(name)
        local = self._local(node)
        if local is None:
            answer = self._remote(node, {"op": "set", "name": param, "value": value})
            if not answer.get("ok", False):
                raise ParameterError(f"{name}: {answer.get('reason') or 'refused'}")
            return
        done = threading.Event()
        result: list[BaseException | str | None] = []

        def apply() -> None:
            try:
                r = local.set_parameter(param, value)
                result.append(None if r.successful else (r.reason or "refused"))
            except ParameterError as err:
                result.append(err)
            done.set()

        if self.context.executor.on_executor_thread():
            apply()
        else:
            self.context.executor.call_soon_threadsafe(apply)
        if not done.wait(_LOCAL_TIMEOUT_S):
            raise ParameterError(f"{name}: node '{node}' did not answer (executor busy?)")
        if isinstance(result[0], BaseException):
            raise ParameterError(f"{name}: {result[0]}")
        if result[0] is not None:
            raise ParameterError(f"{name}: {result[0]}")
