"""``roverlab service`` and ``roverlab action`` against running processes."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from typing import Any

import pytest
import yaml

pytestmark = pytest.mark.zenoh


def _until(cli: Any, args: list[str], ok: Any, timeout: float = 20.0) -> Any:
    """Run ``roverlab ARGS`` until ``ok(result)`` (a just-started process's graph entries
    reach the router asynchronously; on a loaded machine that takes a moment)."""
    deadline = time.monotonic() + timeout
    while True:
        r = cli(*args)
        if ok(r) or time.monotonic() > deadline:
            return r
        time.sleep(0.3)


def test_service_list_type_call(node_proc: Any, cli: Any) -> None:
    node_proc("services")
    r = _until(cli, ["service", "list", "-t"], lambda r: "/fail [" in r.stdout)
    assert r.returncode == 0, r.stderr
    assert "/add_two_ints [rospy_tutorials/srv/AddTwoInts]" in r.stdout.splitlines()
    assert "/fail [std_srvs/srv/Trigger]" in r.stdout.splitlines()
    r = cli("service", "type", "/add_two_ints")
    assert r.stdout.strip() == "rospy_tutorials/srv/AddTwoInts"
    # ROS 1 spelling of the type; then the type left out (looked up from the server)
    for args in (["rospy_tutorials/AddTwoInts", "{a: 40, b: 2}"], ["{a: 40, b: 2}"]):
        r = cli("service", "call", "/add_two_ints", *args)
        assert r.returncode == 0, r.stderr
        assert yaml.safe_load(r.stdout.split("response:")[1]) == {"sum": 42}


def test_service_call_errors_are_one_line_exit_2(node_proc: Any, cli: Any) -> None:
    node_proc("services")
    cases = [
        (["/fail", "std_srvs/Trigger"], "service '/fail' failed: callback raised RuntimeError"),
        (["/nobody", "std_srvs/Empty", "--timeout", "0.5"], "service '/nobody' is not available"),
        (["/add_two_ints", "rospy_tutorials/AddTwoInts", "{a: [}"], "invalid YAML"),
        (["/add_two_ints", "rospy_tutorials/AddTwoInts", "{c: 1}"], "has no field 'c'"),
        (["/add_two_ints", "std_srvs/Emty"], "unknown service type 'std_srvs/Emty'"),
    ]
    for args, needle in cases:
        r = cli("service", "call", *args)
        assert r.returncode == 2, args
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and needle in lines[0], r.stderr


def test_action_list_info_send_goal(node_proc: Any, cli: Any) -> None:
    node_proc("fibonacci")
    r = _until(cli, ["action", "list", "-t"], lambda r: bool(r.stdout.strip()))
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["/fibonacci [actionlib_tutorials/action/Fibonacci]"]
    r = cli("action", "info", "/fibonacci")
    assert "Action servers: 1\n    /proc_fibonacci" in r.stdout
    r = cli(
        "action", "send_goal", "/fibonacci", "actionlib_tutorials/Fibonacci", "{order: 5}", "-f"
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.count("Feedback:") == 5
    result = yaml.safe_load(r.stdout.split("Result:")[1].split("Goal finished")[0])
    assert result == {"sequence": [0, 1, 1, 2, 3, 5, 8]}
    assert r.stdout.rstrip().endswith("Goal finished with status: SUCCEEDED (done)")
    r = cli(
        "action", "send_goal", "/fibonacci", "actionlib_tutorials/FibonacciAction", "{order: 13}"
    )
    assert r.returncode == 1
    assert "Goal finished with status: ABORTED (13 is unlucky)" in r.stdout


def test_action_status_topic_as_topic_echo_shows_it(node_proc: Any, cli: Any) -> None:
    node_proc("fibonacci")
    goal = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "roverlab.cli",
            "action",
            "send_goal",
            "/fibonacci",
            "actionlib_tutorials/Fibonacci",
            "{order: 10000}",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 20
        status: list[Any] = []
        while time.monotonic() < deadline and not status:
            r = cli("topic", "echo", "/fibonacci/status", "--once", "--timeout", "10")
            assert r.returncode == 0, r.stderr
            status = yaml.safe_load(r.stdout.split("---")[0])["status_list"]
        (entry,) = status
        assert entry["status"] == 1  # ACTIVE
        assert entry["goal_id"]["id"].startswith("/roverlab_action_send_goal-1-")
        assert entry["text"] == "This goal has been accepted by the simple action server"
    finally:
        # Ctrl-C cancels the goal: the server preempts it and the command reports that
        goal.send_signal(signal.SIGINT)
        try:
            out, err = goal.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            goal.kill()  # never leave the command running past the test
            out, err = goal.communicate()
            pytest.fail(f"send_goal did not end within 20 s of SIGINT; it printed: {out!r}")
    assert "Canceling goal..." in out, err
    assert "Goal finished with status: PREEMPTED (canceled)" in out
    assert goal.returncode == 1


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["/fibonacci", "actionlib_tutorials/Fibonaci", "{}"], "unknown action type"),
        (["/fibonacci", "actionlib_tutorials/Fibonacci", "{order: x}"], "order"),
        (["/fibonacci", "actionlib_tutorials/Fibonacci", "{", "--timeout", "1"], "invalid YAML"),
        (
            ["/nothing", "actionlib_tutorials/Fibonacci", "{}", "--timeout", "0.5"],
            "no action server",
        ),
    ],
)
def test_send_goal_errors_are_one_line_exit_2(cli: Any, args: list[str], needle: str) -> None:
    r = cli("action", "send_goal", *args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], r.stderr


def test_action_info_unknown_exit_2(cli: Any) -> None:
    r = cli("action", "info", "/nothing_here")
    assert r.returncode == 2 and "unknown action '/nothing_here'" in r.stderr
