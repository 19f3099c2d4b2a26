"""Service and action types, bundled and user interface files."""

from __future__ import annotations

from pathlib import Path

import pytest

from roverlab.msgs import (
    UnknownTypeError,
    action_typenames,
    deserialize,
    get_action_type,
    get_service_type,
    message_definition,
    register_action,
    register_interface_file,
    register_package_interfaces,
    serialize,
    service_typenames,
    to_dict,
)


@pytest.mark.parametrize("name", ["std_srvs/srv/Empty", "std_srvs/Empty", "std_srvs.srv.Empty"])
def test_service_type_spellings(name: str) -> None:
    srv = get_service_type(name)
    assert srv.typename == "std_srvs/srv/Empty"
    assert srv.Request.typename == "std_srvs/srv/Empty_Request"
    assert srv.Response.typename == "std_srvs/srv/Empty_Response"
    assert get_service_type(srv) is srv


def test_bundled_services_and_their_fields() -> None:
    names = service_typenames()
    for needed in (
        "std_srvs/srv/Empty",
        "std_srvs/srv/Trigger",
        "std_srvs/srv/SetBool",
        "nav_msgs/srv/GetMap",
        "nav_msgs/srv/GetPlan",
        "nav_msgs/srv/SetMap",
        "nav_msgs/srv/LoadMap",
    ):
        assert needed in names
    plan = get_service_type("nav_msgs/GetPlan")
    req = plan.Request(tolerance=0.5, goal_header_frame_id="map")
    assert req.goal.header.frame_id == "map"
    assert list(to_dict(plan.Response())) == ["plan"]
    assert get_service_type("nav_msgs/LoadMap").Response.RESULT_MAP_DOES_NOT_EXIST == 1
    assert to_dict(get_service_type("std_srvs/SetBool").Response()) == {
        "success": False,
        "message": "",
    }


def test_empty_request_has_ros2_placeholder_bytes() -> None:
    # rclpy serialises an empty structure as one uint8: the same bytes here
    empty = get_service_type("std_srvs/Empty")
    data = serialize(empty.Request())
    assert data == b"\x00\x01\x00\x00\x00"
    assert to_dict(deserialize(data, empty.Request.typename)) == {}


@pytest.mark.parametrize(
    "name",
    [
        "move_base_msgs/action/MoveBase",
        "move_base_msgs/MoveBaseAction",
        "move_base_msgs/MoveBase",
        "move_base_msgs.msg.MoveBaseAction",
    ],
)
def test_action_type_spellings(name: str) -> None:
    action = get_action_type(name)
    assert action.typename == "move_base_msgs/action/MoveBase"
    assert action.ros1_name == "move_base_msgs/MoveBaseAction"
    assert get_action_type(action.Action) is action


def test_actionlib_messages_are_genactions() -> None:
    mb = get_action_type("move_base_msgs/MoveBaseAction")
    assert list(to_dict(mb.ActionGoal())) == ["header", "goal_id", "goal"]
    assert list(to_dict(mb.ActionResult())) == ["header", "status", "result"]
    assert list(to_dict(mb.ActionFeedback())) == ["header", "status", "feedback"]
    assert list(to_dict(mb.Action())) == ["action_goal", "action_result", "action_feedback"]
    assert list(to_dict(mb.Goal())) == ["target_pose"]
    assert list(to_dict(mb.Feedback())) == ["base_position"]
    assert to_dict(mb.Result()) == {}
    assert mb.ActionGoal.cls.__dataclass_fields__["goal_id"].type == "actionlib_msgs__msg__GoalID"
    text = message_definition("move_base_msgs/msg/MoveBaseActionGoal")
    assert "actionlib_msgs/GoalID goal_id" in text
    goal = mb.ActionGoal(goal_id_id="g1", goal_target_pose_pose_position_x=1.5)
    back = deserialize(serialize(goal), mb.ActionGoal.typename)
    assert back.goal_id.id == "g1" and back.goal.target_pose.pose.position.x == 1.5
    assert "move_base_msgs/action/MoveBase" in action_typenames()


def test_unknown_and_malformed() -> None:
    with pytest.raises(UnknownTypeError, match=r"unknown service type 'std_srvs/Emty'"):
        get_service_type("std_srvs/Emty")
    with pytest.raises(UnknownTypeError, match="not a srv type name"):
        get_service_type("a/b/c/d")
    with pytest.raises(UnknownTypeError, match="unknown action type"):
        get_action_type("move_base_msgs/NoSuchAction")
    with pytest.raises(UnknownTypeError, match="expected 2 '---' separator line"):
        register_action("my_actions/Bad", "int32 a\n---\nint32 b")


def test_user_package_files(tmp_path: Path) -> None:
    pkg = tmp_path / "patrol_msgs"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "srv").mkdir()
    (pkg / "action").mkdir()
    # Waypoint uses Place, which sorts after it: the loader retries in dependency order
    (pkg / "msg" / "Waypoint.msg").write_text("Place place\nfloat64 dwell_s\n")
    (pkg / "msg" / "Place.msg").write_text("string name\ngeometry_msgs/Pose pose\nuint8 HOME=1\n")
    (pkg / "srv" / "NextPlace.srv").write_text("string after\n---\nWaypoint next\n")
    (pkg / "action" / "Patrol.action").write_text(
        "Waypoint[] route\n---\nuint32 done\n---\nuint32 at\n"
    )
    (pkg / "srv" / "notes.txt").write_text("not an interface")
    names = register_package_interfaces(pkg, "patrol_msgs")
    assert set(names) == {
        "patrol_msgs/msg/Place",
        "patrol_msgs/msg/Waypoint",
        "patrol_msgs/srv/NextPlace",
        "patrol_msgs/action/Patrol",
    }
    srv = get_service_type("patrol_msgs/NextPlace")
    resp = srv.Response(next_place_name="kitchen")
    assert deserialize(serialize(resp), srv.Response.typename).next.place.name == "kitchen"
    patrol = get_action_type("patrol_msgs/PatrolAction")
    assert patrol.Feedback(at=3).at == 3
    bad = tmp_path / "broken_msgs" / "msg" / "Bad.msg"
    bad.parent.mkdir(parents=True)
    bad.write_text("NoSuchType x\n")
    with pytest.raises(UnknownTypeError, match=r"Bad\.msg: type broken_msgs/msg/Bad: field 'x'"):
        register_interface_file(bad)
