"""URDF parsing and check_urdf's validation: one error line naming the file and element."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from roverlab.description import (
    Box,
    Cylinder,
    JointType,
    Mesh,
    Sphere,
    URDFError,
    load_robot,
    parse_urdf,
    robot_description,
)
from tests.description.conftest import MYBOT_URDF, robot

LINK = '<link name="{}"/>'


def joint(name: str, parent: str, child: str, jtype: str = "fixed", extra: str = "") -> str:
    return (
        f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/>'
        f'<child link="{child}"/>{extra}</joint>'
    )


def links(*names: str) -> str:
    return "".join(LINK.format(n) for n in names)


BAD_CASES = {
    "bad_xml": ('<?xml version="1.0"?>\n<robot name="r">\n  <link name="a">\n</robot>\n', "line 4"),
    "no_robot": ('<?xml version="1.0"?>\n<model name="x"/>\n', "no <robot> element"),
    "no_name": ("<robot><link name='a'/></robot>", "<robot> has no name"),
    "no_links": (robot(""), "has no <link> elements"),
    "dangling_child": (
        robot(links("a") + joint("j1", "a", "ghost")),
        "<joint name='j1'>: child link 'ghost' is not defined",
    ),
    "dangling_parent": (
        robot(links("a") + joint("j1", "ghost", "a")),
        "<joint name='j1'>: parent link 'ghost' is not defined",
    ),
    "two_roots": (robot(links("a", "b")), "two root links found: 'a' and 'b'"),
    "cycle": (
        robot(
            links("root", "a", "b")
            + joint("j1", "root", "a")
            + joint("j2", "a", "b")
            + '<joint name="j3" type="fixed"><parent link="b"/><child link="root"/></joint>'
        ),
        "no root link found: the joints form a cycle",
    ),
    "detached_cycle": (
        robot(links("root", "a", "b") + joint("j1", "a", "b") + joint("j2", "b", "a")),
        "cycle through links 'a', 'b'",
    ),
    "self_parent": (robot(links("a") + joint("j1", "a", "a")), "is its own parent"),
    "two_parents": (
        robot(links("a", "b", "c") + joint("j1", "a", "c") + joint("j2", "b", "c")),
        "<joint name='j2'>: link 'c' already has parent joint 'j1'",
    ),
    "duplicate_link": (robot(links("a", "a")), "link name 'a' is not unique"),
    "duplicate_joint": (
        robot(links("a", "b", "c") + joint("j", "a", "b") + joint("j", "a", "c")),
        "joint name 'j' is not unique",
    ),
    "negative_box": (
        robot(
            '<link name="a"><visual><geometry><box size="0.1 -1 0.2"/></geometry></visual></link>'
        ),
        "<link name='a'>: <visual> #1: <geometry>: <box size='0.1 -1 0.2'>: negative size",
    ),
    "nan_radius": (
        robot(
            '<link name="a"><collision><geometry><cylinder radius="nan" length="1"/>'
            "</geometry></collision></link>"
        ),
        "<link name='a'>: <collision> #1: <geometry>: <cylinder radius='nan'>: NaN",
    ),
    "unknown_geometry": (
        robot('<link name="a"><visual><geometry><cone radius="1"/></geometry></visual></link>'),
        "<link name='a'>: <visual> #1: <geometry>: unknown geometry <cone>",
    ),
    "no_geometry": (
        robot('<link name="a"><visual><origin xyz="0 0 0"/></visual></link>'),
        "<link name='a'>: <visual> #1: no <geometry>",
    ),
    "bad_origin": (
        robot(links("a", "b") + joint("j", "a", "b", extra='<origin xyz="1 2"/>')),
        "<joint name='j'>: <origin xyz='1 2'>: expected 3 number(s)",
    ),
    "unknown_joint_type": (
        robot(links("a", "b") + joint("j", "a", "b", "hinge")),
        "<joint name='j'>: unknown joint type 'hinge'",
    ),
    "revolute_without_limit": (
        robot(links("a", "b") + joint("j", "a", "b", "revolute")),
        "<joint name='j'>: a revolute joint needs <limit",
    ),
    "zero_axis": (
        robot(links("a", "b") + joint("j", "a", "b", "continuous", '<axis xyz="0 0 0"/>')),
        "<joint name='j'>: <axis xyz='0 0 0'>: zero axis",
    ),
    "negative_mass": (
        robot(
            '<link name="a"><inertial><mass value="-1"/><inertia ixx="1" ixy="0" ixz="0" '
            'iyy="1" iyz="0" izz="1"/></inertial></link>'
        ),
        "<link name='a'>: <inertial>: <mass value='-1'>: negative mass",
    ),
    "mimic_unknown_joint": (
        robot(links("a", "b") + joint("j", "a", "b", "continuous", '<mimic joint="ghost"/>')),
        "<joint name='j'>: <mimic joint='ghost'> is not a joint",
    ),
    "sensor_on_missing_link": (
        robot(links("a") + '<gazebo reference="ghost"><sensor type="ray" name="lidar"/></gazebo>'),
        "<gazebo reference='ghost'>: <sensor name='lidar'> is on link 'ghost'",
    ),
    "diff_drive_missing_joint": (
        robot(
            links("a") + '<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">'
            "<leftJoint>lw</leftJoint></plugin></gazebo>"
        ),
        "<plugin name='dd' filename='libgazebo_ros_diff_drive.so'>: <leftJoint> 'lw' is not",
    ),
    "bad_plugin_number": (
        robot(
            links("a") + '<gazebo reference="a"><sensor type="ray" name="l"><ray><scan>'
            "<horizontal><samples>many</samples></horizontal></scan></ray></sensor></gazebo>"
        ),
        "<sensor name='l' type='ray'>: <ray>: <scan/horizontal/samples>: 'many' is not an integer",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_CASES))
def test_bad_input_is_one_line_naming_file_and_element(tmp_path: Path, case: str) -> None:
    text, expected = BAD_CASES[case]
    f = tmp_path / f"{case}.urdf"
    f.write_text(text)
    with pytest.raises(URDFError) as info:
        load_robot(f)
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith(f"{f}: "), msg
    assert expected in msg, msg


def test_error_for_an_xml_string_names_string() -> None:
    with pytest.raises(URDFError, match=r"^<string>: two root links"):
        load_robot(robot(links("a", "b")))


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(URDFError, match="cannot read"):
        load_robot(tmp_path / "absent.urdf")


def test_parse_mybot_urdf_values() -> None:
    m = load_robot(MYBOT_URDF)
    assert m.name == "mybot"
    assert list(m.links) == [
        "base_footprint",
        "base_link",
        "right_wheel_link",
        "left_wheel_link",
        "ball_wheel_link",
    ]
    base = m.links["base_link"]
    assert base.visuals[0].geometry == Box((0.25, 0.16, 0.05))
    assert base.visuals[0].material is not None
    assert base.visuals[0].material.rgba == (0.0, 0.0, 0.8, 1.0)
    assert base.inertial is not None
    assert base.inertial.mass == 0.1 and base.inertial.izz == 0.001
    assert m.links["right_wheel_link"].collisions[0].geometry == Cylinder(0.025, 0.02)
    assert m.links["ball_wheel_link"].visuals[0].geometry == Sphere(0.025)
    assert m.links["base_footprint"].visuals == ()
    wheel = m.joints["right_wheel_joint"]
    assert wheel.type is JointType.CONTINUOUS
    assert wheel.axis == (0.0, 0.0, -1.0)
    assert wheel.origin.translation == (0.1, -0.09, -0.03)
    assert set(m.materials) == {"blue", "black"}


def test_robot_level_material_wins_over_a_visual_colour() -> None:
    m = parse_urdf(
        robot(
            '<material name="paint"><color rgba="1 0 0 1"/></material>'
            '<link name="a"><visual><geometry><sphere radius="1"/></geometry>'
            '<material name="paint"><color rgba="0 1 0 1"/></material></visual></link>'
        )
    )
    material = m.links["a"].visuals[0].material
    assert material is not None and material.rgba == (1.0, 0.0, 0.0, 1.0)


def test_mesh_limits_mimic_dynamics_and_axis_normalisation() -> None:
    m = parse_urdf(
        robot(
            '<link name="a"><visual><geometry><mesh filename="package://p/m.dae" '
            'scale="2 2 2"/></geometry></visual></link>'
            + links("b", "c")
            + joint(
                "j1",
                "a",
                "b",
                "revolute",
                '<axis xyz="0 0 2"/><limit lower="-1" upper="1" effort="5" velocity="2"/>'
                '<dynamics damping="0.5"/>',
            )
            + joint(
                "j2",
                "a",
                "c",
                "revolute",
                '<limit effort="1" velocity="1"/><mimic joint="j1" multiplier="2" offset="0.1"/>',
            )
        )
    )
    assert m.links["a"].visuals[0].geometry == Mesh("package://p/m.dae", (2.0, 2.0, 2.0))
    j1 = m.joints["j1"]
    assert j1.axis == (0.0, 0.0, 1.0)
    assert j1.limit is not None and (j1.limit.lower, j1.limit.upper) == (-1.0, 1.0)
    assert j1.dynamics is not None and j1.dynamics.damping == 0.5
    assert m.joints["j2"].mimic is not None and m.joints["j2"].mimic.multiplier == 2.0


def test_transmissions_and_unknown_top_level_elements_are_ignored() -> None:
    m = parse_urdf(
        robot(links("a") + "<transmission name='t'><type>x</type></transmission><custom/>")
    )
    assert list(m.links) == ["a"]


def test_default_xml_namespace_is_accepted() -> None:
    m = parse_urdf('<robot name="r" xmlns="http://example.com/urdf"><link name="a"/></robot>')
    assert m.root_link == "a"


def test_robot_description_of_a_plain_urdf_is_the_file(tmp_path: Path) -> None:
    assert robot_description(MYBOT_URDF) == MYBOT_URDF.read_text()
    text = robot(links("a"))
    assert robot_description(text) == text
    assert load_robot(text).urdf == text


def test_origin_rpy_becomes_a_quaternion() -> None:
    m = parse_urdf(
        robot(
            links("a", "b") + joint("j", "a", "b", extra='<origin rpy="0 0 1.5707963267948966"/>')
        )
    )
    q = m.joints["j"].origin.rotation
    assert q[2] == pytest.approx(math.sin(math.pi / 4))
    assert q[3] == pytest.approx(math.cos(math.pi / 4))
