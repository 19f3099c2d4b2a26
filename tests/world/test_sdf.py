"""Gazebo .world / .sdf loading: poses, geometry, includes, <state>, Building Editor walls."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.geometry import Transform3
from roverlab.world import (
    BoxShape,
    CylinderShape,
    PolylineShape,
    PosterShape,
    Shape,
    SphereShape,
    WorldError,
    load_sdf,
    world_warnings,
)
from roverlab.world.sdf import BUNDLED_MODELS_DIR, model_search_path


def world_sdf(body: str, version: str = "1.6") -> str:
    return (
        f"<?xml version='1.0'?>\n<sdf version='{version}'>\n"
        f"<world name='default'>\n{body}\n</world>\n</sdf>\n"
    )


def box_model(
    name: str,
    pose: str,
    size: str = "1 1 1",
    link_pose: str = "",
    coll_pose: str = "",
    material: str = "",
) -> str:
    lp = f"<pose>{link_pose}</pose>" if link_pose else ""
    cp = f"<pose>{coll_pose}</pose>" if coll_pose else ""
    return f"""
<model name='{name}'>
  <static>1</static>
  <pose>{pose}</pose>
  <link name='link'>{lp}
    <collision name='c'>{cp}<geometry><box><size>{size}</size></box></geometry></collision>
    <visual name='v'>{cp}<geometry><box><size>{size}</size></box></geometry>{material}</visual>
  </link>
</model>"""


def tf(shape: Shape) -> Transform3:
    assert not isinstance(shape, PosterShape)
    return shape.transform


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def corners(world_segments: np.ndarray) -> set[tuple[float, float]]:
    return {(round(float(x), 6), round(float(y), 6)) for x, y in world_segments[:, :2]}


def test_box_with_pose_and_yaw(tmp_path: Path) -> None:
    f = write(
        tmp_path / "w.world", world_sdf(box_model("b", "2 1 0.5 0 0 1.5707963267948966", "2 1 1"))
    )
    w = load_sdf(f)
    assert w.name == "w" and w.source == f and w.warnings == ()
    (shape,) = w.shapes
    assert isinstance(shape, BoxShape) and shape.size == (2.0, 1.0, 1.0)
    scene = w.to_scene()
    assert corners(scene.segments) == {(1.5, 0.0), (2.5, 0.0), (2.5, 2.0), (1.5, 2.0)}
    assert scene.segment_z[0].tolist() == pytest.approx([0.0, 1.0])


def test_cylinder_sphere_and_polyline(tmp_path: Path) -> None:
    body = """
<model name='things'>
  <static>true</static>
  <pose>1 0 0 0 0 0</pose>
  <link name='l'>
    <collision name='cyl'><pose>0 2 0.5 0 0 0</pose>
      <geometry><cylinder><radius>0.3</radius><length>1.0</length></cylinder></geometry></collision>
    <collision name='ball'><pose>0 -2 1 0 0 0</pose>
      <geometry><sphere><radius>0.25</radius></sphere></geometry></collision>
    <collision name='poly'><pose>3 0 0.2 0 0 0</pose>
      <geometry>
        <polyline>
          <point>0 0</point><point>1 0</point><point>1 1</point><point>0 1</point>
          <height>0.4</height>
        </polyline>
      </geometry></collision>
  </link>
