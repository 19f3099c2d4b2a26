"""``roverlab node`` and ``roverlab param``: the running system's nodes and parameters."""

from __future__ import annotations

from typing import Annotated, Any

import typer
import yaml

from roverlab.cli.common import Connection, network_options
from roverlab.core.errors import ParameterError
from roverlab.core.parameters import flatten_parameters
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.core.transport.zenoh import query_parameters

node_app = typer.Typer(help="Inspect nodes (rosnode / ros2 node).", no_args_is_help=True)
param_app = typer.Typer(
    help="Get, set and dump node parameters (rosparam / ros2 param).", no_args_is_help=True
)


@node_app.command("list")
def node_list(ctx: typer.Context) -> None:
    """List the nodes of every running roverlab process."""
    with Connection(network_options(ctx)) as conn:
        names = sorted({e.node for e in conn.graph() if e.kind == "node"})
    for name in names:
        typer.echo(name)


@node_app.command("info")
def node_info(
    ctx: typer.Context, node: Annotated[str, typer.Argument(help="Node name, e.g. /amcl.")]
) -> None:
    """Print a node's publishers and subscriptions."""
    fq = node if node.startswith("/") else "/" + node
    with Connection(network_options(ctx)) as conn:
        ents = [e for e in conn.graph() if e.node == fq]
    if not ents:
        raise ParameterError(f"node '{fq}' not found (is it running?)")
    typer.echo(fq)
    for kind, title in (("subscription", "Subscribers"), ("publisher", "Publishers")):
        typer.echo(f"  {title}:")
        for e in sorted((e for e in ents if e.kind == kind), key=lambda e: e.topic):
            typer.echo(f"    {e.topic}: {e.typename}")


def _ask(ctx: typer.Context, node: str, request: dict[str, Any]) -> dict[str, Any]:
    with Connection(network_options(ctx)) as conn:
        if conn.ros1 is not None:
            answer = _ask_master(conn.ros1, node, request)
        else:
            answer = query_parameters(conn.transport.session, node, request, conn.transport.domain)
    if "error" in answer:
        raise ParameterError(str(answer["error"]))
    return answer


def _ask_master(ros1: Ros1Transport, node: str, request: dict[str, Any]) -> dict[str, Any]:
    """The same questions, asked of a ROS 1 master's parameter server: a node's
    parameters are the names under ``/node/`` (``a.b`` is ``/node/a/b``)."""
    fq = node if node.startswith("/") else "/" + node
    tree = ros1.get_param(fq, {})
    flat = flatten_parameters(tree) if isinstance(tree, dict) else {}
    op = request.get("op")
    if op == "list":
        return {"names": sorted(flat)}
    if op == "dump":
        return {"parameters": dict(sorted(flat.items()))}
    name = str(request.get("name"))
    key = f"{fq}/{name.replace('.', '/')}"
    if op == "get":
        try:
            return {"name": name, "value": ros1.get_param(key)}
        except KeyError:
            return {"error": f"parameter '{key}' is not set on {ros1.master_uri}"}
    if op == "set":
        ros1.set_param(key, request.get("value"))
        return {"ok": True}
    return {"error": f"unknown parameter operation {op!r}"}


@param_app.command("list")
def param_list(ctx: typer.Context, node: Annotated[str, typer.Argument(help="Node name.")]) -> None:
    """List a node's parameter names."""
    for name in _ask(ctx, node, {"op": "list"})["names"]:
        typer.echo(f"  {name}")


@param_app.command("get")
def param_get(
    ctx: typer.Context,
    node: Annotated[str, typer.Argument(help="Node name.")],
    name: Annotated[str, typer.Argument(help="Parameter name.")],
) -> None:
    """Print a parameter's value."""
    value = _ask(ctx, node, {"op": "get", "name": name})["value"]
    typer.echo(yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("\n..."))


@param_app.command("set")
def param_set(
    ctx: typer.Context,
    node: Annotated[str, typer.Argument(help="Node name.")],
    name: Annotated[str, typer.Argument(help="Parameter name.")],
    value: Annotated[str, typer.Argument(help="New value, as YAML (0.5, true, [1, 2], text).")],
) -> None:
    """Set a parameter (its type must match the declared one)."""
    try:
        parsed = yaml.safe_load(value)
    except yaml.YAMLError as err:
        raise ParameterError(f"value {value!r} is not valid YAML") from err
    answer = _ask(ctx, node, {"op": "set", "name": name, "value": parsed})
    if not answer.get("ok", False):
        raise ParameterError(f"setting parameter failed: {answer.get('reason') or 'rejected'}")
    typer.echo("Set parameter successful")


@param_app.command("dump")
def param_dump(ctx: typer.Context, node: Annotated[str, typer.Argument(help="Node name.")]) -> None:
    """Print a node's parameters as a ROS 2 parameter YAML file."""
    params = _ask(ctx, node, {"op": "dump"})["parameters"]
    fq = node if node.startswith("/") else "/" + node
    typer.echo(yaml.safe_dump({fq: {"ros__parameters": params}}, sort_keys=False).rstrip())
