"""Seed 002's robot/laptop split on two network namespaces joined by a veth pair.

The robot namespace runs ``roverlab --listen tcp/0.0.0.0:7447 --user U --password P launch``
(the simulated robot with gmapping); the laptop namespace runs ``roverlab --connect
tcp/ROBOT:7447 --user U --password P topic ...``. /scan and /map reach the laptop, its
/cmd_vel drives the robot, a wrong password is one clear error, and an unauthenticated
listen beyond loopback is refused. The test makes the namespaces and removes them; it is
skipped, saying why, where it cannot (no root, no ``ip``, no netns support).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pytest
import yaml

from tests.helpers.procs import twist_pub_args

pytestmark = pytest.mark.timeout(360)

ROVERLAB = str(Path(sys.executable).with_name("roverlab"))
ROBOT_IP, LAPTOP_IP = "10.203.77.1", "10.203.77.2"
AUTH = ["--user", "robot", "--password", "s3cret"]


def _ip(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["ip", *args], capture_output=True, text=True, check=False)


class Namespaces:
    """Two network namespaces (robot, laptop) joined by a veth pair."""

    def __init__(self) -> None:
        tag = str(os.getpid() % 100000)
        self.robot, self.laptop = f"rl_robot_{tag}", f"rl_laptop_{tag}"
        self.veth_r, self.veth_l = f"rlr{tag}", f"rll{tag}"
        self.procs: list[subprocess.Popen[str]] = []

    def create(self) -> str | None:
        """Set up; returns why it could not (then cleans up), or None."""
        steps = [
            ("netns", "add", self.robot),
            ("netns", "add", self.laptop),
            ("link", "add", self.veth_r, "type", "veth", "peer", "name", self.veth_l),
            ("link", "set", self.veth_r, "netns", self.robot),
            ("link", "set", self.veth_l, "netns", self.laptop),
            ("-n", self.robot, "addr", "add", f"{ROBOT_IP}/24", "dev", self.veth_r),
            ("-n", self.laptop, "addr", "add", f"{LAPTOP_IP}/24", "dev", self.veth_l),
            ("-n", self.robot, "link", "set", self.veth_r, "up"),
            ("-n", self.laptop, "link", "set", self.veth_l, "up"),
            ("-n", self.robot, "link", "set", "lo", "up"),
            ("-n", self.laptop, "link", "set", "lo", "up"),
        ]
        for step in steps:
            done = _ip(*step)
            if done.returncode != 0:
                self.remove()
                return f"`ip {' '.join(step)}` failed: {done.stderr.strip()}"
        return None

    def popen(self, ns: str, args: list[str], env: dict[str, str]) -> subprocess.Popen[str]:
        p = subprocess.Popen(
            ["ip", "netns", "exec", ns, *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        self.procs.append(p)
        return p

    def run(self, ns: str, args: list[str], env: dict[str, str], timeout: float = 60):
        return subprocess.run(
            ["ip", "netns", "exec", ns, *args],
            capture_output=True,
            text=True,
            env=env,
            timeout=timeout,
            check=False,
        )

    def wait_listening(self, ns: str, host: str, port: int, timeout: float) -> None:
        """Until ``host:port`` accepts TCP connections from namespace ``ns``."""
        probe = f"import socket; socket.create_connection(({host!r}, {port}), 1).close()"
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.run(ns, [sys.executable, "-c", probe], dict(os.environ)).returncode == 0:
                return
            time.sleep(0.5)
        raise AssertionError(f"nothing listened on {host}:{port} within {timeout} s")

    def remove(self) -> None:
        for p in self.procs:
            if p.poll() is None:
                p.send_signal(signal.SIGINT)
        for p in self.procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        for ns in (self.robot, self.laptop):
            # processes this test started inside the namespace (the robot's daemon)
            pids = _ip("netns", "pids", ns).stdout.split()
            for pid in pids:
                with contextlib.suppress(ProcessLookupError, ValueError):
                    os.kill(int(pid), signal.SIGTERM)
            _ip("netns", "delete", ns)


@pytest.fixture
def namespaces() -> Iterator[Namespaces]:
    if os.geteuid() != 0:
        pytest.skip("network namespaces need root (CAP_NET_ADMIN)")
    if shutil.which("ip") is None:
        pytest.skip("the `ip` command (iproute2) is not installed")
    ns = Namespaces()
    why = ns.create()
    if why is not None:
        pytest.skip(f"cannot make network namespaces here: {why}")
    yield ns
    ns.remove()
    assert ns.robot not in _ip("netns", "list").stdout


def _env(tmp_path: Path, name: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROVERLAB_")}
    env["ROVERLAB_DAEMON"] = "tcp/127.0.0.1:7447"  # the namespace's own loopback
    env["ROVERLAB_LOG_DIR"] = str(tmp_path / f"log_{name}")
    env["ROVERLAB_DASHBOARD_PORT"] = "0"
    env["PYTHONUNBUFFERED"] = "1"
    return env


ROBOT_LAUNCH = """<launch>
  <include file="$(find bingda_tutorials)/launch/simulation_robot.launch"/>
  <node pkg="gmapping" type="slam_gmapping" name="slam_gmapping">
    <param name="map_update_interval" value="1.0"/>
    <param name="particles" value="10"/>
    <param name="temporalUpdate" value="0.5"/>
    <param name="maxUrange" value="4.5"/>
  </node>
