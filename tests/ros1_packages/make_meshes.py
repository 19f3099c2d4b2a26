"""Regenerate the tiny mesh files of the test packages (run from anywhere, with trimesh and
pycollada installed): ``python tests/ros1_packages/make_meshes.py``.

Each mesh is a simple solid whose size the tests know: the lidar must see it where this
script puts its faces.
"""

from __future__ import annotations

from pathlib import Path

import trimesh

HERE = Path(__file__).resolve().parent


def _write(mesh: trimesh.Trimesh, path: Path, **kwargs: object) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    data = mesh.export(file_type=path.suffix[1:], **kwargs)
    path.write_bytes(data if isinstance(data, bytes) else data.encode())


def _dae(mesh: trimesh.Trimesh, path: Path, meter: float, up: str) -> None:
    """Collada with the given ``<unit meter>`` and ``<up_axis>`` (trimesh writes Y_UP)."""
    dae = mesh.export(file_type="dae").decode()
    head, _, rest = dae.partition("</asset>")
    head = "\n".join(ln for ln in head.split("\n") if "<unit" not in ln and "<up_axis" not in ln)
    head = "\n".join(ln for ln in head.split("\n") if ln.strip())
    asset = f'\n    <unit meter="{meter}" name="unit"/>\n    <up_axis>{up}</up_axis>\n  </asset>'
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(head + asset + rest)


def main() -> None:
    robot = HERE / "book_robot_description" / "meshes"
    # rplidar in millimetres (the URDF scales it by 0.001): r 35 mm, 40 mm high
    _write(trimesh.creation.cylinder(radius=35.0, height=40.0, sections=16), robot / "rplidar.stl")
    # kinect body: 0.07 x 0.28 x 0.07 m box, red
    kinect = trimesh.creation.box(extents=(0.07, 0.28, 0.07))
    kinect.visual.face_colors = [200, 30, 30, 255]
    _dae(kinect, robot / "kinect.dae", 1.0, "Z_UP")
    # a base plate used only as a mesh collision (footprint test): 0.5 x 0.3 m, 0.1 m high
    _write(trimesh.creation.box(extents=(0.5, 0.3, 0.1)), robot / "base_plate.stl")

    models = HERE / "book_worlds" / "models"
    # jersey barrier: a 2.0 x 0.4 x 0.8 m prism (binary STL, metres)
    barrier = trimesh.creation.box(extents=(2.0, 0.4, 0.8))
    barrier.apply_translation((0.0, 0.0, 0.4))
    _write(barrier, models / "jersey_barrier" / "meshes" / "jersey_barrier.stl")
    # dumpster: Collada in centimetres with Y up (<unit meter="0.01"/>, Y_UP):
    # 150 x 100 cm footprint (x, z in the file), 120 cm tall (y in the file)
    dumpster = trimesh.creation.box(extents=(150.0, 120.0, 100.0))
    dumpster.apply_translation((0.0, 60.0, 0.0))
    dumpster.visual.face_colors = [20, 110, 40, 255]
    _dae(dumpster, models / "dumpster" / "meshes" / "dumpster.dae", 0.01, "Y_UP")
    # construction cone: OBJ, a cone of radius 0.2 m, 0.7 m high, two parts (cone + base)
    cone = trimesh.creation.cone(radius=0.2, height=0.7, sections=12)
    base = trimesh.creation.box(extents=(0.45, 0.45, 0.03))
    base.apply_translation((0.0, 0.0, 0.015))
    _write(
        trimesh.util.concatenate([cone, base]), models / "construction_cone" / "meshes" / "cone.obj"
    )


if __name__ == "__main__":
    main()
