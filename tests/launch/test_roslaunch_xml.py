"""roslaunch's XML rules a user's own package meets: private parameters at launch scope,
global names inside a node, ``subst_value``, ``rosparam delete``/``dump``, ``<machine>``,
``<test>``, unknown attributes, arg declarations and include args, ``$(eval)``'s builtins,
one value per ``<param>``, if and unless together."""

from __future__ import annotations

from pathlib import Path

import pytest

from roverlab.launch import LaunchError, load_launch


def _write(folder: Path, name: str, body: str) -> Path:
    path = folder / name
    path.write_text(body)
    return path


def test_private_global_and_relative_parameter_names(tmp_path: Path) -> None:
    spec = load_launch(_write(tmp_path, "p.launch", """<launch>
  <param name="~rate" value="10"/>
  <group ns="g">
    <param name="~frame" value="map"/>
    <node pkg="p" type="t" name="a">
      <param name="/abs" value="1"/>
      <param name="~own" value="2"/>
      <param name="rel/x" value="3"/>
      <rosparam ns="/glob">{k: 4}</rosparam>
      <rosparam>{nested: {y: 5}}</rosparam>
    </node>
  </group>
  <node pkg="p" type="t" name="b"/>
</launch>"""))  # fmt: skip
    a, b = spec.nodes
    assert a.params == {"rate": 10, "frame": "map", "own": 2, "rel/x": 3, "nested/y": 5}
    assert b.params == {"rate": 10}  # ~frame belonged to the group
    assert spec.params == {"/abs": 1, "/glob/k": 4}


def test_rosparam_subst_value_delete_and_dump(tmp_path: Path) -> None:
    _write(tmp_path, "v.yaml", "speed: $(arg speed)\n")
    spec = load_launch(_write(tmp_path, "r.launch", """<launch>
  <arg name="speed" default="0.5"/>
  <rosparam>plain: $(arg speed)</rosparam>
  <rosparam subst_value="true">subst: $(arg speed)</rosparam>
  <rosparam file="$(dirname)/v.yaml" ns="f" subst_value="true"/>
  <rosparam command="delete" param="old"/>
  <rosparam command="dump" file="/tmp/dump.yaml"/>
</launch>"""))  # fmt: skip
    assert spec.params == {"/plain": "$(arg speed)", "/subst": 0.5, "/f/speed": 0.5}
    assert len(spec.warnings) == 1 and "rosparam dump not done" in spec.warnings[0]
    assert "r.launch: <rosparam>" in spec.warnings[0]
    with pytest.raises(LaunchError, match="rosparam delete takes no file"):
        body = '<launch><rosparam command="delete" file="x.yaml"/></launch>'
        load_launch(_write(tmp_path, "d.launch", body))


def test_machine_test_and_unknown_attributes_are_reported_by_name(tmp_path: Path) -> None:
    spec = load_launch(_write(tmp_path, "m.launch", """<launch>
  <master auto="start"/>
  <machine name="here" address="localhost" default="true"/>
  <machine name="robot" address="192.168.1.20" user="pi"/>
  <node pkg="p" type="t" name="a" machine="robot" lauch-prefix="gdb"/>
  <test test-name="t1" pkg="p" type="test.py"/>
</launch>"""))  # fmt: skip
    assert [n.name for n in spec.nodes] == ["a"]
    where = f"{tmp_path / 'm.launch'}: "
    assert spec.warnings == [
        where + "<machine name=\"robot\">: machine 'robot' (192.168.1.20): roverlab starts "
        "every node on this machine",
        where + "<node name=\"a\">: unknown attribute 'lauch-prefix' (roslaunch ignores it too)",
        where + "<node name=\"a\">: machine='robot': the node runs on this machine",
        where + "<test>: test 't1' not run: roslaunch leaves tests to rostest",
    ]


def test_arg_declarations_and_include_args(tmp_path: Path) -> None:
    _write(
        tmp_path,
        "inner.launch",
        '<launch><arg name="a"/><param name="a" value="$(arg a)"/></launch>',
    )
    ok = load_launch(_write(tmp_path, "ok.launch", """<launch>
  <arg name="a" default="1"/><arg name="b" default="2"/>
  <include file="inner.launch" pass_all_args="true"/>
  <include file="inner.launch" ns="n"><arg name="a" value="3"/></include>
</launch>"""))  # fmt: skip
    assert ok.params == {"/a": 1, "/n/a": 3}
    for body, needle in [
        ('<arg name="a" default="1"/><arg name="a" default="2"/>', "arg 'a' has already been declared"),  # noqa: E501
        ('<include file="inner.launch"><arg name="a" value="1"/><arg name="zz" value="2"/></include>',  # noqa: E501
         "unused args [zz] for include of"),
        ('<include file="inner.launch"/>', "arg 'a' is not set"),
        ('<include file="inner.launch" pass_all_args="yes"/>', "pass_all_args must be true or false"),  # noqa: E501
    ]:  # fmt: skip
        with pytest.raises(LaunchError, match=needle.replace("[", r"\[")) as info:
            load_launch(_write(tmp_path, "bad.launch", f"<launch>{body}</launch>"))
        assert "\n" not in str(info.value)


def test_eval_has_roslaunchs_builtins_and_math(tmp_path: Path) -> None:
    spec = load_launch(_write(tmp_path, "e.launch", """<launch>
  <arg name="n" default="3"/><arg name="mode" default="dwa"/>
  <param name="next" value="$(eval int(arg('n')) + 1)"/>
  <param name="s" value="$(eval str(n) + 'x')"/>
  <param name="zero" value="$(eval sin(0) + floor(0.5))"/>
  <param name="dwa" value="$(eval arg('mode') == 'dwa')"/>
  <param name="list" type="yaml" value="$(eval list(map(float, [1, 2])))"/>
</launch>"""))  # fmt: skip
    assert spec.params == {"/next": 4, "/s": "3x", "/zero": 0.0, "/dwa": True, "/list": [1.0, 2.0]}
    with pytest.raises(LaunchError, match="double underscore"):
        body = '<launch><param name="x" value="$(eval ().__class__)"/></launch>'
        load_launch(_write(tmp_path, "u.launch", body))


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ('<param name="x" value="1" textfile="f.txt"/>', "one and only one of value/textfile"),
        ('<param name="x"/>', "one and only one of value/textfile"),
        ('<param name="x" value="yes" type="bool"/>', "'yes' is not a valid bool"),
        ('<param name="x" value="1" type="float"/>', "unknown param type 'float'"),
        ('<group if="true" unless="false"/>', "cannot set both 'if' and 'unless'"),
        ('<node pkg="p" type="t"/>', "missing attribute 'name'"),
        ('<node pkg="p" type="t" name="a/b"/>', "illegal node name 'a/b'"),
        ('<node pkg="p" type="t" name="a" ns=""/>', "empty ns attribute"),
        ('<node pkg="p" type="t" name="a" cwd="here"/>', "cwd must be 'ROS_HOME' or 'node'"),
        ('<group clear_params="true"/>', "clear_params needs an ns attribute"),
        ("<rosparam>[1, 2]</rosparam>", "not a mapping needs param="),
    ],
)
def test_what_roslaunch_refuses_is_one_line(tmp_path: Path, body: str, needle: str) -> None:
    with pytest.raises(LaunchError) as info:
        load_launch(_write(tmp_path, "bad.launch", f"<launch>{body}</launch>"))
    msg = str(info.value)
    assert "bad.launch" in msg and needle in msg and "\n" not in msg
