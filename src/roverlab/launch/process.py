"""A ``<node>`` that is the user's own rospy script: run in a process of its own.

roslaunch starts every node as a process. roverlab's own nodes run inside the launch's
process; a Python script of the user's package (``<node pkg="my_pkg" type="talker.py">``)
runs as roslaunch runs it, in a child process (``roverlab run SCRIPT``) joined to the
launch's graph (a Zenoh client of the launch's own endpoint: :func:`child_network`),
with the ``<node>``'s arguments, remappings, name, namespace, ``<env>``, ``cwd`` and
``launch-prefix``. Its private parameters and the
launch's global ones reach rospy's ``get_param`` through a YAML file named by
``ROVERLAB_LAUNCH_PARAMS`` (ROS 1's parameter server, for that one process).
"""

from __future__ import annotations

import glob
import os
import shlex
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import yaml

from roverlab.core.logfiles import node_log_file
from roverlab.core.transport.zenoh import ZenohOptions, daemon_endpoint
from roverlab.description import find_package
from roverlab.description.errors import DescriptionError
from roverlab.launch.xml import LaunchError, NodeSpec
from roverlab.ros1.rospy.runtime import LAUNCH_PARAMS_ENV

__all__ = [
    "ChildNetwork",
    "ScriptLookupError",
    "ScriptProcess",
    "ScriptProcesses",
    "child_network",
    "find_script",
    "is_python_script",
    "launch_endpoint",
    "ros_home",
]

# roslaunch's escalation when it stops a process: SIGINT, then SIGTERM, then SIGKILL
_TIMEOUT_SIGINT_S = 15.0
_TIMEOUT_SIGTERM_S = 2.0


class ScriptLookupError(Exception):
    """Why a package's ``TYPE`` gives no script to run (one line, no trailing period).

    Attributes:
        missing: neither the package nor the file exists (``TYPE`` may be a roverlab node
            that roverlab lacks), rather than a file found that cannot run.
    """

    def __init__(self, message: str, *, missing: bool = False) -> None:
        super().__init__(message)
        self.missing = missing


def _files_named(folder: Path, pkg: str, type_: str) -> list[Path]:
    """The files named ``type_`` in package ``pkg`` (at ``folder``), searched through the
    package's folders as roslaunch and rosrun find a node's executable: one to run; none,
    or several (roslaunch's "multiple files named"), to report. A ``type_`` with a ``/``
    is a path inside the package (``scripts/talker.py``, as rosrun takes it): that one
    file. The executable bit is not required: the callers note a file without it.

    Raises:
        ScriptLookupError: a path that leaves the package (``..``, absolute).
    """
    if not type_:
        return []
    if "/" in type_:
        rel = Path(os.path.normpath(type_))
        if rel.is_absolute() or rel.parts[:1] == ("..",):
            raise ScriptLookupError(f"{type_!r} is outside package {pkg} ({folder})")
        path = folder / rel
        return [path] if path.is_file() else []
    return sorted(p for p in folder.rglob(glob.escape(type_)) if p.is_file())  # the exact name


def find_script(pkg: str, type_: str, package_path: tuple[str, ...] = ()) -> Path:
    """The one Python script that ``rosrun pkg type`` or ``<node pkg type>`` runs, searched
    through the package's folders as roslaunch does: the decision ``roverlab run``, the
    launch's runner and ``roverlab launch`` (which exposes the topics of the script nodes)
    share.

    Raises:
        ScriptLookupError: no such package or file (``missing``), a path outside the
            package, several files of that name, a file that is not a Python script.
    """
    try:
        folder = find_package(pkg, package_path)
    except DescriptionError as err:  # "package 'x' not found (searched: ...)"
        raise ScriptLookupError(str(err), missing=True) from None
    found = _files_named(folder, pkg, type_)
    if not found:
        raise ScriptLookupError(f"no file {type_!r} in package {pkg} ({folder})", missing=True)
    if len(found) > 1:  # rosrun asks which one; roslaunch refuses the node
        raise ScriptLookupError(
            f"multiple files named [{type_}] in package [{pkg}]: "
            f"{', '.join(str(p) for p in found)} (name one by its path in the package: "
            f"{found[0].relative_to(folder)})"
        )
    if not is_python_script(found[0]):
        raise ScriptLookupError(
            f"{found[0]} is not a Python script (roverlab runs rospy scripts, not compiled nodes)"
        )
    return found[0]


