"""The graph and parameters of a Zenoh network, read from outside a context: the
liveliness keys of nodes, publishers, subscriptions, services and clients
(``rl/D/g/<zid>/<kind>/<node>/...``, see :mod:`.zenoh`), and a node's parameter service.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import zenoh

from roverlab.core.errors import ParameterError

__all__ = [
    "GraphEntity",
    "decode_name",
    "encode_name",
    "parse_graph_key",
    "query_graph",
    "query_parameters",
]


def encode_name(name: str) -> str:
    """A ROS name as one Zenoh key chunk ('/' -> '%')."""
    return name.replace("/", "%")


def decode_name(chunk: str) -> str:
    return chunk.replace("%", "/")


@dataclass(frozen=True)
class GraphEntity:
    """One liveliness token of the graph, decoded."""

    zid: str
    kind: str  # "node", "publisher", "subscription", "service" or "client"
    node: str
    topic: str = ""  # the topic, or the service's name
    typename: str = ""
    latched: bool = False


_ENTITY_KINDS = {"p": "publisher", "s": "subscription", "v": "service", "c": "client"}


def parse_graph_key(key: str) -> GraphEntity | None:
    parts = key.split("/")
    # rl / D / g / zid / kind / node [/ topic / type [/ durability]]
    if len(parts) < 6 or parts[0] != "rl" or parts[2] != "g":
        return None
    zid, kind, node = parts[3], parts[4], decode_name(parts[5])
    if kind == "n":
        return GraphEntity(zid, "node", node)
    if kind in _ENTITY_KINDS and len(parts) >= 8:
        return GraphEntity(
            zid,
            _ENTITY_KINDS[kind],
            node,
            decode_name(parts[6]),
            decode_name(parts[7]),
            latched=len(parts) > 8 and parts[8] == "latched",
        )
    return None


def query_graph(
    session: zenoh.Session, domain: int = 0, timeout_s: float = 1.0
) -> list[GraphEntity]:
    """Every node, publisher and subscription visible on the network."""
    out: list[GraphEntity] = []
    for reply in session.liveliness().get(f"rl/{domain}/g/**", timeout=timeout_s):
        if reply.ok is not None:
            ent = parse_graph_key(str(reply.ok.key_expr))
            if ent is not None:
                out.append(ent)
    return out


def query_parameters(
    session: zenoh.Session,
    node: str,
    request: dict[str, Any],
    domain: int = 0,
    timeout_s: float = 3.0,
) -> dict[str, Any]:
    """Send a parameter request (``{"op": "get"|"set"|"list"|"dump", ...}``) to a node."""
    fq = node if node.startswith("/") else "/" + node
    answers: list[dict[str, Any]] = []
    for reply in session.get(
        f"rl/{domain}/p/{encode_name(fq)}", payload=json.dumps(request), timeout=timeout_s
    ):
        if reply.ok is not None:
            answers.append(json.loads(reply.ok.payload.to_bytes()))
    if not answers:
        raise ParameterError(f"node '{fq}' not found (is it running?)")
    return answers[0]
