"""The people stack's ``face_detector``: Haar-cascade faces, sized where depth is known.

:class:`~roverlab.perception.face_detector.faces.Faces` is the algorithm (the people
stack's ``Faces`` class); :mod:`roverlab.perception.face_detector.node` is the node.
"""

from __future__ import annotations

from roverlab.perception.face_detector.faces import (
    DEFAULT_CLASSIFIER,
    Face,
    Faces,
    FaceSizeLimits,
    draw_faces,
)

__all__ = ["DEFAULT_CLASSIFIER", "Face", "FaceSizeLimits", "Faces", "draw_faces"]