</model>"""
    w = load_sdf(write(tmp_path / "w.sdf", world_sdf(body)))
    kinds = [type(s) for s in w.shapes]
    assert kinds == [CylinderShape, SphereShape, PolylineShape]
    scene = w.to_scene()
    assert np.allclose(scene.circles, [[1.0, 2.0, 0.3], [1.0, -2.0, 0.25]])
    assert np.allclose(scene.circle_z, [[0.0, 1.0], [0.75, 1.25]])
    assert corners(scene.segments) == {(4.0, 0.0), (5.0, 0.0), (5.0, 1.0), (4.0, 1.0)}
    assert scene.segment_z[0].tolist() == pytest.approx([0.2, 0.6])


def test_model_link_and_collision_poses_compose(tmp_path: Path) -> None:
    body = box_model(
        "m",
        "1 0 0 0 0 1.5707963267948966",
        "0.2 0.2 1",
        link_pose="1 0 0 0 0 0",
        coll_pose="0 0 0.5 0 0 0",
    )
    w = load_sdf(write(tmp_path / "w.world", world_sdf(body)))
    # model yaw 90 deg turns the link offset (1, 0) into (0, 1): centre at (1, 1)
    assert w.bounds == pytest.approx((0.9, 0.9, 1.1, 1.1))
    assert w.to_scene().segment_z[0].tolist() == pytest.approx([0.0, 1.0])


def test_pose_frames_world_and_sibling_link(tmp_path: Path) -> None:
    body = """
<model name='m'>
  <pose>10 0 0 0 0 0</pose>
  <link name='a'><pose>1 0 0 0 0 0</pose></link>
  <link name='b'><pose relative_to='a'>0 1 0 0 0 0</pose>
    <collision name='c'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
  </link>
  <link name='c'><pose frame='world'>0 5 0 0 0 0</pose>
    <collision name='c'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
  </link>
  <link name='d'><pose frame='nowhere'>0 -1 0 0 0 0</pose>
    <collision name='c'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
  </link>
</model>"""
    w = load_sdf(write(tmp_path / "w.world", world_sdf(body, "1.7")))
    centres = [tf(s).translation[:2] for s in w.shapes if isinstance(s, SphereShape)]
    assert centres == [
        pytest.approx((11.0, 1.0)),
        pytest.approx((0.0, 5.0)),
        pytest.approx((10.0, -1.0)),
    ]
    assert len(w.warnings) == 1 and "nowhere" in w.warnings[0]


def _model_dir(
    root: Path, name: str, model_pose: str = "0 0 0 0 0 0", sdf_name: str = "model.sdf"
) -> Path:
    d = root / name
    write(
        d / "model.config",
        f"<?xml version='1.0'?><model><name>{name}</name><sdf version='1.5'>old.sdf</sdf>"
        f"<sdf version='1.6'>{sdf_name}</sdf></model>",
    )
    write(
        d / sdf_name,
        "<?xml version='1.0'?><sdf version='1.6'>" + box_model(name, model_pose) + "</sdf>",
    )
    return d


def test_include_resolves_through_model_path_and_overrides_pose(tmp_path: Path) -> None:
    _model_dir(tmp_path / "mymodels", "crate", model_pose="100 100 0 0 0 0", sdf_name="crate.sdf")
    body = """
<include><uri>model://crate</uri><pose>3 0 0.5 0 0 0</pose><name>crate_a</name></include>
<include><uri>model://crate</uri></include>"""
    f = write(tmp_path / "w" / "w.world", world_sdf(body))
    w = load_sdf(f, model_path=[tmp_path / "mymodels"])
    a, b = (tf(s).translation for s in w.shapes)
    assert a == pytest.approx((3.0, 0.0, 0.5))  # include pose replaces the model's own
    assert b == pytest.approx((100.0, 100.0, 0.0))


def test_include_through_env_and_world_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _model_dir(tmp_path / "gz", "from_env", model_pose="1 0 0 0 0 0")
    _model_dir(tmp_path / "w" / "models", "beside", model_pose="2 0 0 0 0 0")
    monkeypatch.setenv("GAZEBO_MODEL_PATH", f"/does/not/exist:{tmp_path / 'gz'}")
    body = (
        "<include><uri>model://from_env</uri></include><include><uri>model://beside</uri></include>"
    )
    w = load_sdf(write(tmp_path / "w" / "w.world", world_sdf(body)))
    assert [tf(s).translation[0] for s in w.shapes] == pytest.approx([1.0, 2.0])
    paths = model_search_path(["/mine"], tmp_path)
    assert paths[0] == Path("/mine") and paths[1] == Path("/does/not/exist")
    assert paths[-1] == BUNDLED_MODELS_DIR