</launch>
"""


def _yaml_doc(text: str) -> dict[str, object]:
    doc = text.split("---")[0]
    data = yaml.safe_load(doc)
    assert isinstance(data, dict), text[:300]
    return data


def test_robot_and_laptop_over_a_veth_pair(namespaces: Namespaces, tmp_path: Path) -> None:
    ns = namespaces
    robot_env, laptop_env = _env(tmp_path, "robot"), _env(tmp_path, "laptop")
    launch_file = tmp_path / "robot.launch"
    launch_file.write_text(ROBOT_LAUNCH)
    # seed 002's robot listens on every address, on the port its daemon holds on loopback
    listen = ["--listen", "tcp/0.0.0.0:7447"]
    connect = ["--connect", f"tcp/{ROBOT_IP}:7447"]

    # listening on the veth without authentication is refused
    refused = ns.run(ns.robot, [ROVERLAB, *listen, "launch", str(launch_file)], robot_env)
    assert refused.returncode == 2
    assert refused.stderr.strip().splitlines() == [
        "error: refusing to listen on tcp/0.0.0.0:7447 without authentication: anyone on "
        "that network could read the robot's topics and drive it. Give --user and --password "
        "(the same on both machines), or --insecure on a network you trust"
    ]

    robot = ns.popen(
        ns.robot, [ROVERLAB, *listen, *AUTH, "launch", str(launch_file), "--rate", "1"], robot_env
    )
    ns.wait_listening(ns.laptop, ROBOT_IP, 7447, timeout=90)

    def echo_once(topic: str, wait_s: int, timeout: float) -> subprocess.CompletedProcess[str]:
        """``topic echo TOPIC --once`` on the laptop, through the robot's listener."""
        args = ["topic", "echo", topic, "--once", "--no-arr", "--timeout", str(wait_s)]
        return ns.run(ns.laptop, [ROVERLAB, *connect, *AUTH, *args], laptop_env, timeout=timeout)

    scan = echo_once("/scan", 60, timeout=90)
    assert scan.returncode == 0, scan.stderr + (robot.stderr.read() if robot.poll() else "")
    assert _yaml_doc(scan.stdout)["header"]["frame_id"]  # type: ignore[index]

    # a wrong password: one clear error line, exit code 2
    wrong = ns.run(
        ns.laptop,
        [ROVERLAB, *connect, "--user", "robot", "--password", "wrong", "topic", "list"],
        laptop_env,
    )
    assert wrong.returncode == 2
    assert wrong.stderr.strip().splitlines() == [
        f"error: tcp/{ROBOT_IP}:7447 refused the session: wrong --user/--password "
        "(or another TLS setup)"
    ]

    # the robot's own tools (no password, through its daemon) see the launch too
    local = ns.run(ns.robot, [ROVERLAB, "node", "list"], robot_env)
    assert "/slam_gmapping" in local.stdout.split(), local.stdout + local.stderr

    # the laptop's /cmd_vel drives the robot: /odom (echoed on the laptop) turns. In
    # place: a robot driving ahead meets the maze's wall while a loaded machine is slow
    pub = ns.popen(
        ns.laptop,
        [
            ROVERLAB,
            *connect,
            *AUTH,
            *twist_pub_args(0.0, 0.5),
        ],
        laptop_env,
    )
    twist, seen = 0.0, []
    deadline = time.monotonic() + 120.0
    while time.monotonic() < deadline and twist < 0.4:
        time.sleep(1.0)
        odom = echo_once("/odom", 30, timeout=120)
        assert odom.returncode == 0, odom.stderr
        twist = _yaml_doc(odom.stdout)["twist"]["twist"]["angular"]["z"]  # type: ignore[index]
        seen.append(round(twist, 3))
    pub.send_signal(signal.SIGINT)
    assert pub.wait(timeout=10) == 0
    assert twist == pytest.approx(0.5, abs=0.05), f"/odom's angular speeds: {seen}"

    # gmapping's /map (latched) crosses too
    grid = echo_once("/map", 60, timeout=90)
    assert grid.returncode == 0, grid.stderr
    info = _yaml_doc(grid.stdout)["info"]
    assert info["width"] > 0 and info["resolution"] == pytest.approx(0.05)  # type: ignore[index]
    robot.send_signal(signal.SIGINT)
    assert robot.wait(timeout=20) == 0


