"""Mesh obstacles: STL, Collada (unit, up axis, colour) and OBJ files -> 2.5D shapes seen by
the lidar at the right range; the disk cache; grouped warnings for what is not found."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from roverlab.core import Context
from roverlab.geometry import Transform3, quat_from_rpy
from roverlab.geometry import mesh as mesh_mod
from roverlab.geometry.mesh import MeshError, load_mesh, mesh_cache_dir, mesh_outlines
from roverlab.sim.app import Simulation
from roverlab.world import PolylineShape, load_world, world_warnings
from tests.helpers.nodes import range_at

PKGS = Path(__file__).resolve().parents[1] / "ros1_packages"
MODELS = PKGS / "book_worlds" / "models"
WORLD = PKGS / "book_worlds" / "worlds" / "mesh_obstacles.world"
ROBOT = PKGS / "book_robot_description" / "urdf" / "robot_with_laser.urdf.xacro"


def _box(parts: list[mesh_mod.MeshOutline]) -> tuple[float, ...]:
    pts = np.concatenate([o.points for o in parts])
    return (
        *pts.min(axis=0).round(4),
        *pts.max(axis=0).round(4),
        round(min(o.z_min for o in parts), 4),
        round(max(o.z_max for o in parts), 4),
    )


def test_stl_in_metres_with_scale_and_pose() -> None:
    parts = load_mesh(MODELS / "jersey_barrier" / "meshes" / "jersey_barrier.stl")
    assert len(parts) == 1  # one solid, however many triangles
    assert _box(mesh_outlines(parts, Transform3())) == (-1.0, -0.2, 1.0, 0.2, 0.0, 0.8)
    turned = Transform3.from_arrays((3.0, 0.0, 0.5), quat_from_rpy(0.0, 0.0, math.pi / 2))
    assert _box(mesh_outlines(parts, turned, (1.0, 2.0, 0.5))) == (
        2.6, -1.0, 3.4, 1.0, 0.5, 0.9
    )  # fmt: skip


def test_collada_unit_up_axis_and_colour() -> None:
    # the file is in centimetres with +y up: 150 x 100 cm footprint, 120 cm tall
    parts = load_mesh(MODELS / "dumpster" / "meshes" / "dumpster.dae")
    out = mesh_outlines(parts, Transform3())
    assert _box(out) == (-0.75, -0.5, 0.75, 0.5, 0.0, 1.2)
    assert out[0].rgb == (20, 110, 40)


def test_obj_parts_each_get_their_own_outline() -> None:
    out = mesh_outlines(
        load_mesh(MODELS / "construction_cone" / "meshes" / "cone.obj"), Transform3()
    )
    assert sorted((round(o.z_max, 3), round(float(np.abs(o.points).max()), 3)) for o in out) == [
        (0.03, 0.225),
        (0.7, 0.2),
    ]


def test_cache_is_keyed_by_file_hash(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROVERLAB_CACHE_DIR", str(tmp_path / "cache"))
    src = MODELS / "jersey_barrier" / "meshes" / "jersey_barrier.stl"
    a = tmp_path / "a.stl"
    a.write_bytes(src.read_bytes())
    first = load_mesh(a)
    cached = list(mesh_cache_dir().glob("*.npz"))
    assert len(cached) == 1
    # a copy elsewhere is served from the cache: reading the mesh again would fail now
    monkeypatch.setattr(mesh_mod, "_process", lambda *a: pytest.fail("cache not used"))
    b = tmp_path / "b.stl"
    b.write_bytes(src.read_bytes())
    assert np.array_equal(load_mesh(b)[0].hull, first[0].hull)
    # a changed file is a new key
    monkeypatch.undo()
    monkeypatch.setenv("ROVERLAB_CACHE_DIR", str(tmp_path / "cache"))
    c = tmp_path / "c.obj"
    c.write_bytes((MODELS / "construction_cone" / "meshes" / "cone.obj").read_bytes())
    load_mesh(c)
    assert len(list(mesh_cache_dir().glob("*.npz"))) == 2


def test_bad_mesh_is_one_line_naming_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "broken.stl"
    bad.write_bytes(b"solid nothing\nendsolid nothing\n")
    with pytest.raises(MeshError, match=r"broken\.stl: ") as info:
        load_mesh(bad)
    assert "\n" not in str(info.value)
    with pytest.raises(MeshError, match=r"x\.ply: mesh format \.ply is not supported"):
        load_mesh(tmp_path / "x.ply")


def test_world_mesh_models_become_shapes_and_missing_ones_are_grouped() -> None:
    w = load_world(WORLD)
    assert all(isinstance(s, PolylineShape) for s in w.shapes) and len(w.shapes) == 4
    assert world_warnings(w)[0].startswith(
        "2 models skipped: hydrant_0, hydrant_1 — model://fire_hydrant not found; put Gazebo's "
        "models on GAZEBO_MODEL_PATH"
    )
    assert len(world_warnings(w)) == 1


def test_lidar_sees_stl_dae_and_obj_obstacles_at_the_right_range(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(PKGS))
    ctx = Context(clock="sim")
    try:
        Simulation(context=ctx, world=str(WORLD), robot=str(ROBOT))
        node = ctx.create_node("collector")
        scans: list[object] = []
        node.create_subscription("sensor_msgs/msg/LaserScan", "/scan", scans.append, 10)
        ctx.spin_for(1.0)
    finally:
        ctx.shutdown()
    assert scans
    scan = scans[-1]
    assert range_at(scan, 0.0) == pytest.approx(2.8, abs=0.05)  # STL jersey barrier ahead
    assert range_at(scan, math.pi / 2) == pytest.approx(
        3.5, abs=0.05
    )  # Collada dumpster (cm, Y up)
    assert range_at(scan, math.pi) == pytest.approx(1.6, abs=0.05)  # OBJ cone scaled x2 (hull)