def test_bundled_ground_plane_and_sun_resolve(tmp_path: Path) -> None:
    body = (
        "<include><uri>model://ground_plane</uri></include><include><uri>model://sun</uri></include>"
        "<scene><background>0.2 0.4 0.6 1</background></scene>"
        "<physics type='ode'><gravity>0 0 -1.6</gravity></physics>"
    )
    w = load_sdf(write(tmp_path / "w.world", world_sdf(body)))
    assert w.shapes == () and w.warnings == ()
    assert w.floor_rgb == (178, 178, 178)  # Gazebo/Grey of the ground plane visual
    assert w.sky_rgb == (51, 102, 153)
    assert w.gravity == (0.0, 0.0, -1.6)


def test_state_pose_overrides_model_and_link_poses(tmp_path: Path) -> None:
    body = (
        box_model("a", "0 0 0.5 0 0 0")
        + box_model("b", "0 0 0.5 0 0 0")
        + """
<state world_name='default'>
  <sim_time>10 0</sim_time>
  <model name='a'><pose frame=''>5 0 0.5 0 -0 0</pose><scale>1 1 1</scale></model>
  <model name='b'><pose frame=''>0 7 0 0 -0 0</pose><scale>1 1 1</scale>
    <link name='link'><pose frame=''>0 -7 0.5 0 -0 0</pose><velocity>0 0 0 0 -0 0</velocity></link>
  </model>
  <model name='robot_not_in_world'><pose>1 1 1 0 0 0</pose></model>
</state>"""
    )
    w = load_sdf(write(tmp_path / "w.world", world_sdf(body)))
    a, b = (tf(s).translation for s in w.shapes)
    assert a == pytest.approx((5.0, 0.0, 0.5))
    assert b == pytest.approx((0.0, -7.0, 0.5))  # the link's state pose is a world pose


def building_wall(i: int, pose: str, ambient: str = "1 1 1 1", meta: str = "") -> str:
    """One wall link as the Building Editor saves it (4.15 m long, 2.5 m high)."""
    return f"""
  <link name='Wall_{i}'>
    <collision name='Wall_{i}_Collision'>
      <geometry><box><size>4.15 0.15 2.5</size></box></geometry>
      <pose frame=''>0 0 1.25 0 -0 0</pose>
    </collision>
    <visual name='Wall_{i}_Visual'>
      <pose frame=''>0 0 1.25 0 -0 0</pose>
      <geometry><box><size>4.15 0.15 2.5</size></box></geometry>
      <material>
        <script><uri>file://media/materials/scripts/gazebo.material</uri><name>Gazebo/Grey</name></script>
        <ambient>{ambient}</ambient>
      </material>{meta}
    </visual>
    <pose frame=''>{pose}</pose>
  </link>"""


BUILDING = (
    "\n<model name='my_building'>"
    + building_wall(0, "0 -2 0 0 -0 0", meta="\n      <meta><layer>0</layer></meta>")
    + building_wall(1, "2 0 0 0 -0 1.5708", ambient="0.921569 0.807843 0.615686 1")
    + building_wall(2, "0 2 0 0 -0 3.14159")
    + building_wall(3, "-2 0 0 0 -0 -1.5708")
    + """
  <static>1</static>
  <pose frame=''>-3.1 0.4 0 0 -0 0</pose>
</model>"""
)


