"""Write the bundled worlds ``warehouse`` and ``apartment`` (held out from navigation tuning).

They were written once, before ``roverlab explore`` was tuned on maze, office and house,
and are only evaluated on (docs/exploration.md): a robot that explores them well does so
with parameters that never saw them. Do not edit them to make a run pass; add a new world
instead. Run this script to regenerate them byte for byte::

    python tests/world/make_held_out_worlds.py [OUT_DIR]

Walls are Building Editor links (0.15 m thick, 2.5 m high, each one 0.15 m longer than
its centre line so that corners close), furniture static models from the floor up.
Not a test: pytest does not collect it.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

DEFAULT_OUT = Path(__file__).resolve().parents[2] / "src/roverlab/world/bundled"
WALL_T = 0.15
WALL_H = 2.5


def f(v: float) -> str:
    """A number as Gazebo writes it (no trailing zeros)."""
    s = f"{v:.4f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


@dataclass(frozen=True)
class Box:
    name: str
    x: float
    y: float
    sx: float
    sy: float
    h: float
    yaw: float = 0.0
    material: str = "Gazebo/Wood"


@dataclass(frozen=True)
class Cyl:
    name: str
    x: float
    y: float
    r: float
    h: float
    material: str = "Gazebo/Grey"


@dataclass(frozen=True)
class Poly:
    name: str
    points: tuple[tuple[float, float], ...]
    h: float
    material: str = "Gazebo/Blue"


def wall_links(walls: list[tuple[float, float, float, float]]) -> str:
    out = []
    for i, (ax, ay, bx, by) in enumerate(walls):
        length = math.hypot(bx - ax, by - ay) + WALL_T
        cx, cy = (ax + bx) / 2, (ay + by) / 2
        yaw = math.atan2(by - ay, bx - ax)
        geom = (
            f"          <geometry>\n            <box>\n              <size>{f(length)} "
            f"{f(WALL_T)} {f(WALL_H)}</size>\n            </box>\n          </geometry>\n"
        )
        out.append(
            f"      <link name='Wall_{i}'>\n"
            f"        <collision name='Wall_{i}_Collision'>\n{geom}"
            f"          <pose frame=''>0 0 {f(WALL_H / 2)} 0 -0 0</pose>\n"
            f"        </collision>\n"
            f"        <visual name='Wall_{i}_Visual'>\n"
            f"          <pose frame=''>0 0 {f(WALL_H / 2)} 0 -0 0</pose>\n{geom}"
            f"          <material>\n            <script>\n"
            f"              <uri>file://media/materials/scripts/gazebo.material</uri>\n"
            f"              <name>Gazebo/Grey</name>\n            </script>\n"
            f"            <ambient>0.93 0.92 0.88 1</ambient>\n          </material>\n"
            f"          <meta>\n            <layer>0</layer>\n          </meta>\n"
            f"        </visual>\n"
            f"        <pose frame=''>{f(cx)} {f(cy)} 0 0 -0 {f(yaw)}</pose>\n"
            f"      </link>\n"
        )
    return "".join(out)


def furniture(item: Box | Cyl | Poly) -> str:
    if isinstance(item, Box):
        pose = f"{f(item.x)} {f(item.y)} 0 0 -0 {f(item.yaw)}"
        size = f"{f(item.sx)} {f(item.sy)} {f(item.h)}"
        shape = f"<box>\n              <size>{size}</size>\n            </box>"
        inner = f"0 0 {f(item.h / 2)} 0 -0 0"
    elif isinstance(item, Cyl):
        pose = f"{f(item.x)} {f(item.y)} 0 0 -0 0"
        shape = (
            f"<cylinder>\n              <radius>{f(item.r)}</radius>\n"
            f"              <length>{f(item.h)}</length>\n            </cylinder>"
        )
        inner = f"0 0 {f(item.h / 2)} 0 -0 0"
    else:
        pose = "0 0 0 0 -0 0"
        pts = "".join(f"              <point>{f(x)} {f(y)}</point>\n" for x, y in item.points)
        height = f"              <height>{f(item.h)}</height>\n"
        shape = f"<polyline>\n{pts}{height}            </polyline>"
        inner = "0 0 0 0 -0 0"
    geom = f"          <geometry>\n            {shape}\n          </geometry>\n"
    return (
        f"    <model name='{item.name}'>\n      <static>1</static>\n"
        f"      <pose frame=''>{pose}</pose>\n      <link name='link'>\n"
        f"        <collision name='collision'>\n          <pose frame=''>{inner}</pose>\n{geom}"
        f"        </collision>\n"
        f"        <visual name='visual'>\n          <pose frame=''>{inner}</pose>\n{geom}"
        f"          <material>\n            <script>\n"
        f"              <uri>file://media/materials/scripts/gazebo.material</uri>\n"
        f"              <name>{item.material}</name>\n            </script>\n"
        f"          </material>\n        </visual>\n      </link>\n    </model>\n"
    )


HEADER = """<?xml version="1.0" ?>
<sdf version='1.6'>
  <world name='{name}'>
    <!--
{comment}
    -->
    <include>
      <uri>model://ground_plane</uri>
    </include>
    <include>
      <uri>model://sun</uri>
    </include>
    <gravity>0 0 -9.8</gravity>
    <magnetic_field>6e-06 2.3e-05 -4.2e-05</magnetic_field>
    <atmosphere type='adiabatic'/>
    <physics name='default_physics' default='0' type='ode'>
      <max_step_size>0.001</max_step_size>
      <real_time_factor>1</real_time_factor>
      <real_time_update_rate>1000</real_time_update_rate>
    </physics>
    <scene>
      <ambient>0.4 0.4 0.4 1</ambient>
      <background>0.7 0.7 0.7 1</background>
      <shadows>1</shadows>
    </scene>
    <wind/>
    <spherical_coordinates>
      <surface_model>EARTH_WGS84</surface_model>
      <latitude_deg>0</latitude_deg>
      <longitude_deg>0</longitude_deg>
      <elevation>0</elevation>
      <heading_deg>0</heading_deg>
    </spherical_coordinates>
    <model name='{name}_building'>
      <pose frame=''>0 0 0 0 -0 0</pose>
{walls}      <static>1</static>
    </model>
