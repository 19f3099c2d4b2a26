"""The rospy layer in one process: imports, message classes, time, params, topics,
services, shutdown."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context
from roverlab.msgs import classes as mc
from roverlab.msgs import serialize
from roverlab.ros1 import install, run_script, uninstall
from roverlab.ros1.rospy.runtime import RUNTIME, parse_command_line


@pytest.fixture
def ros1() -> Iterator[Any]:
    """``import rospy`` works; the runtime is reset afterwards."""
    install()
    rospy = importlib.import_module("rospy")
    yield rospy
    RUNTIME.reset()
    uninstall()


@pytest.fixture
def node(ros1: Any) -> Iterator[Any]:
    ctx = Context(clock="wall", publish_clock=False)
    RUNTIME.configure(ctx, ["_speed:=0.7", "_name_list:=[a, b]", "chatter:=/talk"])
    ros1.init_node("tester", disable_signals=True)
    yield ros1
    RUNTIME.signal_shutdown("test over")
    ctx.shutdown()


def test_imports_resolve(ros1: Any) -> None:
    import roslib  # type: ignore[import-not-found]
    import tf.transformations  # type: ignore[import-not-found]
    from actionlib_msgs.msg import GoalStatus  # type: ignore[import-not-found]
    from geometry_msgs.msg import Point, Pose, Quaternion, Twist  # type: ignore[import-not-found]
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal  # type: ignore[import-not-found]
    from std_srvs.srv import Empty, EmptyRequest, EmptyResponse  # type: ignore[import-not-found]

    import actionlib  # type: ignore[import-not-found]

    roslib.load_manifest("teleop_twist_keyboard")
    assert GoalStatus.SUCCEEDED == 3 and GoalStatus.LOST == 9
    pose = Pose(Point(4.589, -0.376, 0.0), Quaternion(0.0, 0.0, -0.447, 0.894))
    assert isinstance(pose, Pose) and pose.position.x == 4.589
    assert Twist()._type if hasattr(Twist(), "_type") else Twist._type == "geometry_msgs/Twist"
    goal = MoveBaseGoal()
    goal.target_pose.pose = pose
    goal.target_pose.header.frame_id = "map"
    assert MoveBaseAction._type == "move_base_msgs/MoveBaseAction"
    assert Empty._request_class is EmptyRequest and Empty._response_class is EmptyResponse
    assert serialize(EmptyRequest()) == b"\x00\x01\x00\x00\x00"
    assert actionlib.GoalStatus is GoalStatus
    q = tf.transformations.quaternion_from_euler(0.0, 0.0, 1.0)
    assert tf.transformations.euler_from_quaternion(q)[2] == pytest.approx(1.0)


def test_star_import_and_genpy_constructor_rules(ros1: Any) -> None:
    scope: dict[str, Any] = {}
    exec("from actionlib_msgs.msg import *", scope)
    assert {"GoalID", "GoalStatus", "GoalStatusArray"} <= set(scope)
    from geometry_msgs.msg import Point, Vector3  # type: ignore[import-not-found]
    from std_msgs.msg import Header  # type: ignore[import-not-found]

    with pytest.raises(TypeError, match="Invalid number of arguments"):
        Point(1.0, 2.0)
    with pytest.raises(TypeError, match="either positionally or by keyword"):
        Vector3(1.0, y=2.0)
    h = Header(7, ros1.Time(3, 5), "map")  # ROS 1's seq is dropped
    assert (h.stamp.secs, h.stamp.nsecs, h.frame_id, h.seq) == (3, 5, "map", 0)
    assert Point.__slots__ == ["x", "y", "z"] and Point._slot_types == ["float64"] * 3
    assert not Point._has_header and Header._type == "std_msgs/Header"
    with pytest.raises(ImportError):
        from geometry_msgs.msg import NoSuchThing  # type: ignore[import-not-found] # noqa: F401


def test_ros1_field_spellings(ros1: Any) -> None:
    from sensor_msgs.msg import CameraInfo  # type: ignore[import-not-found]

    info = CameraInfo()
    info.K = [500.0, 0, 320, 0, 500, 240, 0, 0, 1]
    assert list(info.k) == [500.0, 0, 320, 0, 500, 240, 0, 0, 1] and info.K[0] == 500.0


def test_time_and_duration(ros1: Any) -> None:
    Time, Duration = ros1.Time, ros1.Duration
    t = Time(10, 500_000_000)
    assert t.to_sec() == 10.5 and t.secs == 10 and t.nsecs == 500_000_000
    d = Time.from_sec(12.25) - t
    assert isinstance(d, Duration) and d.to_sec() == 1.75 and d.secs == 1
    assert (t + Duration(1)).to_sec() == 11.5 and (t - Duration.from_sec(0.5)).secs == 10
    neg = Duration.from_sec(-0.5)
    assert (neg.secs, neg.nsecs) == (-1, 500_000_000)
    assert Duration(2) * 1.5 == Duration(3) and Duration(3) / 2 == Duration.from_sec(1.5)
    assert Time(1) < Time(2) and Duration(1) > Duration(0) and Time(5) == mc.Time(5, 0)
    assert mc.Time(5, 0) == Time(5) and Time(0).is_zero()
    received = mc.Time(sec=100, nanosec=0)  # a stamp from a received message
    assert received.to_sec() == 100.0 and (Time(101) - received).to_sec() == 1.0
    assert {Time(1): "a"}[mc.Time(1, 0)] == "a"
    with pytest.raises(ros1.ROSInitException, match="init_node"):
        Time.now()
    with pytest.raises(ValueError):
        Time(-1)


def test_command_line_parsing() -> None:
    cl = parse_command_line(["x", "_rate:=10", "_name:=bob", "scan:=/base_scan", "__name:=t2"])
    assert cl.params == {"rate": 10, "name": "bob"} and cl.remaps == {"scan": "/base_scan"}
    assert cl.special == {"__name": "t2"} and cl.plain == ["x"]


def test_params(node: Any) -> None:
    rospy = node
    assert rospy.get_name() == "/tester"
    assert rospy.get_param("~speed", 0.3) == 0.7  # _speed:=0.7 wins
    assert rospy.get_param("~turn", 0.5) == 0.5
    assert rospy.get_param("~name_list") == ["a", "b"]
    # private parameters show as the node's parameters (roverlab param get /tester speed)
    assert RUNTIME.node is not None and RUNTIME.node.get_parameter_value("speed") == 0.7
    rospy.set_param("/global_thing", {"a": 1})
    assert rospy.get_param("global_thing") == {"a": 1} and rospy.has_param("/global_thing")
    assert rospy.search_param("global_thing") == "/global_thing"
    rospy.delete_param("/global_thing")
    assert not rospy.has_param("/global_thing")
    with pytest.raises(KeyError):
        rospy.get_param("/nothing/here")
    assert rospy.myargv(["s.py", "_a:=1", "file"]) == ["s.py", "file"]


def test_publish_subscribe_remap_and_wait_for_message(node: Any) -> None:
    rospy = node
    from std_msgs.msg import String  # type: ignore[import-not-found]

    got: list[tuple[str, str]] = []
    rospy.Subscriber("/talk", String, lambda m, tag: got.append((m.data, tag)), callback_args="t")
    pub = rospy.Publisher("chatter", String, queue_size=5)  # remapped to /talk
    assert pub.resolved_name == "/talk"
    rospy.sleep(0.05)
    pub.publish(String(data="hello"))
    pub.publish("world")  # fields given to publish
    msg = None
    for _ in range(200):
        if len(got) == 2:
            break
        rospy.sleep(0.01)
    assert got == [("hello", "t"), ("world", "t")]
    latched = rospy.Publisher("/latched", String, queue_size=1, latch=True)
    latched.publish("kept")
    msg = rospy.wait_for_message("/latched", String, timeout=2.0)
    assert msg.data == "kept"
    with pytest.raises(rospy.ROSException, match="timeout exceeded"):
        rospy.wait_for_message("/silent", String, timeout=0.1)


def test_publisher_before_init_node(ros1: Any) -> None:
    from geometry_msgs.msg import Twist  # type: ignore[import-not-found]

    pub = ros1.Publisher("cmd_vel", Twist, queue_size=1)  # keyboard.py does this
    with pytest.raises(ros1.ROSException, match="not been initialized"):
        pub.publish(Twist())
    ctx = Context(clock="wall", publish_clock=False)
    seen: list[Any] = []
    ctx.create_node("listener").create_subscription(
        "geometry_msgs/Twist", "/cmd_vel", seen.append, 10
    )
    RUNTIME.configure(ctx, [])
    ros1.init_node("teleop_twist_keyboard", disable_signals=True)
    twist = Twist()
    twist.linear.x = 0.3
    pub.publish(twist)
    ros1.sleep(0.1)
    assert [m.linear.x for m in seen] == [0.3]
    RUNTIME.signal_shutdown("done")
    ctx.shutdown()


def test_services(node: Any) -> None:
    rospy = node
    from rospy_tutorials.srv import AddTwoInts, AddTwoIntsResponse  # type: ignore[import-not-found]
    from std_srvs.srv import Trigger  # type: ignore[import-not-found]

    rospy.Service("add_two_ints", AddTwoInts, lambda req: AddTwoIntsResponse(req.a + req.b))
    rospy.Service("add_tuple", AddTwoInts, lambda req: (req.a * req.b,))
    rospy.Service("trigger", Trigger, lambda req: {"success": True, "message": "ok"})
    rospy.Service("broken", Trigger, lambda req: 1 / 0)
    rospy.wait_for_service("add_two_ints", timeout=1.0)
    add = rospy.ServiceProxy("add_two_ints", AddTwoInts)
    assert add(2, 3).sum == 5 and add(a=4, b=5).sum == 9
    assert rospy.ServiceProxy("add_tuple", AddTwoInts)(3, 4).sum == 12
    assert rospy.ServiceProxy("trigger", Trigger)().message == "ok"
    with pytest.raises(rospy.ServiceException, match="ZeroDivisionError"):
        rospy.ServiceProxy("broken", Trigger)()
    with pytest.raises(rospy.ROSException, match="timeout exceeded while waiting for service"):
        rospy.wait_for_service("/nobody", timeout=0.1)


def test_shutdown_hooks_run_before_is_shutdown(node: Any) -> None:
    rospy = node
    seen: list[bool] = []

    def hook() -> None:
        seen.append(rospy.is_shutdown())
        rospy.sleep(0.01)  # allowed: the node is not shut down yet

    rospy.on_shutdown(hook)
    rospy.signal_shutdown("because")
    assert seen == [False] and rospy.is_shutdown()
    with pytest.raises(rospy.ROSInterruptException):
        rospy.sleep(1.0)
    with pytest.raises(rospy.ROSInterruptException):
        rospy.Rate(10).sleep()
    rospy.spin()  # returns at once


def test_rate_follows_sim_time(ros1: Any) -> None:
    # Paced at 10x: 2 s of sim time take 0.2 s of wall time. Following wall time instead
    # would take 20 s of sim time, so a bound of 2.5 s still tells the two apart while
    # leaving 50 ms of wall time for the last wake-up on a loaded machine.
    ctx = Context(clock="paced", rate=10.0)
    RUNTIME.configure(ctx, [])
    ros1.init_node("looper", disable_signals=True)
    start = ros1.get_rostime().to_nsec()
    rate = ros1.Rate(10)
    woke = []
    for _ in range(20):
        rate.sleep()
        woke.append(ros1.get_rostime().to_nsec())
    # never early: the k-th sleep ends at or after start + k periods of sim time
    assert all(t >= start + (k + 1) * 100_000_000 for k, t in enumerate(woke))
    assert (woke[-1] - start) / 1e9 < 2.5  # 2 s of sim time, not 20
    RUNTIME.signal_shutdown("done")
    ctx.shutdown()


def test_rate_makes_up_a_late_wake_up(ros1: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """As rospy.Rate: a sleep that wakes 3 periods late is made up by the next calls
    returning at once, so the loop keeps its schedule (last + period), while a loop body
    slower than 2 periods restarts the schedule from the time of the call."""
    clock = [0]
    overslept = []

    def sleep_until(t_ns: int) -> None:
        if clock[0] < t_ns:
            late = 300_000_000 if not overslept else 0
            overslept.append(late)
            clock[0] = t_ns + late

    monkeypatch.setattr(RUNTIME, "now_ns", lambda: clock[0])
    monkeypatch.setattr(RUNTIME, "sleep_until", sleep_until)
    rate = ros1.Rate(10)
    woke = []
    for _ in range(6):
        rate.sleep()
        woke.append(clock[0])
    # woke at 0.4 (late), caught up at once through 0.2, 0.3, 0.4, then 0.5, 0.6 on time
    assert woke == [400_000_000] * 4 + [500_000_000, 600_000_000]
    clock[0] += 1_000_000_000  # a 1 s loop body: more than 2 periods behind
    rate.sleep()
    assert rate.last_ns == 1_600_000_000
    rate.sleep()
    assert clock[0] == 1_700_000_000


def test_user_message_package_from_the_package_path(
    ros1: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pkg = tmp_path / "ws" / "patrol_tools"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>patrol_tools</name></package>")
    (pkg / "msg" / "Place.msg").write_text("string name\nfloat64 x\nfloat64 y\n")
    monkeypatch.setenv("ROVERLAB_PACKAGE_PATH", str(tmp_path / "ws"))
    from patrol_tools.msg import Place  # type: ignore[import-not-found]

    place = Place("kitchen", 1.5, -2.0)
    assert place.name == "kitchen" and Place._type == "patrol_tools/Place"


def test_run_script_exit_codes(ros1: Any, tmp_path: Path) -> None:
    script = tmp_path / "talker.py"
    script.write_text(
        "import sys, rospy\n"
        "from std_msgs.msg import String\n"
        "rospy.init_node('talker', anonymous=True)\n"
        "assert rospy.get_name().startswith('/talker_')\n"
        "print('args', rospy.myargv(argv=sys.argv)[1:], rospy.get_param('~n'))\n"
        "sys.exit(3)\n"
    )
    ctx = Context(clock="wall", publish_clock=False)
    assert run_script(script, ["hello", "_n:=4"], ctx) == 3
    ctx.shutdown()
    broken = tmp_path / "broken.py"
    broken.write_text("raise RuntimeError('nope')\n")
    ctx = Context(clock="wall", publish_clock=False)
    assert run_script(broken, [], ctx) == 1
    ctx.shutdown()
    assert RUNTIME.node is None and "rospy" in sys.modules


def test_numpy_fields_take_lists(ros1: Any) -> None:
    from sensor_msgs.msg import LaserScan  # type: ignore[import-not-found]

    scan = LaserScan(ranges=[1.0, 2.0])
    assert scan.ranges.dtype == np.float32