def test_building_editor_walls_as_saved_by_save_world_as(tmp_path: Path) -> None:
    state = """
<state world_name='default'>
  <model name='my_building'><pose frame=''>1 1 0 0 -0 0</pose><scale>1 1 1</scale></model>
</state>"""
    w = load_sdf(write(tmp_path / "room.world", world_sdf(BUILDING + state)))
    assert [s.name for s in w.shapes] == [f"Wall_{i}_Collision" for i in range(4)]
    assert w.warnings == ()
    # the state pose (1, 1) wins over the model's own (-3.1, 0.4): a closed 4 m room around (1, 1)
    assert w.bounds == pytest.approx((-1.075, -1.075, 3.075, 3.075), abs=1e-3)
    assert not w.footprint_collides(1.0, 1.0, 0.0, 0.5)
    grid, (_, oy) = w.occupancy(0.05)
    inside = grid[int((1 - oy) / 0.05), :]
    assert inside.sum() >= 4  # both side walls cut the row through the centre
    # colours: Gazebo/Grey with a white ambient, or the ambient the editor wrote
    rgbs = [s.rgb for s in w.shapes]
    assert rgbs[0] == (178, 178, 178) and rgbs[1] == (235, 206, 157)


SAVED_EXTRAS = """
<light name='sun' type='directional'>
  <cast_shadows>1</cast_shadows>
  <pose frame=''>0 0 10 0 -0 0</pose>
  <diffuse>0.8 0.8 0.8 1</diffuse>
  <direction>-0.5 0.1 -0.9</direction>
</light>
<model name='ground_plane'>
  <static>1</static>
  <link name='link'>
    <collision name='collision'>
      <geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry>
      <surface><friction><ode><mu>100</mu><mu2>50</mu2></ode></friction><bounce/><contact/></surface>
      <max_contacts>10</max_contacts>
    </collision>
    <visual name='visual'>
      <cast_shadows>0</cast_shadows>
      <geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry>
      <material>
        <script><uri>file://media/materials/scripts/gazebo.material</uri><name>Gazebo/Grey</name></script>
      </material>
    </visual>
    <self_collide>0</self_collide>
    <enable_wind>0</enable_wind>
    <kinematic>0</kinematic>
  </link>
</model>
<model name='unit_box'>
  <pose frame=''>2 3 0.5 0 -0 0</pose>
  <link name='link'>
    <inertial><mass>1</mass></inertial>
    <collision name='collision'>
      <geometry><box><size>1 1 1</size></box></geometry>
      <max_contacts>10</max_contacts>
    </collision>
    <visual name='visual'>
      <geometry><box><size>1 1 1</size></box></geometry>
      <material>
        <script><name>Gazebo/Grey</name><uri>file://media/materials/scripts/gazebo.material</uri></script>
      </material>
    </visual>
    <self_collide>0</self_collide>
  </link>
</model>
<model name='unit_cylinder'>
  <pose frame=''>-2 3 0.5 0 -0 0</pose>
  <link name='link'>
    <collision name='collision'>
      <geometry><cylinder><radius>0.5</radius><length>1</length></cylinder></geometry>
    </collision>
    <visual name='visual'>
      <geometry><cylinder><radius>0.5</radius><length>1</length></cylinder></geometry>
      <material><script><uri>__default__</uri><name>__default__</name></script></material>
    </visual>
  </link>
</model>
<gravity>0 0 -9.8</gravity>
<magnetic_field>6e-06 2.3e-05 -4.2e-05</magnetic_field>
<atmosphere type='adiabatic'/>
<physics name='default_physics' default='0' type='ode'>
  <max_step_size>0.001</max_step_size>
</physics>
<scene><ambient>0.4 0.4 0.4 1</ambient><background>0.7 0.7 0.7 1</background></scene>
<wind/>
<spherical_coordinates><surface_model>EARTH_WGS84</surface_model></spherical_coordinates>
<gui fullscreen='0'>
  <camera name='user_camera'><pose frame=''>5 -5 2 0 0.27 2.35</pose></camera>
</gui>
"""


