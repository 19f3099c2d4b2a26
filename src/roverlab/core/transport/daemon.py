"""The roverlab daemon: a Zenoh router on 127.0.0.1 that lets local processes find each other.

It plays the part of ``roscore`` (ROS 1) or the ``ros2`` CLI daemon / ``rmw_zenohd``
(ROS 2): every roverlab process connects to it, and Zenoh's gossip then links the
processes directly. The CLI starts it on first use; ``roverlab daemon stop`` ends it.
It only ever listens on the loopback endpoint it is given.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import subprocess
import sys
import threading
import time
from dataclasses import replace

from roverlab.core.context import Context
from roverlab.core.errors import TransportError
from roverlab.core.logfiles import log_dir as roverlab_log_dir
from roverlab.core.transport.zenoh import (
    ZenohOptions,
    ZenohTransport,
    daemon_endpoint,
    endpoint_reachable,
    open_session,
)

__all__ = ["connect_context", "daemon_running", "ensure_daemon", "run_daemon", "stop_daemon"]

_CONTROL = "rl/daemon"


def _loopback_only(endpoint: str) -> None:
    proto, _, addr = endpoint.partition("/")
    host = addr.rpartition(":")[0].strip("[]")
    if proto != "tcp" or host not in ("127.0.0.1", "localhost", "::1"):
        raise TransportError(
            f"the daemon listens on loopback TCP only; got {endpoint!r} "
            "(to reach other machines use --listen/--connect on the processes themselves)"
        )


def daemon_running(endpoint: str | None = None) -> bool:
    return endpoint_reachable(endpoint or daemon_endpoint())


def ensure_daemon(endpoint: str | None = None, timeout_s: float = 10.0) -> str:
    """Start the daemon in the background unless one answers at ``endpoint``."""
    ep = endpoint or daemon_endpoint()
    if endpoint_reachable(ep):
        return ep
    _loopback_only(ep)
    log_dir = roverlab_log_dir()
    log_dir.mkdir(parents=True, exist_ok=True)
    with open(log_dir / "daemon.log", "ab") as log:
        subprocess.Popen(
            [sys.executable, "-m", "roverlab.core.transport.daemon", "--endpoint", ep],
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=log,
            start_new_session=True,
            close_fds=True,
        )
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if endpoint_reachable(ep):
            return ep
        time.sleep(0.05)
    raise TransportError(f"the roverlab daemon did not start on {ep} (see {log_dir}/daemon.log)")


def stop_daemon(endpoint: str | None = None, timeout_s: float = 5.0) -> bool:
    """Ask the daemon at ``endpoint`` to exit; False if none was running."""
    ep = endpoint or daemon_endpoint()
    if not endpoint_reachable(ep):
        return False
    session, temps = open_session(ZenohOptions(mode="client", listen=(), connect=(ep,)))
    try:
        list(session.get(f"{_CONTROL}/stop", timeout=2.0))
    finally:
        session.close()
        for p in temps:
            os.unlink(p)
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if not endpoint_reachable(ep):
            return True
        time.sleep(0.05)
    return not endpoint_reachable(ep)


def connect_context(context: Context, options: ZenohOptions | None = None) -> ZenohTransport:
    """Expose a context's topics on the local network of roverlab processes.

    With no explicit ``connect`` endpoints the daemon is started if needed and joined, so
    ``roverlab topic echo`` in another terminal finds this process.
    """
    opts = options or ZenohOptions()
    if not opts.connect and opts.mode != "router":
        opts = replace(opts, connect=(ensure_daemon(),))
    transport = ZenohTransport(opts)
    context.add_transport(transport)
    return transport


def run_daemon(endpoint: str) -> None:
    """Run the router until asked to stop (blocking)."""
    _loopback_only(endpoint)
    session, temps = open_session(ZenohOptions(mode="router", listen=(endpoint,), connect=()))
    stop = threading.Event()
    started = time.time()

    def on_stop(query: object) -> None:
        query.reply(query.key_expr, "stopping")  # type: ignore[attr-defined]
        stop.set()

    def on_info(query: object) -> None:
        info = {"pid": os.getpid(), "endpoint": endpoint, "since": started}
        query.reply(query.key_expr, json.dumps(info))  # type: ignore[attr-defined]

    q1 = session.declare_queryable(f"{_CONTROL}/stop", on_stop)
    q2 = session.declare_queryable(f"{_CONTROL}/info", on_info)
    print(f"roverlab daemon listening on {endpoint} (pid {os.getpid()})", flush=True)
    try:
        while not stop.wait(0.5):
            pass
    finally:
        q1.undeclare()
        q2.undeclare()
        time.sleep(0.1)  # let the stop reply leave
        session.close()
        for p in temps:
            with contextlib.suppress(OSError):
                os.unlink(p)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="roverlab daemon (Zenoh router on loopback)")
    parser.add_argument("--endpoint", default=daemon_endpoint())
    args = parser.parse_args(argv)
    try:
        run_daemon(args.endpoint)
    except TransportError as err:
        print(f"error: {err}", file=sys.stderr)
        sys.exit(2)


if __name__ == "__main__":
    main()
