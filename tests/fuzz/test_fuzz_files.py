"""Fuzzing the file parsers: URDF, xacro, SDF/.world, .launch, .rviz, map YAML + image.

Each test edits a real document of the project at random (a fixed, derandomised budget)
and checks the parser gives a result or one clear line naming the file (tests/fuzz/
mutation.py), never another exception or a hang.
"""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from roverlab.description import find_package
from roverlab.description.urdf import load_robot, parse_urdf, robot_description
from roverlab.launch.xml import load_launch
from roverlab.maps import load_map
from roverlab.viz.config import parse_rviz
from roverlab.world import load_world
from roverlab.world.loader import BUNDLED_WORLDS_DIR
from tests.fuzz.mutation import FUZZ, clean, in_folder, mutated

_MYBOT = find_package("bingda_tutorials") / "urdf" / "mybot.xacro"
URDF_TEXT = robot_description(_MYBOT)
XACRO_TEXT = _MYBOT.read_text()
WORLD_TEXT = (BUNDLED_WORLDS_DIR / "maze.world").read_text()
_NAV = find_package("robot_navigation")
LAUNCH_TEXT = (_NAV / "launch" / "navigation_stack.launch").read_text()
RVIZ_TEXT = (_NAV / "rviz" / "navigation.rviz").read_text()
MAP_YAML = "image: map.pgm\nresolution: 0.05\norigin: [-1.0, -2.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n"  # noqa: E501
PGM = b"P5\n4 3\n255\n" + bytes([0, 254, 205, 100, 254, 254, 0, 0, 205, 205, 254, 0])


@FUZZ
@given(mutated(URDF_TEXT))
def test_urdf(text: str) -> None:
    clean(parse_urdf, text, source="fuzz.urdf", name="fuzz.urdf")


@FUZZ
@given(mutated(XACRO_TEXT))
def test_xacro(text: str) -> None:
    with in_folder("robot.urdf.xacro", text) as path:
        clean(load_robot, path, name="robot.urdf.xacro")


@FUZZ
@given(mutated(WORLD_TEXT))
def test_world(text: str) -> None:
    with in_folder("fuzz.world", text) as path:
        clean(load_world, path, name="fuzz.world")


@FUZZ
@given(mutated(LAUNCH_TEXT))
def test_launch(text: str) -> None:
    with in_folder("fuzz.launch", text) as path:
        clean(load_launch, path, {"simulation": "true"}, name="fuzz.launch")


@FUZZ
@given(mutated(RVIZ_TEXT))
def test_rviz(text: str) -> None:
    clean(parse_rviz, text, "fuzz.rviz", name="fuzz.rviz")


@FUZZ
@given(mutated(MAP_YAML))
def test_map_yaml(text: str) -> None:
    with in_folder("map.yaml", text, {"map.pgm": PGM}) as path:
        clean(load_map, path, name="map")


@FUZZ
@given(st.binary(max_size=64) | st.builds(lambda cut: PGM[:cut], st.integers(0, len(PGM))))
def test_map_image(data: bytes) -> None:
    with in_folder("map.yaml", MAP_YAML, {"map.pgm": data}) as path:
        clean(load_map, path, name="map.pgm")


def test_in_folder_leaves_nothing_behind() -> None:
    # every example gets its own folder; each run of the suite used to leave hundreds in /tmp
    with in_folder("map.yaml", MAP_YAML, {"map.pgm": PGM}) as path:
        folder = path.parent
        assert sorted(p.name for p in folder.iterdir()) == ["map.pgm", "map.yaml"]
        assert path.read_text() == MAP_YAML
    assert not folder.exists()