def is_python_script(path: Path) -> bool:
    """``*.py``, or a first line ``#!...python...``."""
    if path.suffix == ".py":
        return True
    try:
        with path.open("rb") as f:
            first = f.readline(200)
    except OSError:
        return False
    return first.startswith(b"#!") and b"python" in first


def launch_endpoint(folder: Path) -> str:
    """A Unix-socket endpoint in ``folder`` (a private temporary folder) for the launch to
    listen on, so that its script processes join it there (no port to pick, and only this
    user can connect)."""
    return f"unixsock-stream/{folder / 'zenoh.sock'}"


@dataclass(frozen=True)
class ChildNetwork:
    """How a script process joins the launch's graph: root options of ``roverlab`` (never
    a password) and environment variables (``None``: removed)."""

    args: tuple[str, ...] = ()
    env: dict[str, str | None] = field(default_factory=dict)


def _joinable(endpoint: str) -> bool:
    """A Unix socket, or a loopback TCP port fixed in advance (not ``:0``)."""
    proto, _, addr = endpoint.partition("/")
    if proto.startswith("unixsock"):
        return True
    host, _, port = addr.split("#")[0].rpartition(":")
    return proto == "tcp" and host.startswith("127.") and port not in ("", "0")


def child_network(options: ZenohOptions) -> ChildNetwork:
    """The same graph as a launch joined with ``options``: a Zenoh client of the launch's
    Unix socket (or fixed loopback port), which routes for it, so it is seen wherever the
    launch is (the robot's daemon, a laptop connected to the launch, the robot the launch
    connected to, multicast peers). Without such an endpoint: a peer with the launch's
    ``connect`` endpoints, credentials and TLS CA. The password and the domain go in the
    environment (``ps`` shows a command line)."""
    secret = {
        "ROVERLAB_PASSWORD": options.password,
        "ROVERLAB_DOMAIN_ID": str(options.domain),
        "ROVERLAB_CONNECT": None,  # the launch's own, given explicitly below
        "ROVERLAB_LISTEN": None,
    }
    user = ("--user", options.user) if options.user is not None else ()
    own = [ep for ep in options.listen if _joinable(ep)]
    if own:
        return ChildNetwork(args=("--client-of", own[0], *user), env=secret)
    args: list[str] = list(user)
    if options.connect != (daemon_endpoint(),) or options.present_credentials:
        for ep in options.connect:
            args += ["--connect", ep]
    if options.tls_root_ca is not None:
        args += ["--tls-root-ca", options.tls_root_ca]
    if options.multicast_scouting:
        args.append("--multicast")
    return ChildNetwork(args=tuple(args), env=secret)


def ros_home() -> Path:
    """``$ROS_HOME``, else ``~/.ros``: roslaunch's working directory for its nodes."""
    home = Path(os.environ.get("ROS_HOME") or Path.home() / ".ros")
    home.mkdir(parents=True, exist_ok=True)
    return home


