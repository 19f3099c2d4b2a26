"""Tree helpers and link transforms of RobotModel."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from roverlab.description import Joint, JointType, Link, RobotModel, URDFError, load_robot
from roverlab.geometry import Transform3
from tests.description.conftest import MYCAR_XACRO, robot

ARM = robot(
    """
<link name="base"/><link name="upper"/><link name="lower"/><link name="slider"/>
<link name="follower"/><link name="tool"/>
<joint name="shoulder" type="revolute">
  <parent link="base"/><child link="upper"/>
  <origin xyz="0 0 1"/><axis xyz="0 0 1"/>
  <limit lower="-3" upper="3" effort="1" velocity="1"/>
</joint>
<joint name="elbow" type="continuous">
  <parent link="upper"/><child link="lower"/>
  <origin xyz="1 0 0"/><axis xyz="0 1 0"/>
</joint>
<joint name="slide" type="prismatic">
  <parent link="lower"/><child link="slider"/>
  <origin xyz="0 0 0" rpy="0 0 1.5707963267948966"/><axis xyz="1 0 0"/>
  <limit lower="0" upper="0.5" effort="1" velocity="1"/>
</joint>
<joint name="mimic" type="continuous">
  <parent link="base"/><child link="follower"/>
  <axis xyz="0 0 1"/><mimic joint="shoulder" multiplier="-2" offset="0.5"/>
</joint>
<joint name="tool_mount" type="fixed">
  <parent link="slider"/><child link="tool"/><origin xyz="0 0 0.1"/>
</joint>
""",
    "arm",
)


def test_tree_helpers() -> None:
    m = load_robot(ARM)
    assert m.root_link == "base"
    assert m.children("base") == ("upper", "follower")
    assert m.children("tool") == ()
    assert m.parent_joint("base") is None
    parent = m.parent_joint("lower")
    assert parent is not None and parent.name == "elbow"
    assert [j.name for j in m.chain("tool")] == ["shoulder", "elbow", "slide", "tool_mount"]
    assert [j.name for j in m.chain("tool", root="lower")] == ["slide", "tool_mount"]
    assert [j.name for j in m.movable_joints] == ["shoulder", "elbow", "slide", "mimic"]
    assert [j.name for j in m.fixed_joints] == ["tool_mount"]
    with pytest.raises(KeyError, match="not an ancestor"):
        m.chain("upper", root="tool")
    with pytest.raises(KeyError, match="no link 'nope'"):
        m.children("nope")


def test_link_transform_at_zero() -> None:
    m = load_robot(ARM)
    t = m.link_transform("tool")
    assert t.translation == pytest.approx((1.0, 0.0, 1.1))
    assert m.link_transform("base") == Transform3()


def test_revolute_rotates_about_its_axis() -> None:
    m = load_robot(ARM)
    t = m.link_transform("lower", {"shoulder": math.pi / 2})
    assert t.translation == pytest.approx((0.0, 1.0, 1.0), abs=1e-12)
    assert t.yaw == pytest.approx(math.pi / 2)
    # elbow about y by +90 deg turns the lower link's x axis to -z
    t = m.link_transform("lower", {"elbow": math.pi / 2})
    assert t.apply([1.0, 0.0, 0.0]) == pytest.approx([1.0, 0.0, 0.0], abs=1e-12)
    assert t.apply([0.0, 0.0, 1.0]) == pytest.approx([2.0, 0.0, 1.0], abs=1e-12)


def test_prismatic_slides_along_its_axis_in_the_joint_frame() -> None:
    m = load_robot(ARM)
    # the slide frame is yawed 90 deg, so sliding along its x moves along the parent's y
    t = m.link_transform("slider", {"slide": 0.3})
    assert t.translation == pytest.approx((1.0, 0.3, 1.0), abs=1e-12)
    assert m.link_transform("tool", {"slide": 0.3}, root="lower").translation == pytest.approx(
        (0.0, 0.3, 0.1), abs=1e-12
    )


def test_mimic_joint_follows() -> None:
    m = load_robot(ARM)
    assert m.joint_position("mimic", {"shoulder": 0.25}) == pytest.approx(0.0)
    t = m.link_transform("follower", {"shoulder": 1.0, "mimic": 99.0})
    assert t.yaw == pytest.approx(-1.5)


def test_link_transforms_agree_with_link_transform() -> None:
    m = load_robot(ARM)
    q = {"shoulder": 0.3, "elbow": -0.7, "slide": 0.2}
    all_links = m.link_transforms(q)
    assert set(all_links) == set(m.links)
    for name, t in all_links.items():
        one = m.link_transform(name, q)
        assert np.allclose(t.translation, one.translation)
        assert np.allclose(t.rotation, one.rotation)


def test_mycar_laser_height_as_the_xacro_computes() -> None:
    m = load_robot(MYCAR_XACRO)
    earth_space, base_length, support_length, laser_length = 0.015, 0.08, 0.15, 0.05
    footprint_to_base = earth_space + base_length / 2  # 0.015 + 0.04
    base_to_support = base_length / 2 + support_length / 2  # 0.04 + 0.075
    support_to_laser = support_length / 2 + laser_length / 2  # 0.075 + 0.025
    expected = footprint_to_base + base_to_support + support_to_laser
    assert m.link_transform("laser").translation == pytest.approx((0.0, 0.0, expected))
    assert expected == pytest.approx(0.27)
    # wheels touch the ground: wheel centre at the wheel radius above base_footprint
    assert m.link_transform("left_wheel").translation == pytest.approx((0.0, 0.1, 0.0325))
    assert m.link_transform("front_wheel").translation[2] == pytest.approx(0.0075)


def test_model_is_frozen_and_validates_on_construction() -> None:
    m = load_robot(ARM)
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.name = "other"  # type: ignore[misc]
    with pytest.raises(TypeError):
        m.links["x"] = Link("x")  # type: ignore[index]
    with pytest.raises(URDFError, match="two root links"):
        RobotModel(name="r", links={"a": Link("a"), "b": Link("b")}, joints={}, source="mem")
    ok = RobotModel(
        name="r",
        links={"a": Link("a"), "b": Link("b")},
        joints={"j": Joint("j", JointType.FIXED, "a", "b", Transform3((1.0, 0.0, 0.0)))},
    )
    assert ok.link_transform("b").translation == (1.0, 0.0, 0.0)
