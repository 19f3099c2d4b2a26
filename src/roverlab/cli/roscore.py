"""``roverlab roscore`` (also ``roverlab master``): a ROS 1 master and parameter server."""

from __future__ import annotations

import signal
import threading
from typing import Annotated, Any

import typer

from roverlab.core.errors import TransportError
from roverlab.core.transport.ros1.errors import MasterError
from roverlab.core.transport.ros1.master import DEFAULT_MASTER_PORT, Master
from roverlab.core.transport.ros1.peer import Ros1Peer, TopicSpec
from roverlab.core.transport.ros1.transport import ros_master_uri
from roverlab.core.transport.ros1.xmlrpc import call, split_uri
from roverlab.msgs.ros1 import ros1_definition

_LOCAL = {"127.0.0.1", "localhost", "::1"}


def ensure_master() -> Master | None:
    """As roslaunch does: with ROS_MASTER_URI naming this machine and no master answering
    there, start one (in this process; the caller stops it). None when ROS 1 is not asked
    for, or a master already answers.

    Raises:
        TransportError: the master's port is taken by something that is not a master.
    """
    uri = ros_master_uri()
    if uri is None:
        return None
    try:
        call(uri, "getUri", "/roverlab_launch", timeout_s=2.0)
        return None
    except MasterError:
        pass
    host, port = split_uri(uri)
    if host not in _LOCAL:
        return None  # another machine's master: the transport says it is not there
    try:
        master = Master(host=host if host != "localhost" else "127.0.0.1", port=port)
    except OSError as err:
        raise TransportError(f"cannot start a ROS master at {uri}: {err.strerror or err}") from None
    master.start()
    typer.echo(f"note: started a ROS master at {uri} (nothing answered there)", err=True)
    return master


def start_rosout(master_uri: str) -> Ros1Peer:
    """roscore's ``/rosout`` node: every node's log messages (``/rosout``) gathered on
    ``/rosout_agg``, relayed as the bytes came (rqt_console and ``rostopic echo
    /rosout_agg`` read them)."""
    definition, md5 = ros1_definition("rosgraph_msgs/msg/Log")
    spec = TopicSpec("rosgraph_msgs/Log", md5, definition)
    peer = Ros1Peer(master_uri)
    peer.advertise("/rosout", "/rosout_agg", spec, queue_size=1000)
    peer.subscribe("/rosout", "/rosout", spec, lambda data: peer.publish("/rosout_agg", data))
    return peer


def roscore(
    port: Annotated[
        int,
        typer.Option("--port", "-p", help="XML-RPC port of the master (ROS: roscore -p)."),
    ] = DEFAULT_MASTER_PORT,
    host: Annotated[
        str,
        typer.Option(
            "--host",
            help="Address to listen on and advertise (default loopback only; 0.0.0.0 or "
            "this machine's address to let other machines in).",
        ),
    ] = "127.0.0.1",
) -> None:
    """Run a ROS 1 master: the master API (register/unregister publishers, subscribers
    and services, lookupNode, getSystemState, ...) and the parameter server (with
    /run_id and paramUpdate callbacks), like ros_comm's roscore / rosmaster. Real rospy
    and roscpp nodes, rostopic, rosnode, rosparam and rosservice work against it; point
    them (and roverlab) at it with ROS_MASTER_URI=http://127.0.0.1:PORT/. As roscore, it
    runs the /rosout node (/rosout gathered on /rosout_agg; no log file)."""
    try:
        master = Master(host=host, port=port)
    except OSError as err:
        raise TransportError(
            f"cannot listen on {host}:{port}: {err.strerror or err} "
            "(another roscore running? try -p PORT)"
        ) from None
    stop = threading.Event()

    def on_signal(*_: Any) -> None:
        stop.set()

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    master.start()
    rosout = start_rosout(master.uri)
    typer.echo(f"started roscore: ROS_MASTER_URI={master.uri}", err=False)
    while not stop.wait(0.2):
        if master.shutdown_requested.is_set():
            break
    rosout.close()
    master.stop()
    typer.echo("roscore stopped")
