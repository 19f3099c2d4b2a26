"""``roverlab action``: list, info, send_goal — the ros2 action habits, on ROS 1 actionlib.

An action ``NAME`` is the five topics ``NAME/goal``, ``cancel``, ``status``, ``feedback``
and ``result``; a server subscribes to ``NAME/goal``, a client publishes it.
"""

from __future__ import annotations

from typing import Annotated, Any

import typer

from roverlab.actionlib import GoalStatus, SimpleActionClient, status_name
from roverlab.cli.common import Connection, network_options
from roverlab.core.errors import GraphError
from roverlab.core.graph import resolve_name
from roverlab.core.transport.zenoh import GraphEntity
from roverlab.msgs import UnknownTypeError, get_action_type, parse_yaml_message, to_yaml

app = typer.Typer(
    help="Inspect actions and send goals (ros2 action, on ROS 1 actionlib).",
    no_args_is_help=True,
)

_GOAL_SUFFIX = "ActionGoal"


def _actions(ents: list[GraphEntity]) -> dict[str, str]:
    """Action name -> ``pkg/action/Name`` for every ``NAME/goal`` of an ActionGoal type
    that has a ``NAME/status`` beside it."""
    topics = {e.topic for e in ents}
    out: dict[str, str] = {}
    for e in ents:
        if (
            e.kind in ("publisher", "subscription")
            and e.topic.endswith("/goal")
            and e.typename.endswith(_GOAL_SUFFIX)
        ):
            name = e.topic[: -len("/goal")]
            if f"{name}/status" in topics:
                pkg, _, short = e.typename.split("/")
                out[name] = f"{pkg}/action/{short[: -len(_GOAL_SUFFIX)]}"
    return out


@app.command("list")
def list_actions(
    ctx: typer.Context,
    show_types: Annotated[
        bool, typer.Option("--show-types", "-t", help="Also print each action's type.")
    ] = False,
) -> None:
    """List the actions of every running roverlab process."""
    with Connection(network_options(ctx)) as conn:
        actions = _actions(conn.graph())
    for name in sorted(actions):
        typer.echo(f"{name} [{actions[name]}]" if show_types else name)


@app.command("info")
def info(
    ctx: typer.Context,
    name: Annotated[str, typer.Argument(help="Action name, e.g. /move_base.")],
    show_types: Annotated[
        bool, typer.Option("--show-types", "-t", help="Also print the action's type.")
    ] = False,
) -> None:
    """Print an action's clients and servers."""
    full = resolve_name(name)
    with Connection(network_options(ctx)) as conn:
        ents = conn.graph()
    actions = _actions(ents)
    if full not in actions:
        raise GraphError(f"unknown action '{full}' (no process has its goal and status topics)")
    goal = [e for e in ents if e.topic == f"{full}/goal"]
    clients = sorted({e.node for e in goal if e.kind == "publisher"})
    servers = sorted({e.node for e in goal if e.kind == "subscription"})
    typer.echo(f"Action: {full}" + (f" [{actions[full]}]" if show_types else ""))
    for title, nodes in (("Action clients", clients), ("Action servers", servers)):
        typer.echo(f"{title}: {len(nodes)}")
        for n in nodes:
            typer.echo(f"    {n}")


def _indent(text: str) -> str:
    return "    " + text.strip().replace("\n", "\n    ")


@app.command("send_goal")
def send_goal(
    ctx: typer.Context,
    name: Annotated[str, typer.Argument(help="Action name, e.g. /move_base.")],
    action_type: Annotated[
        str,
        typer.Argument(
            help="Action type: move_base_msgs/action/MoveBase, move_base_msgs/MoveBaseAction "
            "or move_base_msgs/MoveBase."
        ),
    ],
    values: Annotated[
        str,
        typer.Argument(
            help='Goal fields as YAML, e.g. "{target_pose: {header: {frame_id: map}}}".'
        ),
    ] = "{}",
    feedback: Annotated[
        bool, typer.Option("--feedback", "-f", help="Print the feedback messages.")
    ] = False,
    timeout: Annotated[
        float, typer.Option("--timeout", help="Seconds to wait for the action server.")
    ] = 5.0,
) -> None:
    """Send a goal, wait for the result and print the final state (Ctrl-C cancels the goal).

    Exit status: 0 when the goal SUCCEEDED, 1 when it ended otherwise, 2 on an error.
    """
    full = resolve_name(name)
    try:
        spec = get_action_type(action_type)
    except UnknownTypeError as err:
        raise UnknownTypeError(f"{err} (known: see `roverlab action list -t`)") from None
    goal = parse_yaml_message(spec.Goal, values)  # validate before touching the network
    with Connection(network_options(ctx)) as conn:
        client = SimpleActionClient(
            conn.context.create_node("roverlab_action_send_goal"), full, spec
        )
        conn.context.spin_in_thread()
        typer.echo("Waiting for an action server to become available...")
        if not client.wait_for_server(timeout):
            raise GraphError(f"no action server of '{full}' within {timeout:g} s")
        typer.echo("Sending goal:")
        typer.echo(_indent(to_yaml(goal)))

        def on_feedback(msg: Any) -> None:
            if feedback:
                typer.echo("\nFeedback:\n" + _indent(to_yaml(msg)))

        client.send_goal(goal, feedback_cb=on_feedback)
        goal_id = client.gh.goal_id if client.gh is not None else ""
        typer.echo(f"\nGoal sent with ID: {goal_id}")
        try:
            client.wait_for_result(None)
        except KeyboardInterrupt:
            typer.echo("\nCanceling goal...")
            client.cancel_goal()
            if not client.wait_for_result(5.0):
                typer.echo("The goal did not end within 5 s of the cancel request.", err=True)
        state = client.get_state()
        result = client.get_result()
        if result is not None:
            typer.echo("\nResult:\n" + _indent(to_yaml(result)))
        text = client.get_goal_status_text()
        typer.echo(
            f"\nGoal finished with status: {status_name(state)}" + (f" ({text})" if text else "")
        )
    if state != GoalStatus.SUCCEEDED:
        raise typer.Exit(1)