def test_a_whole_saved_world_loads_without_warnings(tmp_path: Path) -> None:
    w = load_sdf(write(tmp_path / "saved.world", world_sdf(SAVED_EXTRAS + BUILDING)))
    assert w.warnings == ()
    assert w.floor_rgb == (178, 178, 178) and w.sky_rgb == (178, 178, 178)
    kinds = [type(s).__name__ for s in w.shapes]
    assert kinds == ["BoxShape", "CylinderShape"] + ["BoxShape"] * 4
    assert w.shapes[1].rgb == (200, 200, 200)  # __default__ material: the default colour
    assert tf(w.shapes[0]).translation == pytest.approx((2.0, 3.0, 0.5))


def test_building_editor_model_sdf_loads_without_a_world(tmp_path: Path) -> None:
    f = write(
        tmp_path / "model.sdf", "<?xml version='1.0'?><sdf version='1.6'>" + BUILDING + "</sdf>"
    )
    w = load_sdf(f)
    assert len(w.shapes) == 4
    assert w.bounds == pytest.approx((-5.175, -1.675, -1.025, 2.475), abs=1e-3)


def test_material_colours(tmp_path: Path) -> None:
    def mat(inner: str) -> str:
        return f"<material>{inner}</material>"

    script = (
        "<script><uri>file://media/materials/scripts/gazebo.material</uri><name>{}</name></script>"
    )
    body = (
        box_model(
            "diffuse",
            "0 0 0 0 0 0",
            material=mat("<ambient>1 0 0 1</ambient><diffuse>0 0 1 1</diffuse>"),
        )
        + box_model("script", "2 0 0 0 0 0", material=mat(script.format("Gazebo/Red")))
        + box_model("ambient", "4 0 0 0 0 0", material=mat("<ambient>0 1 0 1</ambient>"))
        + box_model("unknown", "6 0 0 0 0 0", material=mat(script.format("My/Paint")))
        + box_model("none", "8 0 0 0 0 0")
    )
    w = load_sdf(write(tmp_path / "w.world", world_sdf(body)))
    assert [s.rgb for s in w.shapes] == [
        (0, 0, 255),
        (255, 0, 0),
        (0, 255, 0),
        (200, 200, 200),
        (200, 200, 200),
    ]
    assert len(w.warnings) == 1 and "My/Paint" in w.warnings[0]


def test_texture_from_an_ogre_material_script(tmp_path: Path) -> None:
    d = tmp_path / "models" / "sign"
    (d / "materials/textures").mkdir(parents=True)
    Image.new("RGB", (4, 4), (9, 8, 7)).save(d / "materials/textures/sign.png")
    write(
        d / "materials/scripts/sign.material",
        "// comment\nmaterial Sign/Face\n{\n technique\n {\n  pass\n  {\n   diffuse 0.5 0.5 0.5 1\n"
        "   texture_unit\n   {\n    texture sign.png\n   }\n  }\n }\n}\n",
    )
    material = (
        "<material><script><uri>model://sign/materials/scripts</uri>"
        "<uri>model://sign/materials/textures</uri><name>Sign/Face</name></script></material>"
    )
    write(
        d / "model.sdf",
        "<sdf version='1.6'>" + box_model("sign", "0 0 0.5 0 0 0", material=material) + "</sdf>",
    )
    w = load_sdf(
        write(tmp_path / "w.world", world_sdf("<include><uri>model://sign</uri></include>"))
    )
    (box,) = w.shapes
    assert isinstance(box, BoxShape)
    assert box.texture == d / "materials/textures/sign.png"
    assert box.rgb == (128, 128, 128)
    scene = w.to_scene()
    assert scene.segment_texture.tolist() == [0, 0, 0, 0]
    assert scene.textures[0][0, 0].tolist() == [9, 8, 7]