class ScriptProcess:
    """One script node's process: started at construction, stopped with :meth:`stop`.

    Args:
        spec: the ``<node>``.
        script: the script file.
        clock: ``roverlab run --clock`` (``wall`` or ``external``: the launch's clock).
        params: the launch's global parameters (absolute names).
        network: how it joins the launch's graph (:func:`child_network`).
    """

    def __init__(
        self,
        spec: NodeSpec,
        script: Path,
        *,
        clock: str,
        params: dict[str, Any],
        network: ChildNetwork,
    ) -> None:
        self.spec = spec
        self.script = script
        self._signalled: set[int] = set()
        try:
            argv = [*shlex.split(spec.launch_prefix), sys.executable, "-m", "roverlab.cli"]
            argv += [*network.args, "run"]
            argv += ["--clock", clock, str(script), *shlex.split(spec.args)]
        except ValueError as err:  # an unmatched quote in launch-prefix or args
            raise LaunchError(f"{spec.source}: {err}") from err
        argv += [f"{k}:={v}" for k, v in spec.remaps.items()]
        argv += [f"__name:={spec.name}", f"__ns:={spec.namespace}"]
        self.argv = argv
        self._log: IO[bytes] | None = None
        self.log_file: Path | None = None  # its stdout's file (output="log")
        stdout: IO[bytes] | None = None
        if spec.output == "log":  # roslaunch: stdout to the node's log file, stderr on screen
            log_file = node_log_file(spec.fq_name)  # as the launch's own nodes' logs
            self.log_file = log_file
            try:
                log_file.parent.mkdir(parents=True, exist_ok=True)
                self._log = stdout = log_file.open("ab")
            except OSError as err:
                raise LaunchError(
                    f"{spec.source}: cannot write {log_file}: {err.strerror}"
                ) from err
        self._params_file = _write_params(spec, params)
        env = {**os.environ, **spec.env, LAUNCH_PARAMS_ENV: self._params_file}
        for key, value in network.env.items():  # the launch's graph, whatever <env> says
            if value is None:
                env.pop(key, None)
            else:
                env[key] = value
        env["PYTHONUNBUFFERED"] = "1"  # its lines in order with the launch's
        cwd = script.parent if spec.cwd == "node" else ros_home()
        try:
            # a session of its own: the launch alone signals it (one SIGINT, as roslaunch
            # sends), not also the terminal's Ctrl-C
            self.popen = subprocess.Popen(
                argv, env=env, cwd=cwd, stdout=stdout, start_new_session=True
            )
        except OSError as err:
            self._cleanup()
            raise LaunchError(f"{spec.source}: cannot start {argv[0]}: {err.strerror}") from err

    @property
    def pid(self) -> int:
        return self.popen.pid

    def poll(self) -> int | None:
        """The exit code once the process has ended, else ``None``."""
        return self.popen.poll()

    def signal(self, sig: int) -> None:
        """Send ``sig`` once (a second SIGINT would cut rospy's shutdown hooks short)."""
        if sig not in self._signalled and self.popen.poll() is None:
            self._signalled.add(sig)
            self.popen.send_signal(sig)

    def stop(self) -> None:
        """SIGINT (rospy's shutdown hooks run), then SIGTERM, then SIGKILL, as roslaunch;
        killed and its files removed whatever interrupts the wait."""
        try:
            for sig, timeout_s in (
                (signal.SIGINT, _TIMEOUT_SIGINT_S),
                (signal.SIGTERM, _TIMEOUT_SIGTERM_S),
                (signal.SIGKILL, None),
            ):
                if self.popen.poll() is not None:
                    break
                self.signal(sig)
                try:
                    self.popen.wait(timeout_s)
                except subprocess.TimeoutExpired:
                    continue
        finally:
            if self.popen.poll() is None:
                self.popen.kill()
            self._cleanup()

    def _cleanup(self) -> None:
        if self._log is not None:
            self._log.close()
            self._log = None
        Path(self._params_file).unlink(missing_ok=True)


def _write_params(spec: NodeSpec, params: dict[str, Any]) -> str:
    """The node's private parameters and the launch's global ones, in a temporary YAML
    file (a ``robot_description`` is too long for an environment variable)."""
    fd, name = tempfile.mkstemp(prefix=f"roverlab-{spec.name}-", suffix=".yaml")
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        yaml.safe_dump({"private": dict(spec.params), "global": dict(params)}, f)
    return name


class ScriptProcesses:
    """The launch's script processes, stopped when its context shuts down (attached to
    the context as a transport: :meth:`close` is the context's shutdown hook)."""

    def __init__(self) -> None:
        self.processes: list[ScriptProcess] = []

    def attach(self, context: Any) -> None:
        pass

    def on_node(self, node: Any, added: bool) -> None:
        pass

    def on_publisher(self, pub: Any, added: bool) -> None:
        pass

    def on_subscription(self, sub: Any, added: bool) -> None:
        pass

    def close(self) -> None:
        """Stop every process (idempotent): SIGINT to all at once (their hooks run
        together), then each waited for; whatever interrupts, none is left running."""
        procs, self.processes = self.processes, []
        try:
            for proc in procs:
                proc.signal(signal.SIGINT)
        finally:
            for proc in procs:
                try:
                    proc.stop()
                except BaseException:
                    for rest in procs:  # a second Ctrl-C: kill what runs, remove the files
                        if rest.poll() is None:
                            rest.popen.kill()
                        rest._cleanup()
                    raise
