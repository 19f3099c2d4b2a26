"""xacro with $(find) hooked to roverlab's package path: args, macros, includes, errors."""

from __future__ import annotations

import importlib.metadata
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import xacro
import xacro.substitution_args

from roverlab.description import (
    XACRO_HOOK,
    XACRO_PINNED_VERSION,
    PackagePath,
    XacroError,
    check_xacro_hook,
    load_robot,
    robot_description,
    xacro_file,
    xacro_string,
)
from roverlab.packages import BUNDLED_PACKAGES_DIR
from tests.description.conftest import MakePackage, xrobot


def _links(xml_text: str) -> list[str]:
    return [e.get("name", "") for e in ET.fromstring(xml_text).iter("link")]


# ------------------------------------------------------------------ the hook
def test_installed_xacro_is_the_pinned_series_with_the_hook_point() -> None:
    check_xacro_hook()  # raises if an upgrade moved the hook point
    assert importlib.metadata.version("xacro").startswith(XACRO_PINNED_VERSION + ".")
    module, function = XACRO_HOOK
    assert module == "xacro.substitution_args"
    assert callable(getattr(xacro.substitution_args, function))
    assert "find" in xacro.substitution_args._eval_dict


def test_missing_hook_point_fails_loudly(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delattr(xacro.substitution_args, "_eval_find")
    with pytest.raises(XacroError, match="_eval_find is missing"):
        check_xacro_hook()
    with pytest.raises(XacroError, match="cannot hook"):
        xacro_string(xrobot('<link name="a"/>'))


def test_other_xacro_series_fails_loudly(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(importlib.metadata, "version", lambda name: "2.2.0")
    with pytest.raises(XacroError, match=r"xacro 2\.2\.0 installed, roverlab supports 2\.1\.x"):
        check_xacro_hook()


def test_hook_is_removed_after_each_expansion() -> None:
    before = xacro.substitution_args._eval_find
    xacro_string(xrobot('<link name="a"/>'))
    with pytest.raises(XacroError):
        xacro_string(xrobot('<xacro:include filename="$(find nopkg)/x.xacro"/>'))
    assert xacro.substitution_args._eval_find is before
    assert xacro.substitution_args._eval_dict["find"] is before


# ------------------------------------------------------------------ $(find)
def test_find_resolves_through_the_package_path(tmp_path: Path, make_package: MakePackage) -> None:
    pkg = make_package(
        "my_parts",
        {"urdf/part.xacro": xrobot('<link name="from_pkg"/>', "parts")},
    )
    top = tmp_path / "top.urdf.xacro"
    top.write_text(
        xrobot(
            '<xacro:include filename="$(find my_parts)/urdf/part.xacro"/>\n'
            '<link name="$(find my_parts)"/>'
        )
    )
    out = xacro_file(top, package_path=PackagePath([tmp_path / "ws"]))
    assert _links(out) == ["from_pkg", str(pkg)]


def test_find_uses_environment_variable(
    tmp_path: Path, make_package: MakePackage, monkeypatch: pytest.MonkeyPatch
) -> None:
    pkg = make_package("envpkg", root=tmp_path / "envroot")
    monkeypatch.setenv("ROVERLAB_PACKAGE_PATH", str(tmp_path / "envroot"))
    assert _links(xacro_string(xrobot('<link name="$(find envpkg)"/>'))) == [str(pkg)]


def test_bundled_xacro_finds_its_own_package() -> None:
    out = xacro_file(BUNDLED_PACKAGES_DIR / "bingda_tutorials" / "urdf" / "mybot.xacro")
    names = _links(out)
    assert "base_laser_link" in names and "base_footprint" in names
    root = ET.fromstring(out)
    assert root.find("gazebo/plugin[@filename='libgazebo_ros_diff_drive.so']") is not None


# ------------------------------------------------------------------ xacro language
def test_args_defaults_and_mappings(tmp_path: Path) -> None:
    doc = xrobot(
        '<xacro:arg name="flag" default="false"/>\n'
        '<xacro:arg name="wheel" default="0.1"/>\n'
        '<link name="l_$(arg flag)"/>\n'
        "<link name=\"r_${xacro.arg('wheel')}\"/>"
    )
    assert _links(xacro_string(doc)) == ["l_false", "r_0.1"]
    assert _links(xacro_string(doc, args={"flag": "true", "wheel": "0.25"})) == [
        "l_true",
        "r_0.25",
    ]
    # The caller's mapping is not modified by xacro (it adds defaults to its own copy).
    args = {"flag": "true"}
    xacro_string(doc, args=args)
    assert args == {"flag": "true"}


def test_properties_macros_and_conditionals() -> None:
    doc = xrobot(
        '<xacro:property name="r" value="0.05"/>\n'
        '<xacro:macro name="wheel" params="side reflect:=1 *origin">\n'
        '  <link name="${side}_wheel"><visual><geometry>'
        '<cylinder radius="${r}" length="${r*reflect}"/></geometry></visual></link>\n'
        "</xacro:macro>\n"
        '<xacro:wheel side="left"><origin xyz="0 0 0"/></xacro:wheel>\n'
        '<xacro:if value="${r > 0.01}"><link name="big"/></xacro:if>\n'
        '<xacro:unless value="${r > 0.01}"><link name="small"/></xacro:unless>'
    )
    out = xacro_string(doc)
    assert _links(out) == ["left_wheel", "big"]
    cylinder = ET.fromstring(out).find("link/visual/geometry/cylinder")
    assert cylinder is not None and cylinder.get("radius") == "0.05"


def test_relative_includes_resolve_from_the_including_file(tmp_path: Path) -> None:
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "inner.xacro").write_text(xrobot('<link name="inner"/>'))
    (tmp_path / "parts" / "middle.xacro").write_text(
        xrobot('<xacro:include filename="inner.xacro"/><link name="middle"/>')
    )
    top = tmp_path / "robot.urdf.xacro"
    top.write_text(xrobot('<xacro:include filename="parts/middle.xacro"/><link name="top"/>'))
    assert _links(xacro_file(top)) == ["inner", "middle", "top"]


def test_robot_description_matches_the_xacro_tool_layout(tmp_path: Path) -> None:
    top = tmp_path / "a.xacro"
    top.write_text(xrobot('<link name="a"/>'))
    text = robot_description(top)
    assert text.startswith('<?xml version="1.0" ?>\n<!-- ====')
    assert "autogenerated by xacro" in text
    assert '\n  <link name="a"/>\n' in text


def test_xmlns_xacro_urdf_file_is_expanded(tmp_path: Path) -> None:
    f = tmp_path / "robot.urdf"
    f.write_text(xrobot('<xacro:property name="n" value="x"/><link name="${n}"/>'))
    assert list(load_robot(f).links) == ["x"]


# ------------------------------------------------------------------ errors
def _error(tmp_path: Path, body: str, **kwargs: object) -> str:
    f = tmp_path / "bad.urdf.xacro"
    f.write_text(xrobot(body))
    with pytest.raises(XacroError) as info:
        xacro_file(f, **kwargs)  # type: ignore[arg-type]
    msg = str(info.value)
    assert "\n" not in msg
    assert "Traceback" not in msg
    return msg


def test_undefined_macro_names_file_and_macro(tmp_path: Path) -> None:
    msg = _error(tmp_path, '<xacro:nowhere side="l"/>')
    assert msg.startswith(str(tmp_path / "bad.urdf.xacro") + ": ")
    assert "xacro:nowhere" in msg


def test_undefined_property_names_macro(tmp_path: Path) -> None:
    msg = _error(
        tmp_path,
        '<xacro:macro name="wheel" params="s"><link name="${s}_${missing_prop}"/>'
        '</xacro:macro><xacro:wheel s="l"/>',
    )
    assert "in macro 'wheel'" in msg
    assert "missing_prop" in msg


def test_missing_include_names_the_file(tmp_path: Path) -> None:
    msg = _error(tmp_path, '<xacro:include filename="parts/absent.xacro"/>')
    assert msg.startswith(str(tmp_path / "bad.urdf.xacro"))
    assert "<xacro:include filename=" in msg and "absent.xacro" in msg


def test_unknown_package_lists_search_path(tmp_path: Path) -> None:
    msg = _error(tmp_path, '<xacro:include filename="$(find ghost_pkg)/urdf/x.xacro"/>')
    assert "$(find)" in msg and "package 'ghost_pkg' not found" in msg
    assert str(BUNDLED_PACKAGES_DIR) in msg


def test_errors_inside_expressions_name_their_cause(tmp_path: Path) -> None:
    # ${load_yaml('$(find x)/...')}: xacro wraps the error once per expression; the line
    # names the cause as it does outside an expression, without xacro's class names
    yaml = "${xacro.load_yaml('$(find ghost_pkg)/config/d.yaml')}"
    msg = _error(tmp_path, f'<xacro:property name="d" value="{yaml}"/><link name="${{d}}"/>')
    assert "$(find): package 'ghost_pkg' not found" in msg
    assert "<class" not in msg and msg.count("not found") == 1
    missing = f"${{load_yaml('{tmp_path}/absent.yaml')}}"
    msg = _error(tmp_path, f'<xacro:property name="d" value="{missing}"/><link name="${{d}}"/>')
    assert msg.endswith(f": cannot read {tmp_path}/absent.yaml: No such file or directory")
    msg = _error(tmp_path, '<link name="${$(arg width) * 2}"/>')
    assert "$(arg width): undefined xacro argument" in msg


def test_undefined_arg(tmp_path: Path) -> None:
    msg = _error(tmp_path, '<link name="$(arg nope)"/>')
    assert "$(arg nope)" in msg and "nope:=value" in msg


def test_bad_xml_in_included_file_has_line_number(tmp_path: Path) -> None:
    (tmp_path / "inc.xacro").write_text('<robot>\n  <link name="a">\n</robot>\n')
    msg = _error(tmp_path, '<xacro:include filename="inc.xacro"/>')
    assert msg.startswith(str(tmp_path / "inc.xacro"))
    assert "included from" in msg
    assert "line 3" in msg


def test_missing_top_file(tmp_path: Path) -> None:
    with pytest.raises(XacroError, match="no such file"):
        xacro_file(tmp_path / "absent.xacro")


def test_xacro_warnings_are_logged_not_printed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    (tmp_path / "inc.xacro").write_text(xrobot('<link name="inc"/>'))
    top = tmp_path / "top.xacro"
    top.write_text(xrobot('<xacro:include filename="inc.xacro"><child/></xacro:include>'))
    with caplog.at_level("WARNING", logger="roverlab.description"):
        out = xacro_file(top)
    assert _links(out) == ["inc"]
    assert capsys.readouterr().err == ""
    assert any(
        "Child elements of a <xacro:include> tag are ignored" in r.message for r in caplog.records
    )
