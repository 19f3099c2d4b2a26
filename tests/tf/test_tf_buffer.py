"""BufferCore: interpolation, chains, latest common time, errors, static data, pruning."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import yaml

from roverlab.core.time import Duration, Time
from roverlab.geometry import Transform3, quat_from_rpy, quat_from_yaw
from roverlab.tf import (
    BackwardExtrapolationException,
    Buffer,
    BufferCore,
    ConnectivityException,
    ExtrapolationException,
    ForwardExtrapolationException,
    InvalidArgumentException,
    LookupException,
    NoDataForExtrapolationException,
    TransformException,
)


def tf(x: float = 0.0, y: float = 0.0, z: float = 0.0, yaw: float = 0.0) -> Transform3:
    q = quat_from_yaw(yaw)
    return Transform3((x, y, z), (float(q[0]), float(q[1]), float(q[2]), float(q[3])))


def s(seconds: float) -> Time:
    return Time.from_seconds(seconds)


def assert_tf_close(a: Transform3, b: Transform3, tol: float = 1e-9) -> None:
    np.testing.assert_allclose(a.translation, b.translation, atol=tol)
    qa, qb = np.asarray(a.rotation), np.asarray(b.rotation)
    # q and -q are the same rotation
    assert min(np.abs(qa - qb).max(), np.abs(qa + qb).max()) < tol, (qa, qb)


@pytest.fixture
def robot() -> BufferCore:
    """map -> odom -> base_link -> laser, dynamic at 1..5 s, laser static."""
    buf = BufferCore()
    for k in range(1, 6):
        buf.set_transform("map", "odom", s(k), tf(x=0.1 * k), "amcl")
        buf.set_transform("odom", "base_link", s(k), tf(x=1.0 * k, yaw=0.2 * k), "diff_drive")
    buf.set_transform("base_link", "laser", s(0), tf(x=0.3, z=0.2), "rsp", is_static=True)
    return buf


# ------------------------------------------------------------------ interpolation
def test_translation_is_interpolated_linearly() -> None:
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(1.0), tf(x=0.0, y=4.0))
    buf.set_transform("odom", "base_link", s(2.0), tf(x=2.0, y=0.0))
    t, stamp = buf.lookup_transform("odom", "base_link", s(1.5))
    assert stamp == s(1.5)
    np.testing.assert_allclose(t.translation, (1.0, 2.0, 0.0), atol=1e-12)
    t, _ = buf.lookup_transform("odom", "base_link", s(1.25))
    np.testing.assert_allclose(t.translation, (0.5, 3.0, 0.0), atol=1e-12)


def test_rotation_is_slerped() -> None:
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(1.0), tf(yaw=0.0))
    buf.set_transform("odom", "base_link", s(2.0), tf(yaw=1.0))
    t, _ = buf.lookup_transform("odom", "base_link", s(1.5))
    assert t.yaw == pytest.approx(0.5, abs=1e-12)
    t, _ = buf.lookup_transform("odom", "base_link", s(1.75))
    assert t.yaw == pytest.approx(0.75, abs=1e-12)
    assert np.linalg.norm(t.rotation) == pytest.approx(1.0, abs=1e-12)


def test_rotation_interpolates_3d() -> None:
    buf = BufferCore()
    buf.set_transform("a", "b", s(1.0), Transform3.from_arrays((0, 0, 0), quat_from_rpy(0, 0, 0)))
    buf.set_transform("a", "b", s(2.0), Transform3.from_arrays((0, 0, 0), quat_from_rpy(0.4, 0, 0)))
    t, _ = buf.lookup_transform("a", "b", s(1.5))
    assert_tf_close(t, Transform3.from_arrays((0, 0, 0), quat_from_rpy(0.2, 0, 0)))


def test_yaw_interpolation_takes_the_short_way_across_pi() -> None:
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(1.0), tf(yaw=3.0))
    buf.set_transform("odom", "base_link", s(2.0), tf(yaw=-3.0))
    t, _ = buf.lookup_transform("odom", "base_link", s(1.5))
    # halfway on the short arc (through +-pi), not through 0
    assert abs(abs(t.yaw) - math.pi) < 1e-9
    t, _ = buf.lookup_transform("odom", "base_link", s(1.25))
    step = 2 * math.pi - 6.0
    assert t.yaw == pytest.approx(3.0 + 0.25 * step, abs=1e-9)
    t, _ = buf.lookup_transform("odom", "base_link", s(1.75))
    assert t.yaw == pytest.approx(-3.0 - 0.25 * step, abs=1e-9)


def test_exact_sample_times_return_the_samples() -> None:
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(1.0), tf(x=1.0))
    buf.set_transform("odom", "base_link", s(2.0), tf(x=5.0))
    assert buf.lookup_transform("odom", "base_link", s(1.0))[0].translation[0] == 1.0
    assert buf.lookup_transform("odom", "base_link", s(2.0))[0].translation[0] == 5.0


def test_out_of_order_data_is_sorted_and_same_stamp_replaces() -> None:
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(3.0), tf(x=3.0))
    buf.set_transform("odom", "base_link", s(1.0), tf(x=1.0))
    buf.set_transform("odom", "base_link", s(2.0), tf(x=9.0))
    buf.set_transform("odom", "base_link", s(2.0), tf(x=2.0))
    t, _ = buf.lookup_transform("odom", "base_link", s(1.5))
    assert t.translation[0] == pytest.approx(1.5)
    t, _ = buf.lookup_transform("odom", "base_link", s(2.5))
    assert t.translation[0] == pytest.approx(2.5)


# ------------------------------------------------------------------ chains
def test_chain_lookup_matches_manual_composition(robot: BufferCore) -> None:
    t, stamp = robot.lookup_transform("map", "laser", s(2.5))
    assert stamp == s(2.5)
    map_odom = tf(x=0.25)
    odom_base = tf(x=2.5, yaw=0.5)
    base_laser = tf(x=0.3, z=0.2)
    assert_tf_close(t, map_odom * odom_base * base_laser)
    # a point 1 m ahead of the laser, expressed in map
    p = t.apply(np.array([1.0, 0.0, 0.0]))
    c, sn = math.cos(0.5), math.sin(0.5)
    np.testing.assert_allclose(p, (0.25 + 2.5 + 1.3 * c, 1.3 * sn, 0.2), atol=1e-12)


def test_inverse_direction_is_the_inverse(robot: BufferCore) -> None:
    fwd, _ = robot.lookup_transform("map", "laser", s(3.2))
    back, _ = robot.lookup_transform("laser", "map", s(3.2))
    assert_tf_close(back, ~fwd)
    assert_tf_close(back * fwd, Transform3())


def test_lookup_between_siblings_goes_through_common_parent(robot: BufferCore) -> None:
    robot.set_transform("base_link", "imu", s(0), tf(y=0.1, yaw=math.pi), is_static=True)
    t, _ = robot.lookup_transform("laser", "imu", s(4.0))
    assert_tf_close(t, ~tf(x=0.3, z=0.2) * tf(y=0.1, yaw=math.pi))


def test_direct_parent_and_child_lookups(robot: BufferCore) -> None:
    t, _ = robot.lookup_transform("odom", "base_link", s(2.0))
    assert_tf_close(t, tf(x=2.0, yaw=0.4))
    t, _ = robot.lookup_transform("base_link", "odom", s(2.0))
    assert_tf_close(t, ~tf(x=2.0, yaw=0.4))


def test_same_frame_is_identity(robot: BufferCore) -> None:
    t, stamp = robot.lookup_transform("odom", "odom", s(7.0))
    assert t == Transform3() and stamp == s(7.0)
    # Time(0): the latest stamp of that frame's own data, as tf2
    _, stamp = robot.lookup_transform("base_link", "base_link", Time(0))
    assert stamp == s(5.0)


def test_leading_slash_is_stripped_on_input() -> None:
    buf = BufferCore()
    buf.set_transform("/odom", "/base_link", s(1.0), tf(x=1.0))
    assert buf.frames() == ["base_link", "odom"]
    assert buf.lookup_transform("odom", "base_link", s(1.0))[0].translation[0] == 1.0


def test_lookup_transform_full_uses_a_fixed_frame(robot: BufferCore) -> None:
    # where was the laser at t=2 as seen from the laser at t=4, odom assumed fixed
    t, stamp = robot.lookup_transform_full("laser", s(4.0), "laser", s(2.0), "odom")
    assert stamp == s(4.0)
    odom_laser_2 = tf(x=2.0, yaw=0.4) * tf(x=0.3, z=0.2)
    odom_laser_4 = tf(x=4.0, yaw=0.8) * tf(x=0.3, z=0.2)
    assert_tf_close(t, ~odom_laser_4 * odom_laser_2)
    assert robot.can_transform_full("laser", s(4.0), "laser", s(2.0), "odom")
    assert not robot.can_transform_full("laser", s(9.0), "laser", s(2.0), "odom")
    with pytest.raises(LookupException, match="fixed_frame"):
        robot.lookup_transform_full("laser", s(4.0), "laser", s(2.0), "nowhere")


# ------------------------------------------------------------------ Time(0)
def test_time_zero_uses_latest_common_time() -> None:
    buf = BufferCore()
    for k in range(1, 6):
        buf.set_transform("map", "odom", s(k), tf(x=float(k)))
    for k in range(1, 4):
        buf.set_transform("odom", "base_link", s(k), tf(y=float(k)))
    buf.set_transform("base_link", "laser", s(0), tf(z=1.0), is_static=True)
    t, stamp = buf.lookup_transform("map", "laser", Time(0))
    assert stamp == s(3.0)
    np.testing.assert_allclose(t.translation, (3.0, 3.0, 1.0))
    assert buf.get_latest_common_time("map", "laser") == s(3.0)
    # only the edges between the two frames count
    assert buf.get_latest_common_time("map", "odom") == s(5.0)
    _, stamp = buf.lookup_transform("odom", "map", Time(0))
    assert stamp == s(5.0)


def test_time_zero_on_an_all_static_chain_is_zero() -> None:
    buf = BufferCore()
    buf.set_transform("base_link", "laser", s(5), tf(x=1.0), is_static=True)
    buf.set_transform("laser", "optical", s(5), tf(y=1.0), is_static=True)
    t, stamp = buf.lookup_transform("base_link", "optical", Time(0))
    assert stamp == Time(0)
    np.testing.assert_allclose(t.translation, (1.0, 1.0, 0.0))


def test_time_zero_through_a_sibling_branch() -> None:
    buf = BufferCore()
    for k in range(1, 6):
        buf.set_transform("odom", "base_link", s(k), tf(x=float(k)))
    for k in range(2, 5):
        buf.set_transform("odom", "marker", s(k), tf(y=float(k)))
    _, stamp = buf.lookup_transform("marker", "base_link", Time(0))
    assert stamp == s(4.0)


# ------------------------------------------------------------------ errors
def test_unknown_frame_raises_lookup_exception(robot: BufferCore) -> None:
    with pytest.raises(LookupException) as info:
        robot.lookup_transform("map", "gripper", s(2.0))
    assert '"gripper" passed to lookupTransform argument source_frame does not exist' in str(
        info.value
    )
    with pytest.raises(LookupException, match="target_frame"):
        robot.lookup_transform("world", "map", Time(0))
    assert not robot.can_transform("map", "gripper", s(2.0))
    assert isinstance(info.value, TransformException)


def test_disconnected_trees_raise_connectivity_exception(robot: BufferCore) -> None:
    robot.set_transform("world", "table", s(2.0), tf(x=1.0))
    for time in (s(2.0), Time(0)):
        with pytest.raises(ConnectivityException) as info:
            robot.lookup_transform("table", "laser", time)
        assert "Could not find a connection between 'table' and 'laser'" in str(info.value)
    assert not robot.can_transform("table", "laser", s(2.0))


def test_future_extrapolation_message_names_side_times_and_frames(robot: BufferCore) -> None:
    with pytest.raises(ExtrapolationException) as info:
        robot.lookup_transform("odom", "laser", s(7.5))
    assert isinstance(info.value, ForwardExtrapolationException)
    assert str(info.value) == (
        "Lookup would require extrapolation into the future.  Requested time 7.500000 but the "
        "latest data is at time 5.000000, when looking up transform from frame [laser] to "
        "frame [odom]"
    )


def test_past_extrapolation_beyond_the_cache() -> None:
    buf = BufferCore(cache_time=Duration.from_seconds(10.0))
    for k in range(0, 21):
        buf.set_transform("odom", "base_link", s(k), tf(x=float(k)))
    with pytest.raises(BackwardExtrapolationException) as info:
        buf.lookup_transform("base_link", "odom", s(5.0))
    msg = str(info.value)
    assert "extrapolation into the past" in msg
    assert "Requested time 5.000000 but the earliest data is at time 10.000000" in msg
    assert msg.endswith("from frame [odom] to frame [base_link]")
    assert buf.can_transform("base_link", "odom", s(10.0))
    assert not buf.can_transform("base_link", "odom", s(9.99))


def test_extrapolation_on_the_target_side(robot: BufferCore) -> None:
    robot.set_transform("map", "goal", s(1.0), tf(x=1.0), is_static=True)
    with pytest.raises(ForwardExtrapolationException, match=r"from frame \[goal\] to frame"):
        robot.lookup_transform("base_link", "goal", s(9.0))


def test_single_sample_only_matches_its_own_stamp() -> None:
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(2.0), tf(x=1.0))
    assert buf.can_transform("odom", "base_link", s(2.0))
    with pytest.raises(NoDataForExtrapolationException, match=r"but only time 2\.000000"):
        buf.lookup_transform("odom", "base_link", s(2.5))


def test_invalid_transforms_are_rejected_and_not_stored() -> None:
    buf = BufferCore()
    nan = float("nan")
    with pytest.raises(InvalidArgumentException, match="TF_NAN_INPUT"):
        buf.set_transform("odom", "base_link", s(1.0), tf(x=nan))
    with pytest.raises(InvalidArgumentException, match="TF_NAN_INPUT"):
        buf.set_transform("odom", "base_link", s(1.0), Transform3((0, 0, 0), (0, 0, nan, 1)))
    with pytest.raises(InvalidArgumentException, match="TF_SELF_TRANSFORM"):
        buf.set_transform("odom", "/odom", s(1.0), tf())
    with pytest.raises(InvalidArgumentException, match="TF_NO_CHILD_FRAME_ID"):
        buf.set_transform("odom", "", s(1.0), tf())
    with pytest.raises(InvalidArgumentException, match="TF_NO_FRAME_ID"):
        buf.set_transform("", "base_link", s(1.0), tf())
    with pytest.raises(InvalidArgumentException, match="TF_DENORMALIZED_QUATERNION"):
        buf.set_transform("odom", "base_link", s(1.0), Transform3((0, 0, 0), (0, 0, 0, 2)))
    assert buf.frames() == []


def test_quaternion_slightly_off_unit_is_normalised() -> None:
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(1.0), Transform3((0, 0, 0), (0, 0, 0, 1.001)))
    t, _ = buf.lookup_transform("odom", "base_link", s(1.0))
    assert t.rotation == (0.0, 0.0, 0.0, 1.0)


def test_invalid_lookup_arguments(robot: BufferCore) -> None:
    with pytest.raises(InvalidArgumentException, match="cannot start with a '/'"):
        robot.lookup_transform("/map", "laser", Time(0))
    with pytest.raises(InvalidArgumentException, match="cannot be empty"):
        robot.lookup_transform("map", "", Time(0))
    with pytest.raises(InvalidArgumentException):
        BufferCore(cache_time=0.0)


def test_a_loop_in_the_tree_raises_instead_of_hanging() -> None:
    buf = BufferCore()
    buf.set_transform("a", "b", s(1.0), tf(x=1.0))
    buf.set_transform("b", "a", s(1.0), tf(x=1.0))
    buf.set_transform("a", "c", s(1.0), tf(x=1.0))
    buf.set_transform("root", "d", s(1.0), tf(x=1.0))
    for time in (s(1.0), Time(0)):
        with pytest.raises(LookupException, match="contains a loop"):
            buf.lookup_transform("d", "c", time)
    assert "frames in a loop" in buf.tree_as_text()


# ------------------------------------------------------------------ static data
def test_static_transforms_are_valid_at_any_time() -> None:
    buf = BufferCore()
    buf.set_transform("base_link", "laser", s(100.0), tf(x=0.2), is_static=True)
    for time in (s(0.001), s(100.0), s(1e6), Time(0)):
        t, stamp = buf.lookup_transform("base_link", "laser", time)
        assert t.translation[0] == 0.2
        assert stamp == time
    # a new static transform replaces the old one
    buf.set_transform("base_link", "laser", s(0.0), tf(x=0.5), is_static=True)
    assert buf.lookup_transform("laser", "base_link", s(3.0))[0].translation[0] == -0.5


def test_static_and_dynamic_data_replace_each_other() -> None:
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(1.0), tf(x=1.0))
    buf.set_transform("odom", "base_link", s(0.0), tf(x=7.0), is_static=True)
    assert buf.lookup_transform("odom", "base_link", s(50.0))[0].translation[0] == 7.0
    buf.set_transform("odom", "base_link", s(2.0), tf(x=2.0))
    assert not buf.can_transform("odom", "base_link", s(50.0))


def test_clear_drops_dynamic_data_but_keeps_static(robot: BufferCore) -> None:
    robot.clear()
    assert not robot.can_transform("map", "base_link", s(3.0))
    with pytest.raises(ExtrapolationException, match="no data for frame"):
        robot.lookup_transform("odom", "base_link", s(3.0))
    assert robot.lookup_transform("base_link", "laser", s(3.0))[0].translation[0] == 0.3
    assert set(robot.frames()) == {"map", "odom", "base_link", "laser"}
    robot.set_transform("odom", "base_link", s(9.0), tf(x=9.0))
    assert robot.lookup_transform("odom", "laser", Time(0))[1] == s(9.0)


# ------------------------------------------------------------------ pruning
def test_cache_keeps_only_cache_time_behind_newest() -> None:
    buf = BufferCore(cache_time=Duration.from_seconds(1.0))
    for k in range(0, 51):
        buf.set_transform("odom", "base_link", s(k * 0.1), tf(x=k * 0.1))
    assert buf.can_transform("odom", "base_link", s(4.0))
    assert buf.can_transform("odom", "base_link", s(4.05))
    assert not buf.can_transform("odom", "base_link", s(3.95))
    info = yaml.safe_load(buf.all_frames_as_yaml())["base_link"]
    assert info["oldest_transform"] == pytest.approx(4.0)
    assert info["most_recent_transform"] == pytest.approx(5.0)
    assert info["buffer_length"] == pytest.approx(1.0)
    assert info["rate"] == pytest.approx(11.0)  # 11 samples over 1 s, as tf2 computes it


def test_data_older_than_the_cache_is_refused() -> None:
    buf = BufferCore(cache_time=2.0)
    assert buf.set_transform("odom", "base_link", s(10.0), tf(x=10.0))
    assert not buf.set_transform("odom", "base_link", s(7.0), tf(x=7.0))
    assert buf.set_transform("odom", "base_link", s(8.5), tf(x=8.5))
    assert buf.lookup_transform("odom", "base_link", s(9.25))[0].translation[0] == pytest.approx(
        9.25
    )


# ------------------------------------------------------------------ re-parenting
def test_reparenting_the_latest_parent_wins() -> None:
    buf = BufferCore()
    buf.set_transform("base_link", "tool", s(1.0), tf(x=1.0))
    buf.set_transform("base_link", "arm", s(1.0), tf(y=1.0), is_static=True)
    buf.set_transform("arm", "tool", s(2.0), tf(z=1.0))
    # at t=2 and for Time(0) the tool hangs from arm
    t, _ = buf.lookup_transform("base_link", "tool", s(2.0))
    np.testing.assert_allclose(t.translation, (0.0, 1.0, 1.0))
    t, stamp = buf.lookup_transform("base_link", "tool", Time(0))
    np.testing.assert_allclose(t.translation, (0.0, 1.0, 1.0))
    assert stamp == s(2.0)
    # at t=1 (and between the samples: the older one, as tf2) it still hangs from base_link
    t, _ = buf.lookup_transform("base_link", "tool", s(1.0))
    np.testing.assert_allclose(t.translation, (1.0, 0.0, 0.0))
    t, _ = buf.lookup_transform("base_link", "tool", s(1.5))
    np.testing.assert_allclose(t.translation, (1.0, 0.0, 0.0))
    assert "Frame tool exists with parent arm." in buf.all_frames_as_string()


# ------------------------------------------------------------------ introspection
def test_all_frames_as_string(robot: BufferCore) -> None:
    assert robot.all_frames_as_string() == (
        "Frame odom exists with parent map.\n"
        "Frame base_link exists with parent odom.\n"
        "Frame laser exists with parent base_link.\n"
    )
    assert robot.frames() == ["odom", "map", "base_link", "laser"]
    assert robot.has_frame("map") and not robot.has_frame("gripper")


def test_all_frames_as_yaml(robot: BufferCore) -> None:
    text = robot.all_frames_as_yaml(s(6.0))
    data = yaml.safe_load(text)
    assert set(data) == {"odom", "base_link", "laser"}
    assert data["odom"] == {
        "parent": "map",
        "broadcaster": "amcl",
        "rate": pytest.approx(1.25),
        "most_recent_transform": 5.0,
        "oldest_transform": 1.0,
        "transform_delay": 1.0,
        "buffer_length": 4.0,
    }
    assert data["laser"]["rate"] == 10000.0  # tf2's figure for static data
    assert data["laser"]["broadcaster"] == "rsp"
    assert "base_link: \n  parent: 'odom'\n  broadcaster: 'diff_drive'\n" in text
    assert BufferCore().all_frames_as_yaml() == "[]"


def test_tree_as_text_shows_the_tree(robot: BufferCore) -> None:
    robot.set_transform("base_link", "imu", s(0), tf(), "rsp", is_static=True)
    robot.set_transform("world", "table", s(1.0), tf(), "sim")
    text = robot.tree_as_text()
    lines = text.splitlines()
    assert lines[0] == "map"
    assert lines[1].startswith("└── odom  [broadcaster: amcl, rate: 1.250 Hz")
    assert lines[2].startswith("    └── base_link  [broadcaster: diff_drive")
    assert lines[3] == "        ├── imu  [static, broadcaster: rsp]"
    assert lines[4] == "        └── laser  [static, broadcaster: rsp]"
    assert lines[5] == "world"
    assert lines[6].startswith("└── table  [broadcaster: sim")
    assert BufferCore().tree_as_text() == "no tf data received\n"


def test_a_lookup_repeated_at_a_stamp_sees_data_that_arrived_in_between() -> None:
    """Lookups are remembered per (target, source, stamp) only until the data changes."""
    buf = BufferCore()
    buf.set_transform("odom", "base_link", s(1.0), tf(x=0.0))
    buf.set_transform("odom", "base_link", s(3.0), tf(x=2.0))
    first, _ = buf.lookup_transform("odom", "base_link", s(2.0))
    again, _ = buf.lookup_transform("odom", "base_link", s(2.0))
    assert (
        first.translation[0] == pytest.approx(1.0) and again.translation[0] == first.translation[0]
    )
    buf.set_transform("odom", "base_link", s(2.0), tf(x=5.0))  # late data at that stamp
    assert buf.lookup_transform("odom", "base_link", s(2.0))[0].translation[0] == 5.0
    buf.clear()
    with pytest.raises(TransformException):
        buf.lookup_transform("odom", "base_link", s(2.0))


class _Walking(BufferCore):
    """The plain version: every lookup walks the tree (nothing remembered)."""

    def _lookup_pose(self, target: str, source: str, t_ns: int) -> tuple[Any, int]:
        return self._lookup_pose_at(target, source, t_ns)


def test_a_latest_lookup_is_remembered_only_until_the_data_changes() -> None:
    """``Time(0)`` lookups are remembered per (target, source) like stamped ones: always
    the answer of a buffer that walks the tree every time; new data and ``clear`` are seen."""
    buf, plain = Buffer(), _Walking()

    def both(parent: str, child: str, t: float, x: float, *, is_static: bool = False) -> None:
        for b in (buf, plain):
            b.set_transform(parent, child, s(t), tf(x=x, yaw=x), is_static=is_static)

    def check() -> None:
        want = plain.lookup_transform("map", "laser", Time())
        assert buf.lookup_transform("map", "laser", Time()) == want
        assert buf.lookup_transform("map", "laser", Time()) == want  # remembered
        assert buf.lookup_transform("odom", "laser", s(1.0)) == plain.lookup_transform(
            "odom", "laser", s(1.0)
        )

    both("base_link", "laser", 0.0, 0.3, is_static=True)
    both("map", "odom", 1.0, 0.0)
    both("odom", "base_link", 1.0, 1.0)
    check()
    both("odom", "base_link", 2.0, 2.0)  # newer data: the latest common time is still 1 s
    check()
    both("map", "odom", 2.0, 0.5)  # now 2 s
    check()
    assert buf.lookup_transform("map", "laser", Time())[1] == s(2.0)
    buf.clear()
    with pytest.raises(TransformException):
        buf.lookup_transform("map", "laser", Time())


def test_buffer_lookup_without_timeout_matches_the_waiting_path() -> None:
    """The no-timeout lookup (no closure) gives what the waiting path gives, errors too."""
    buf = Buffer()
    buf.set_transform("odom", "base_link", s(1.0), tf(x=1.0, yaw=0.2))
    buf.set_transform("odom", "base_link", s(2.0), tf(x=2.0, yaw=0.4))
    for t in (s(1.5), s(2.0), Time()):
        fast = buf.lookup_transform("odom", "base_link", t)
        slow = buf.lookup_transform("odom", "base_link", t, Duration(0))
        assert fast == slow
    for timeout in (0.0, Duration(0)):
        with pytest.raises(ExtrapolationException) as err:
            buf.lookup_transform("odom", "base_link", s(3.0), timeout)
        assert "extrapolation into the future" in str(err.value).lower()