def test_listen_beyond_loopback_needs_authentication() -> None:
    from roverlab.cli.common import NetworkOptions, is_loopback_endpoint
    from roverlab.errors import RoverlabError

    assert is_loopback_endpoint("tcp/127.0.0.1:7447") and is_loopback_endpoint("tcp/[::1]:7447")
    assert is_loopback_endpoint("tcp/localhost:0") and is_loopback_endpoint("unixsock-stream//x")
    assert not is_loopback_endpoint("tcp/0.0.0.0:7447")
    assert not is_loopback_endpoint("tcp/192.168.1.41:7447")
    peer = ("tcp/127.0.0.1:1",)  # an explicit --connect: no daemon is started
    with pytest.raises(RoverlabError, match=r"refusing to listen on tcp/0\.0\.0\.0:7447"):
        NetworkOptions(listen=("tcp/0.0.0.0:7447",), connect=peer).zenoh_options()
    insecure = NetworkOptions(listen=("tcp/0.0.0.0:7447",), connect=peer, insecure=True)
    assert insecure.zenoh_options().listen == ("tcp/0.0.0.0:7447",)
    auth = NetworkOptions(
        listen=("tcp/0.0.0.0:7447",), connect=peer, user="robot", password="s3cret"
    ).zenoh_options()
    assert auth.user == "robot" and auth.connect_timeout_s == 5.0


def test_connect_to_nothing_is_one_clear_error() -> None:
    done = subprocess.run(
        [ROVERLAB, "--connect", "tcp/127.0.0.1:9", "topic", "list"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "error: cannot connect to tcp/127.0.0.1:9: nothing answers there (is roverlab running "
        "on that machine with --listen on that address and port?)"
    ]


def test_a_listening_robot_joins_its_daemon(daemon: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """With a password and no --connect: the wildcard on the daemon's port becomes the
    machine's addresses, and the session offers no password to the daemon (which asks for
    none) while it checks the password of sessions that come in."""

    from roverlab.cli.common import NetworkOptions
    from roverlab.core.errors import TransportError
    from roverlab.core.transport import interfaces
    from roverlab.core.transport.zenoh import open_session

    port = daemon.rpartition(":")[2]
    monkeypatch.setattr(
        interfaces, "host_addresses", lambda family: ["192.0.2.7"] if family == 4 else ["fd00::7"]
    )
    robot = NetworkOptions(
        listen=(f"tcp/0.0.0.0:{port}", "tcp/[::]:" + port, "tcp/0.0.0.0:7400", "tcp/127.0.0.1:0"),
        user="robot",
        password="s3cret",
    ).zenoh_options()
    assert robot.connect == (daemon,) and not robot.present_credentials
    assert robot.listen == (
        f"tcp/192.0.2.7:{port}",
        f"tcp/192.0.2.7:{port}",
        f"tcp/[fd00::7]:{port}",
        "tcp/0.0.0.0:7400",
        "tcp/127.0.0.1:0",
    )
    monkeypatch.setattr(interfaces, "host_addresses", lambda family: [])
    with pytest.raises(TransportError, match="no address besides loopback"):
        NetworkOptions(listen=(f"tcp/0.0.0.0:{port}",), user="u", password="p").zenoh_options()

    # on loopback: the robot joins the daemon; a laptop with the password joins the robot
    # (and its own daemon-less peers), one with a wrong password does not
    robot_port = _free_tcp_port()
    session, temps = open_session(replace(robot, listen=(f"tcp/127.0.0.1:{robot_port}",)))
    try:
        time.sleep(1.0)
        assert len(list(session.info.routers_zid())) == 1  # the daemon
        laptop = NetworkOptions(
            connect=(f"tcp/127.0.0.1:{robot_port}",), user="robot", password="s3cret"
        ).zenoh_options()
        assert laptop.present_credentials
        other, other_temps = open_session(laptop)
        assert str(session.info.zid()) in {str(z) for z in other.info.peers_zid()}
        other.close()
        for path in other_temps:
            os.unlink(path)
        with pytest.raises(TransportError, match="refused the session: wrong --user"):
            open_session(replace(laptop, password="wrong"))
    finally:
        session.close()
        for path in temps:
            os.unlink(path)


def _free_tcp_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])
