"""The ``note:`` lines of a world file: what it says that the simulator runs otherwise than
Gazebo would (``World.notes``; ``--strict`` does not refuse them)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

__all__ = ["movable_note", "world_notes"]


def movable_note(path: Path, names: list[str]) -> tuple[str, ...]:
    """Models not ``<static>``: Gazebo would let a robot push them; they stay put here."""
    if not names:
        return ()
    shown = ", ".join(names[:8]) + (f" and {len(names) - 8} more" if len(names) > 8 else "")
    return (
        f"{path}: {len(names)} model{'s' if len(names) != 1 else ''} not <static> (Gazebo "
        f"lets a robot push them) kept as fixed obstacles: {shown}",
    )


def world_notes(path: Path, world: ET.Element | None) -> tuple[str, ...]:
    """The world's settings of Gazebo's own that the simulator does not act on: its
    ``<physics>`` step and rate when they differ from Gazebo's defaults (roverlab steps at
    the ``physics_rate`` parameter and runs at ``--rate``), and its world plugins (none
    for a file that holds models only)."""
    if world is None:
        return ()
    out: list[str] = []
    physics = [
        f"{el.tag} {(el.text or '').strip()}"
        for ph in world.findall("physics")
        for el in ph
        if el.tag in _PHYSICS_TIMING and not _is_number(el.text, _PHYSICS_TIMING[el.tag])
    ]
    if physics:
        out.append(
            f"{path}: <physics> not used (the simulator steps at its physics_rate parameter, "
            f"100 Hz by default, and runs at --rate): {', '.join(physics)}"
        )
    plugins = [el.get("filename") or el.get("name") or "?" for el in world.findall("plugin")]
    if plugins:
        out.append(f"{path}: world plugins not run: {', '.join(plugins)}")
    return tuple(out)


# Gazebo's defaults, which every saved world repeats: real time, as roverlab runs by default
_PHYSICS_TIMING = {"max_step_size": 0.001, "real_time_update_rate": 1000.0, "real_time_factor": 1.0}


def _is_number(text: str | None, value: float) -> bool:
    try:
        return float((text or "").strip()) == value
    except ValueError:
        return False