def test_unsupported_things_are_skipped_with_warnings(tmp_path: Path) -> None:
    body = """
<model name='statue'><static>1</static><link name='l'>
  <collision name='c'><geometry><mesh><uri>model://statue/meshes/s.dae</uri></mesh></geometry></collision>
</link></model>
<model name='turtlebot'><link name='base'>
  <collision name='c'><geometry><box><size>0.3 0.3 0.2</size></box></geometry></collision>
  <sensor name='lidar' type='ray'/>
</link><plugin name='diff' filename='libgazebo_ros_diff_drive.so'/></model>
<model name='deco'><static>1</static><link name='l'>
  <visual name='v'><geometry><box><size>1 1 1</size></box></geometry></visual>
</link></model>
<actor name='walker'><skin><filename>walk.dae</filename></skin></actor>
<population name='crowd'/>
<light name='lamp' type='point'/>
<physics type='ode'/>
""" + box_model("kept", "5 5 0.5 0 0 0")
    w = load_sdf(write(tmp_path / "w.world", world_sdf(body)))
    assert [s.name for s in w.shapes] == ["c"]
    assert tf(w.shapes[0]).translation == pytest.approx((5.0, 5.0, 0.5))
    text = "\n".join(w.warnings)
    assert len(w.warnings) == 5
    for needle in ("mesh", "turtlebot", "deco", "walker", "population"):
        assert needle in text
    assert all("w.world:" in line for line in w.warnings)


# ------------------------------------------------------------------------ errors


def _one_line_error(path: Path, *needles: str) -> str:
    with pytest.raises(WorldError) as info:
        load_sdf(path)
    msg = str(info.value)
    assert "\n" not in msg
    assert str(path) in msg
    for n in needles:
        assert n in msg
    return msg


def test_malformed_xml_names_the_line(tmp_path: Path) -> None:
    f = write(
        tmp_path / "bad.world",
        "<sdf version='1.6'>\n<world name='x'>\n<model name='m'>\n</world>\n</sdf>\n",
    )
    _one_line_error(f, "bad.world:4:", "malformed XML")


def test_missing_include_is_a_grouped_warning_listing_the_searched_paths(tmp_path: Path) -> None:
    f = write(
        tmp_path / "w.world", world_sdf("<include>\n<uri>model://nowhere_model</uri>\n</include>")
    )
    w = load_sdf(f)
    assert w.shapes == () or list(w.shapes) == []
    assert len(w.warnings) == 1 and ":5:" in w.warnings[0]  # the <uri> line
    (line,) = world_warnings(w)
    assert line.startswith("1 model skipped: nowhere_model — model://nowhere_model not found")
    assert str(BUNDLED_MODELS_DIR) in line and str(tmp_path) in line


@pytest.mark.parametrize(
    ("geometry", "needles"),
    [
        ("<box><size>1 0 1</size></box>", ("<box> / <size>", "'1 0 1'")),
        ("<box><size>1 nan 1</size></box>", ("<size>", "nan")),
        ("<box><size>1 1</size></box>", ("<size>", "3 positive")),
        (
            "<cylinder><radius>-0.2</radius><length>1</length></cylinder>",
            ("<cylinder> / <radius>",),
        ),
        ("<cylinder><radius>0.2</radius><length>0</length></cylinder>", ("<length>",)),
        ("<sphere><radius>NaN</radius></sphere>", ("<sphere> / <radius>",)),
        (
            "<polyline><point>0 0</point><point>1 0</point><height>1</height></polyline>",
            ("<polyline>", "3 distinct"),
        ),
        (
            "<polyline><point>0 0</point><point>1 0</point><point>1 1</point>"
            "<height>-1</height></polyline>",
            ("<height>",),
        ),
    ],
)
def test_bad_geometry_is_one_line_naming_file_and_element(
    tmp_path: Path, geometry: str, needles: tuple[str, ...]
) -> None:
    body = (
        "<model name='m'><link name='l'>\n<collision name='c'><geometry>\n"
        f"{geometry}\n</geometry></collision></link></model>"
    )
    f = write(tmp_path / "w.world", world_sdf(body))
    _one_line_error(f, "model 'm' / link 'l' / collision 'c'", *needles)


