"""``roverlab service``: list, type, call — the rosservice / ros2 service habits."""

from __future__ import annotations

import time
from typing import Annotated

import typer

from roverlab.cli.common import Connection, network_options
from roverlab.core.errors import GraphError, ServiceError
from roverlab.core.graph import resolve_name
from roverlab.core.transport.zenoh import GraphEntity
from roverlab.msgs import get_service_type, parse_yaml_message, to_yaml

app = typer.Typer(
    help="Inspect and call services (rosservice / ros2 service).", no_args_is_help=True
)


def _services(ents: list[GraphEntity]) -> dict[str, set[str]]:
    out: dict[str, set[str]] = {}
    for e in ents:
        if e.kind == "service":
            out.setdefault(e.topic, set()).add(e.typename)
    return out


@app.command("list")
def list_services(
    ctx: typer.Context,
    show_types: Annotated[
        bool, typer.Option("--show-types", "-t", help="Also print each service's type.")
    ] = False,
) -> None:
    """List the services of every running roverlab process."""
    with Connection(network_options(ctx)) as conn:
        services = _services(conn.graph())
    for name in sorted(services):
        typer.echo(f"{name} [{', '.join(sorted(services[name]))}]" if show_types else name)


def _service_type(conn: Connection, name: str, wait_s: float) -> str:
    deadline = time.monotonic() + wait_s
    while True:
        types = _services(conn.graph(timeout_s=0.5)).get(name)
        if types:
            if len(types) > 1:
                raise GraphError(
                    f"service '{name}' is served with several types: {', '.join(sorted(types))}"
                )
            return next(iter(types))
        if time.monotonic() >= deadline:
            raise GraphError(f"service '{name}' is not available (waited {wait_s:g} s)")
        time.sleep(0.1)


@app.command("type")
def service_type(
    ctx: typer.Context,
    name: Annotated[str, typer.Argument(help="Service name, e.g. /static_map.")],
) -> None:
    """Print the type of a service (pkg/srv/Name)."""
    full = resolve_name(name)
    with Connection(network_options(ctx)) as conn:
        typer.echo(_service_type(conn, full, 1.0))


@app.command("call")
def call(
    ctx: typer.Context,
    name: Annotated[str, typer.Argument(help="Service name, e.g. /add_two_ints.")],
    srv_type: Annotated[
        str | None,
        typer.Argument(
            metavar="[TYPE]",
            help="Service type, e.g. std_srvs/srv/Empty or std_srvs/Empty; looked up from "
            "the server when left out.",
        ),
    ] = None,
    values: Annotated[
        str, typer.Argument(help='Request fields as YAML, e.g. "{a: 1, b: 2}".')
    ] = "{}",
    timeout: Annotated[
        float,
        typer.Option("--timeout", help="Seconds to wait for the service and for its answer."),
    ] = 5.0,
) -> None:
    """Call a service once and print the response as YAML (exit 2 on any error)."""
    full = resolve_name(name)
    if srv_type is not None and srv_type.lstrip().startswith("{"):
        values, srv_type = srv_type, None  # `service call NAME "{yaml}"`
    srv = get_service_type(srv_type) if srv_type is not None else None
    request = parse_yaml_message(srv.Request, values) if srv is not None else None
    with Connection(network_options(ctx)) as conn:
        if srv is None:
            srv = get_service_type(_service_type(conn, full, timeout))
            request = parse_yaml_message(srv.Request, values)
        client = conn.context.create_node("roverlab_service_call").create_client(srv, full)
        if not client.wait_for_service(timeout_sec=timeout):
            raise GraphError(f"service '{full}' is not available (waited {timeout:g} s)")
        conn.context.spin_in_thread()
        typer.echo(f"requester: making request: {srv.Request.typename}")
        text = to_yaml(request).strip()
        if text and text != "{}":
            typer.echo("  " + text.replace("\n", "\n  "))
        response = client.call(request, timeout_sec=timeout)
        if response is None:
            raise ServiceError(f"service '{full}' did not answer within {timeout:g} s")
        typer.echo("\nresponse:")
        typer.echo(to_yaml(response).rstrip())
