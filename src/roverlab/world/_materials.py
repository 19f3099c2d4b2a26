"""Colours of Gazebo materials and a reader for OGRE ``.material`` scripts (private).

``GAZEBO_MATERIALS`` approximates the diffuse colour of the materials that ship in
Gazebo's ``media/materials/scripts/gazebo.material`` (textured ones by their average
colour). User material scripts (``<script><uri>model://x/materials/scripts</uri>``) are
read for ``diffuse`` and the first ``texture`` of each ``material`` block.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

RGB = tuple[int, int, int]


def _c(r: float, g: float, b: float) -> RGB:
    return (round(r * 255), round(g * 255), round(b * 255))


GAZEBO_MATERIALS: dict[str, RGB] = {
    name.lower(): rgb
    for name, rgb in {
        "Gazebo/Grey": _c(0.7, 0.7, 0.7),
        "Gazebo/Gray": _c(0.7, 0.7, 0.7),
        "Gazebo/DarkGrey": _c(0.175, 0.175, 0.175),
        "Gazebo/DarkGray": _c(0.175, 0.175, 0.175),
        "Gazebo/LightGrey": _c(0.8, 0.8, 0.8),
        "Gazebo/White": _c(1.0, 1.0, 1.0),
        "Gazebo/WhiteGlow": _c(1.0, 1.0, 1.0),
        "Gazebo/FlatBlack": _c(0.1, 0.1, 0.1),
        "Gazebo/Black": _c(0.0, 0.0, 0.0),
        "Gazebo/Red": _c(1.0, 0.0, 0.0),
        "Gazebo/RedBright": _c(0.87, 0.26, 0.07),
        "Gazebo/RedGlow": _c(1.0, 0.0, 0.0),
        "Gazebo/Green": _c(0.0, 1.0, 0.0),
        "Gazebo/GreenGlow": _c(0.0, 1.0, 0.0),
        "Gazebo/Blue": _c(0.0, 0.0, 1.0),
        "Gazebo/BlueGlow": _c(0.0, 0.0, 1.0),
        "Gazebo/SkyBlue": _c(0.53, 0.81, 0.92),
        "Gazebo/DarkBlue": _c(0.0, 0.0, 0.4),
        "Gazebo/Yellow": _c(1.0, 1.0, 0.0),
        "Gazebo/DarkYellow": _c(0.7, 0.7, 0.0),
        "Gazebo/ZincYellow": _c(0.97, 0.95, 0.21),
        "Gazebo/Purple": _c(1.0, 0.0, 1.0),
        "Gazebo/Turquoise": _c(0.0, 1.0, 1.0),
        "Gazebo/Orange": _c(1.0, 0.51, 0.05),
        "Gazebo/Indigo": _c(0.33, 0.0, 0.5),
        "Gazebo/Gold": _c(0.8, 0.64, 0.25),
        "Gazebo/Wood": _c(0.55, 0.38, 0.22),
        "Gazebo/WoodFloor": _c(0.6, 0.45, 0.3),
        "Gazebo/WoodPallet": _c(0.65, 0.52, 0.36),
        "Gazebo/Bricks": _c(0.6, 0.32, 0.25),
        "Gazebo/CeilingTiled": _c(0.85, 0.85, 0.85),
        "Gazebo/PaintedWall": _c(0.85, 0.84, 0.8),
        "Gazebo/Grass": _c(0.3, 0.55, 0.2),
        "Gazebo/Dirt": _c(0.45, 0.35, 0.25),
        "Gazebo/Road": _c(0.3, 0.3, 0.3),
        "Gazebo/Residential": _c(0.35, 0.35, 0.35),
        "Gazebo/Asphalt": _c(0.25, 0.25, 0.25),
        "Gazebo/Rocky": _c(0.5, 0.47, 0.44),
        "Gazebo/Chrome": _c(0.8, 0.8, 0.82),
        "Gazebo/Motorway": _c(0.3, 0.3, 0.3),
    }.items()
}


@dataclass(frozen=True)
class ScriptMaterial:
    """One ``material`` block of an OGRE script."""

    name: str
    rgb: RGB | None
    texture: Path | None
    parent: str | None


_BLOCK = re.compile(r"\bmaterial\s+([^\s{:]+)\s*(?::\s*([^\s{]+))?\s*\{")
_DIFFUSE = re.compile(r"^\s*diffuse\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)", re.M)
_TEXTURE = re.compile(r"^\s*texture\s+(\S+)", re.M)


def read_material_script(path: Path) -> list[ScriptMaterial]:
    """The material blocks of an OGRE ``.material`` file (unreadable files give none)."""
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return []
    text = re.sub(r"//[^\n]*", "", text)
    found: list[ScriptMaterial] = []
    for m in _BLOCK.finditer(text):
        depth = 1
        i = m.end()
        while i < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[i], 0)
            i += 1
        body = text[m.end() : i]
        rgb: RGB | None = None
        d = _DIFFUSE.search(body)
        if d:
            try:
                vals = [min(1.0, max(0.0, float(v))) for v in d.groups()]
                rgb = _c(vals[0], vals[1], vals[2])
            except ValueError:
                rgb = None
        t = _TEXTURE.search(body)
        found.append(
            ScriptMaterial(
                name=m.group(1),
                rgb=rgb,
                texture=Path(t.group(1)) if t else None,
                parent=m.group(2),
            )
        )
    return found