def test_bad_pose_and_root_are_errors(tmp_path: Path) -> None:
    f = write(tmp_path / "p.world", world_sdf("<model name='m'><pose>1 2 3</pose></model>"))
    _one_line_error(f, "model 'm' / <pose>", "6 finite numbers")
    f = write(tmp_path / "r.world", "<robot name='x'/>")
    _one_line_error(f, "expected <sdf>")
    with pytest.raises(WorldError, match="cannot read"):
        load_sdf(tmp_path / "missing.world")


def test_online_and_missing_folder_includes_are_errors(tmp_path: Path) -> None:
    fuel = "https://fuel.gazebosim.org/1.0/OpenRobotics/models/Table"
    f = write(tmp_path / "a.world", world_sdf(f"<include><uri>{fuel}</uri></include>"))
    _one_line_error(f, "online models are not fetched", "ROVERLAB_MODEL_PATH")
    f = write(tmp_path / "b.world", world_sdf("<include><uri>file://no/such/dir</uri></include>"))
    _one_line_error(f, "model folder file://no/such/dir not found")
    f = write(tmp_path / "c.world", world_sdf("<include><name>x</name></include>"))
    _one_line_error(f, "<include>: needs a <uri>")


def test_include_cycle_is_an_error(tmp_path: Path) -> None:
    d = tmp_path / "models" / "loop"
    write(
        d / "model.sdf",
        "<sdf version='1.6'><model name='loop'><include><uri>model://loop</uri></include></model></sdf>",
    )
    f = write(tmp_path / "w.world", world_sdf("<include><uri>model://loop</uri></include>"))
    with pytest.raises(WorldError, match="includes itself"):
        load_sdf(f)


def test_pose_in_degrees_and_quaternions(tmp_path: Path) -> None:
    body = """
<model name='a'><pose degrees='true'>0 0 0.5 0 0 90</pose><link name='l'>
  <collision name='c'><geometry><box><size>2 1 1</size></box></geometry></collision>
</link></model>
<model name='b'><pose rotation_format='quat_xyzw'>5 0 0.5 0 0 0.7071068 0.7071068</pose>
  <link name='l'>
    <collision name='c'><geometry><box><size>2 1 1</size></box></geometry></collision>
  </link>
</model>"""
    w = load_sdf(write(tmp_path / "w.world", world_sdf(body, "1.9")))
    assert [tf(s).yaw for s in w.shapes] == pytest.approx([math.pi / 2, math.pi / 2])


def test_models_gazebo_would_move_are_named_in_a_note(tmp_path: Path) -> None:
    _model_dir(tmp_path / "m", "crate")  # <static>1</static> in its own file
    movable = box_model("cart", "2 0 0 0 0 0").replace("<static>1</static>", "")
    falsy = box_model("ball", "4 0 0 0 0 0").replace("<static>1</static>", "<static>0</static>")
    body = (
        box_model("wall", "0 0 0 0 0 0")
        + box_model("post", "6 0 0 0 0 0").replace("<static>1</static>", "<static>True</static>")
        + movable
        + falsy
        + "<include><uri>model://crate</uri><name>kept</name></include>"
        + "<include><uri>model://crate</uri><name>pushed</name><static>false</static></include>"
        + "<model name='marker'><pose>0 0 0 0 0 0</pose><link name='l'/></model>"  # nothing to hit
    )
    w = load_sdf(write(tmp_path / "w.world", world_sdf(body)), model_path=[tmp_path / "m"])
    assert len(w.shapes) == 6  # all kept, as fixed obstacles
    assert w.notes == (
        f"{tmp_path / 'w.world'}: 3 models not <static> (Gazebo lets a robot push them) kept as "
        "fixed obstacles: cart, ball, pushed",
    )
    assert w.warnings == ()
    still = load_sdf(write(tmp_path / "s.world", world_sdf(box_model("wall", "0 0 0 0 0 0"))))
    assert still.notes == ()
