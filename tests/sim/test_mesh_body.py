"""A robot whose body is a mesh: the simulator's footprint comes from the mesh; a mesh it
cannot read is a warning by name (issue 17: no silent 0.2 m square)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from roverlab.description import load_robot
from roverlab.description.check import robot_warnings
from roverlab.sim.robot import sim_config_from_model


def _robot(tmp_path: Path, mesh: str, scale: str = "1 1 1") -> Path:
    path = tmp_path / "r.urdf"
    path.write_text(f"""<robot name="r">
  <link name="base_footprint"/>
  <joint name="j" type="fixed"><parent link="base_footprint"/><child link="base_link"/>
    <origin xyz="0.1 0 0.05"/></joint>
  <link name="base_link">
    <visual><geometry><mesh filename="{mesh}" scale="{scale}"/></geometry></visual>
    <collision><geometry><mesh filename="{mesh}" scale="{scale}"/></geometry></collision>
  </link>
</robot>""")
    return path


def test_the_footprint_is_the_meshs_outline(tmp_path: Path) -> None:
    trimesh.creation.box(extents=(0.6, 0.4, 0.1)).export(tmp_path / "body.stl")
    model = load_robot(_robot(tmp_path, "body.stl", scale="1 0.5 1"))
    config = sim_config_from_model(model)
    xy = config.footprint
    # the 0.6 x 0.2 m box (y scaled by half), 0.1 m ahead of base_footprint
    np.testing.assert_allclose(xy.min(axis=0), [-0.2, -0.1], atol=1e-6)
    np.testing.assert_allclose(xy.max(axis=0), [0.4, 0.1], atol=1e-6)
    assert abs(config.height_band[1] - 0.1) < 1e-6  # the top of the box: 0.05 + 0.05 m
    assert not [w for w in robot_warnings(model) if "mesh" in w or "square" in w]


def test_a_mesh_that_cannot_be_read_is_named(tmp_path: Path) -> None:
    model = load_robot(_robot(tmp_path, "missing.stl"))
    warnings = robot_warnings(model)
    assert any("link 'base_link': mesh left out of the body" in w and "missing.stl" in w
               for w in warnings), warnings  # fmt: skip
    assert any("the body is a 0.2 m square" in w for w in warnings), warnings
    np.testing.assert_allclose(np.abs(sim_config_from_model(model).footprint), 0.1)
