"""SDF 1.7 frames: ``<frame>`` elements of a world and of a model, and nested models posed
relative to their parent's links, as Gazebo 11 (sdformat 9) resolves them."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from roverlab.world import SphereShape, WorldError, load_sdf
from tests.world.test_sdf import tf, world_sdf, write

BALL = "<collision name='c'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>"


def _centres(path: Path) -> dict[str, tuple[float, float]]:
    w = load_sdf(path)
    assert w.warnings == ()
    out = {}
    for s in w.shapes:
        assert isinstance(s, SphereShape)
        x, y = tf(s).translation[:2]
        out[s.name] = (round(float(x), 6), round(float(y), 6))
    return out


def test_world_and_model_frames_place_what_is_relative_to_them(tmp_path: Path) -> None:
    c, s = math.cos(0.5), math.sin(0.5)
    body = """
<frame name='corner'><pose>3 3 0 0 0 0.5</pose></frame>
<frame name='beyond' attached_to='corner'><pose>1 0 0 0 0 0</pose></frame>
<model name='by_world_frame'><pose relative_to='beyond'>0 1 0 0 0 0</pose>
  <link name='l'><collision name='w'><geometry><sphere><radius>0.1</radius></sphere></geometry>
  </collision></link>
</model>
<model name='m'><pose>0 -3 0 0 0 1.5707963267948966</pose>
  <link name='base'><pose>0 0 0.25 0 0 0</pose></link>
  <frame name='mount' attached_to='base'><pose>0.5 0 0 0 0 0</pose></frame>
  <frame name='loose'><pose>2 0 0 0 0 0</pose></frame>
  <link name='on_mount'><pose relative_to='mount'>0 0.5 0 0 0 0</pose>
    <collision name='a'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
  </link>
  <link name='on_loose'><pose relative_to='loose'/>
    <collision name='b'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
  </link>
  <model name='inner'><pose relative_to='base'>1 0 0 0 0 0</pose>
    <link name='l'><collision name='n'><geometry><sphere><radius>0.1</radius></sphere>
    </geometry></collision></link>
  </model>
</model>"""
    got = _centres(write(tmp_path / "w.world", world_sdf(body, "1.7")))
    # beyond = corner * (1, 0); the model is (0, 1) in it
    assert got["w"] == pytest.approx((3 + c - s, 3 + s + c))
    # m is turned 90 degrees: its x axis is the world's y
    assert got["a"] == pytest.approx((-0.5, -2.5))  # base, 0.5 along x, then 0.5 along y
    assert got["b"] == pytest.approx((0.0, -1.0))  # a frame without attached_to: the model's
    assert got["n"] == pytest.approx((0.0, -2.0))  # nested model relative to a parent link


def test_frames_in_a_cycle_are_one_error(tmp_path: Path) -> None:
    frames = "<frame name='f1' attached_to='f2'/><frame name='f2' attached_to='f1'/>"
    body = f"<model name='m'>{frames}<link name='l'><pose relative_to='f1'/>{BALL}</link></model>"
    with pytest.raises(WorldError, match=r"w.world:\d+: model 'm' / frame 'f\d': pose frames form"):
        load_sdf(write(tmp_path / "w.world", world_sdf(body, "1.7")))
