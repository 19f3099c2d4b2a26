"""ROS 1 xacro forms: un-prefixed tags and macro calls (with ROS 1's warning), --xacro-ns,
$(find)/$(arg)/$(env)/$(optenv), and the book-style test package's robots."""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from roverlab.description import DescriptionError, PackagePath, XacroError, load_robot, xacro_string
from roverlab.description.xacro_hook import ROS1_DEPRECATION

PKGS = Path(__file__).resolve().parents[1] / "ros1_packages"
BOOK = PKGS / "book_robot_description" / "urdf"


def _links(xml_text: str) -> list[str]:
    return [e.get("name", "") for e in ET.fromstring(xml_text).iter("link")]


def _doc(body: str) -> str:
    return f'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">{body}</robot>'


def test_unprefixed_macro_call_expands_with_ros1_warning(caplog: pytest.LogCaptureFixture) -> None:
    text = _doc('<xacro:macro name="body"><link name="base_link"/></xacro:macro><body/>')
    with caplog.at_level(logging.WARNING, logger="roverlab.description"):
        out = xacro_string(text)
    assert _links(out) == ["base_link"]
    assert ROS1_DEPRECATION in caplog.text and "<body>" in caplog.text


@pytest.mark.parametrize(
    ("body", "links"),
    [
        ('<property name="n" value="a"/><link name="${n}"/>', ["a"]),
        ('<macro name="m" params="x"><link name="${x}"/></macro><m x="q"/>', ["q"]),
        (
            '<if value="true"><link name="yes"/></if><if value="false"><link name="no"/></if>',
            ["yes"],
        ),
        ('<unless value="false"><link name="kept"/></unless>', ["kept"]),
        ('<arg name="w" default="d"/><link name="$(arg w)"/>', ["d"]),
        (
            '<macro name="m" params="*b"><link name="l"><insert_block name="b"/></link></macro>'
            '<m><visual><geometry><box size="1 1 1"/></geometry></visual></m>',
            ["l"],
        ),
    ],
)
def test_each_unprefixed_tag_is_xacros(body: str, links: list[str]) -> None:
    assert _links(xacro_string(_doc(body))) == links


def test_unprefixed_include_and_gazebo_include_with_children(tmp_path: Path) -> None:
    part = tmp_path / "part.xacro"
    part.write_text(_doc('<link name="from_include"/>'))
    text = _doc(
        f'<include filename="{part}"/><gazebo><include><uri>model://x</uri></include></gazebo>'
    )
    out = xacro_string(text)
    assert _links(out) == ["from_include"]
    assert "model://x" in out  # an <include> with child elements is not xacro's (ROS 1's rule)


def test_xacro_ns_refuses_unprefixed_forms(caplog: pytest.LogCaptureFixture) -> None:
    text = _doc('<macro name="m"><link name="a"/></macro><m/>')
    with caplog.at_level(logging.WARNING, logger="roverlab.description"):
        out = xacro_string(text, xacro_ns=True)
    root = ET.fromstring(out)  # the plain <macro> and <m> are ordinary elements then
    assert [e.tag for e in root] == ["macro", "m"]
    assert ROS1_DEPRECATION not in caplog.text


def test_an_element_that_is_no_macro_stays(caplog: pytest.LogCaptureFixture) -> None:
    out = xacro_string(
        _doc('<link name="a"><visual><geometry><box size="1 1 1"/></geometry></visual></link>')
    )
    assert _links(out) == ["a"] and "<box" in out
    assert ROS1_DEPRECATION not in caplog.text


def test_env_and_optenv(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("BOT_LINK", "from_env")
    out = xacro_string(
        _doc('<link name="$(env BOT_LINK)"/><link name="$(optenv NO_SUCH_VAR fb)"/>')
    )
    assert _links(out) == ["from_env", "fb"]


def test_hooks_are_removed_after_each_expansion() -> None:
    import xacro

    before = (xacro.eval_all, xacro.handle_macro_call)
    xacro_string(_doc('<macro name="m"><link name="a"/></macro><m/>'))
    with pytest.raises(XacroError):
        xacro_string(_doc("<xacro:nosuchmacro/>"))
    assert (xacro.eval_all, xacro.handle_macro_call) == before


@pytest.mark.parametrize(
    ("name", "sensor_link"),
    [("laser", "laser_link"), ("camera", "camera_link"), ("kinect", "kinect_link")],
)
def test_book_robots_load(name: str, sensor_link: str) -> None:
    model = load_robot(BOOK / f"robot_with_{name}.urdf.xacro", package_path=[PKGS])
    assert model.root_link == "base_footprint"
    assert {"base_link", "left_wheel_link", "right_wheel_link", sensor_link} <= set(model.links)
    assert model.gazebo.sensors and model.gazebo.sensors[0].reference_link == sensor_link
    # 'black' is defined inside base_footprint's visual and used by name in later links
    black = model.links["front_caster_link"].visuals[0].material
    assert black is not None and black.rgba == (0.05, 0.05, 0.05, 1.0)


def test_book_robot_xacro_ns_expands_to_no_links() -> None:
    with pytest.raises(DescriptionError, match=r"camera_offset_x. is not defined"):
        load_robot(BOOK / "robot_with_camera.urdf.xacro", package_path=[PKGS], xacro_ns=True)


def test_package_path_is_used_for_find() -> None:
    assert PackagePath([PKGS]).find("book_robot_description").name == "book_robot_description"