"""

FOOTER = """    <gui fullscreen='0'>
      <camera name='user_camera'>
        <pose frame=''>{cx} {cy} 13 0 0.85 1.5708</pose>
        <view_controller>orbit</view_controller>
        <projection_type>perspective</projection_type>
      </camera>
    </gui>
  </world>
</sdf>
"""


def world(
    name: str,
    comment: str,
    walls: list[tuple[float, float, float, float]],
    items: list[Box | Cyl | Poly],
    camera: tuple[float, float],
) -> str:
    text = "\n".join(f"      {line}".rstrip() for line in comment.strip().splitlines())
    return (
        HEADER.format(name=name, comment=text, walls=wall_links(walls))
        + "".join(furniture(i) for i in items)
        + FOOTER.format(cx=f(camera[0]), cy=f(camera[1]))
    )


# ---------------------------------------------------------------------------- warehouse
WAREHOUSE_COMMENT = """
roverlab bundled world "warehouse": 14 m x 9 m (x from -2 to 12, y from -4.5 to 4.5).
A loading area (x < 2.5: pallet stacks, a forklift, one pallet turned 0.5 rad) with
a site office in its north-west corner (door 0.85 m clear, east side); three rows of
2 m high pallet racks from x = 3.5 to 10.5, each cut by a 1 m cross aisle at
x = 6.5..7.5; aisles 1.375, 1.35, 1.65 and 1.775 m wide from south to north, a cart
parked in the third aisle (0.95 m left beside it); columns, one in the 1.4 m end aisle
at x = 10.5..12 (0.5 m left on either side of it).
Held out: written before roverlab explore was tuned, never tuned on.
Spawn: x=0 y=0 yaw=0 (Gazebo's default); the nearest obstacle (the forklift) is 0.8 m away.
"""
WAREHOUSE_WALLS = [
    (-2.0, -4.5, 12.0, -4.5),
    (12.0, -4.5, 12.0, 4.5),
    (12.0, 4.5, -2.0, 4.5),
    (-2.0, 4.5, -2.0, -4.5),
    # site office: x -2..0.2, y 2..4.5, door on its east side at y 3.0..3.85
    (-2.0, 2.0, 0.2, 2.0),
    (0.2, 2.0, 0.2, 2.925),
    (0.2, 3.925, 0.2, 4.5),
]
WAREHOUSE_ITEMS: list[Box | Cyl | Poly] = [
    *(
        Box(f"rack_{row}_{half}", cx, cy, 3.0, d, 2.0, material="Gazebo/Orange")
        for row, (cy, d) in enumerate(((-2.6, 0.9), (-0.35, 0.9), (2.2, 0.9)))
        for half, cx in enumerate((5.0, 9.0))
    ),
    Box("pallet_stack_0", -1.2, -3.5, 1.2, 1.0, 1.2),
    Box("pallet_stack_1", 0.9, -3.6, 1.2, 1.0, 0.9),
    Box("pallet_turned", 1.4, -1.9, 1.2, 1.0, 0.6, yaw=0.5),
    Box("forklift", -1.3, -1.2, 1.0, 2.0, 2.0, material="Gazebo/Yellow"),
    Box("cart", 4.5, 1.3, 0.8, 0.5, 0.9, material="Gazebo/Grey"),
    Box("office_desk", -1.2, 4.05, 1.2, 0.6, 0.75),
    Box("office_cabinet", -1.75, 2.6, 0.4, 0.8, 1.2, material="Gazebo/Grey"),
    Cyl("column_0", 2.5, -3.6, 0.2, 2.5),
    Cyl("column_1", 2.5, 3.6, 0.2, 2.5),
    Cyl("column_2", 11.2, 0.3, 0.2, 2.5),
]

# ---------------------------------------------------------------------------- apartment
APARTMENT_COMMENT = """
roverlab bundled world "apartment": 11 m x 9.5 m (x from -3 to 8, y from -4 to 5.5).
Living room (x < 3.5, y < 1.5; an L-shaped sofa as a polyline, coffee table, TV stand,
armchair, plant, a wall cut at 45 degrees across its south-west corner), open kitchen
and dining room (x > 3.5, y < 1.5; counters, fridge, an island, a round table and four
chairs) reached through a 1.2 m opening, a hallway 1.05 m clear (y 1.5..2.7) entered
through a 1.6 m double door from the living room and a 0.9 m door from the dining room;
north of it bedroom 1 (door 0.9 m; bed, nightstand, wardrobe, desk), a bathroom (door
0.8 m; bathtub, toilet, sink) and bedroom 2 (door 1.0 m; bed, wardrobe, desk, chair).
Door widths are clear openings between the wall faces.
Held out: written before roverlab explore was tuned, never tuned on.
Spawn: x=0 y=0 yaw=0 (Gazebo's default), in the living room; the nearest obstacle is
0.85 m away.
"""


Segment = tuple[float, float, float, float]


def _h_wall(y: float, x0: float, x1: float, gaps: list[tuple[float, float]]) -> list[Segment]:
    """Horizontal wall pieces at ``y`` from ``x0`` to ``x1`` around clear ``gaps`` (between
    wall faces: each piece ends WALL_T / 2 before the gap's edge)."""
    out: list[Segment] = []
    a = x0
    for g0, g1 in gaps:
        out.append((a, y, g0 - WALL_T / 2, y))
        a = g1 + WALL_T / 2
    out.append((a, y, x1, y))
    return out


def _v_wall(x: float, y0: float, y1: float, gaps: list[tuple[float, float]]) -> list[Segment]:
    return [(x, a, x, b) for a, _, b, _ in _h_wall(x, y0, y1, gaps)]


APARTMENT_WALLS = [
    (-3.0, -4.0, 8.0, -4.0),
    (8.0, -4.0, 8.0, 5.5),
    (8.0, 5.5, -3.0, 5.5),
    (-3.0, 5.5, -3.0, -4.0),
    (-3.0, -2.5, -1.5, -4.0),  # the 45 degree wall across the living room's corner
    *_h_wall(1.5, -3.0, 3.5, [(-1.0, 0.6)]),  # living room | hallway: 1.6 m double door
    *_h_wall(1.5, 3.5, 8.0, [(6.0, 6.9)]),  # dining | hallway: 0.9 m
    *_v_wall(3.5, -4.0, 1.5, [(-2.2, -1.0)]),  # living room | kitchen: 1.2 m opening
    *_h_wall(2.7, -3.0, 8.0, [(-0.5, 0.4), (2.4, 3.2), (4.0, 5.0)]),  # hallway | rooms
    (1.0, 2.7, 1.0, 5.5),
    (3.5, 2.7, 3.5, 5.5),
]
APARTMENT_ITEMS: list[Box | Cyl | Poly] = [
    Poly(
        "sofa_l",
        ((-2.85, 1.2), (-2.05, 1.2), (-2.05, -0.6), (-0.6, -0.6), (-0.6, -1.4), (-2.85, -1.4)),
        0.8,
    ),
    Box("coffee_table", -1.4, 0.4, 0.9, 0.5, 0.45),
    Box("tv_stand", 3.0, 0.6, 0.4, 1.2, 0.5),
    Cyl("armchair", -1.0, -3.2, 0.35, 0.8, material="Gazebo/Red"),
    Cyl("plant", 3.1, -3.6, 0.2, 0.9, material="Gazebo/Green"),
    Box("counter_south", 5.85, -3.625, 3.8, 0.6, 0.9, material="Gazebo/White"),
    Box("counter_east", 7.625, -2.3, 0.6, 2.0, 0.9, material="Gazebo/White"),
    Box("fridge", 7.55, -0.6, 0.7, 0.7, 1.8, material="Gazebo/White"),
    Box("island", 5.6, -1.9, 1.6, 0.8, 0.9, material="Gazebo/White"),
    Cyl("dining_table", 5.2, 0.2, 0.5, 0.75),
    Box("dining_chair_0", 4.4, 0.2, 0.42, 0.42, 0.45),
    Box("dining_chair_1", 6.0, 0.2, 0.42, 0.42, 0.45),
    Box("dining_chair_2", 5.2, -0.6, 0.42, 0.42, 0.45),
    Box("dining_chair_3", 5.2, 1.0, 0.42, 0.42, 0.45),
    Box("shoe_cabinet", 7.6, 2.1, 0.35, 1.0, 1.0),
    Box("bed_1", -2.1, 4.4, 1.6, 2.0, 0.5, material="Gazebo/Blue"),
    Box("nightstand", -1.0, 5.15, 0.45, 0.45, 0.55),
    Box("wardrobe_1", 0.3, 5.15, 1.2, 0.6, 2.0),
    Box("desk_1", 0.6, 4.0, 0.6, 1.0, 0.75),
    Box("bathtub", 1.9, 5.05, 1.6, 0.75, 0.6, material="Gazebo/White"),
    Box("toilet", 3.2, 4.9, 0.4, 0.6, 0.8, material="Gazebo/White"),
    Cyl("sink", 1.35, 3.4, 0.25, 0.85, material="Gazebo/White"),
    Box("bed_2", 6.9, 4.4, 1.4, 2.0, 0.5, material="Gazebo/Blue"),
    Box("wardrobe_2", 3.9, 4.6, 0.6, 1.5, 2.0),
    Box("desk_2", 5.3, 5.15, 1.2, 0.6, 0.75),
    Cyl("desk_chair", 5.3, 4.55, 0.22, 0.45, material="Gazebo/Black"),
]


def main(argv: list[str]) -> None:
    out = Path(argv[0]) if argv else DEFAULT_OUT
    out.mkdir(parents=True, exist_ok=True)
    worlds = {
        "warehouse": world(
            "warehouse", WAREHOUSE_COMMENT, WAREHOUSE_WALLS, WAREHOUSE_ITEMS, (5.0, -9.0)
        ),
        "apartment": world(
            "apartment", APARTMENT_COMMENT, APARTMENT_WALLS, APARTMENT_ITEMS, (2.5, -9.0)
        ),
    }
    for name, text in worlds.items():
        path = out / f"{name}.world"
        tmp = path.with_suffix(".world.part")
        tmp.write_text(text)
        tmp.replace(path)
        print(path)


if __name__ == "__main__":
    main(sys.argv[1:])
