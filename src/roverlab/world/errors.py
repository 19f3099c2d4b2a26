"""Errors of :mod:`roverlab.world`.

Every error is a :class:`WorldError` (a :class:`~roverlab.errors.RoverlabError`) whose
message is one line naming the file (with a line number where the format has one) and the
element or key at fault, e.g. ``maze.world:42: model 'maze' / link 'Wall_3' / collision
'Wall_3_Collision' / <box><size>: needs 3 positive numbers, got '0 0.15 2.5'``.
"""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["WorldError"]


class WorldError(RoverlabError):
    """A world file (SDF, YAML world, map image) or a shape that cannot be used."""
