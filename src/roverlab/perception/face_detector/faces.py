"""Face detection as the people stack's ``Faces`` class does it, on numpy images.

* OpenCV's Haar cascade (``haarcascade_frontalface_alt.xml`` by default) over the
  histogram-equalised grey image, scale step 1.2, 2 neighbours, Canny pruning;
* with a depth image and the camera's intrinsics, each box gets a 3-D centre (the median
  valid depth in the middle half of the box, back-projected through K) and a width in
  metres (box width * z / fx): ``good`` when ``face_size_min_m <= width <= face_size_max_m``
  and ``z <= max_face_z_m``, else ``bad``;
* without depth (RGB-only), every box is ``unknown``: its size cannot be checked.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final, Literal

import cv2
import numpy as np
from numpy.typing import NDArray

from roverlab.perception.errors import PerceptionError

__all__ = ["DEFAULT_CLASSIFIER", "Face", "FaceSizeLimits", "Faces", "draw_faces"]

DEFAULT_CLASSIFIER: Final = (
    Path(cv2.data.haarcascades)  # type: ignore[attr-defined]
    / "haarcascade_frontalface_alt.xml"
)
"""OpenCV's frontal face (alt) cascade, face_detector's usual ``classifier_filename``."""

Status = Literal["good", "bad", "unknown"]
_COLOURS: Final[dict[str, tuple[int, int, int]]] = {
    "good": (0, 255, 0),
    "unknown": (0, 0, 255),
    "bad": (255, 0, 0),
}  # RGB: face_detector draws good green, unknown blue, bad red


@dataclass(frozen=True, kw_only=True)
class FaceSizeLimits:
    """face_detector's size checks (used where depth is known)."""

    face_size_min_m: float = 0.1
    face_size_max_m: float = 0.5
    max_face_z_m: float = 8.0

    def __post_init__(self) -> None:
        values = (self.face_size_min_m, self.face_size_max_m, self.max_face_z_m)
        if not all(math.isfinite(v) and v >= 0 for v in values):
            raise PerceptionError(f"face size limits must be finite and >= 0, got {values}")
        if self.face_size_min_m > self.face_size_max_m:
            raise PerceptionError(
                f"face_size_min_m ({self.face_size_min_m}) > face_size_max_m "
                f"({self.face_size_max_m})"
            )


@dataclass(frozen=True)
class Face:
    """One detection: the box in pixels, and in 3-D where depth is known.

    Attributes:
        box: ``(x, y, width, height)`` in pixels.
        status: ``good`` / ``bad`` (depth known, size checked) or ``unknown``.
        center3d: ``(x, y, z)`` in the camera's optical frame (m), or None.
        width_m: the face's width in metres, or None.
    """

    box: tuple[int, int, int, int]
    status: Status
    center3d: tuple[float, float, float] | None = None
    width_m: float | None = None

    @property
    def center_px(self) -> tuple[float, float]:
        x, y, w, h = self.box
        return x + w / 2.0, y + h / 2.0


class Faces:
    """A Haar-cascade face detector with face_detector's size checks.

    Args:
        classifier_filename: the cascade XML (default :data:`DEFAULT_CLASSIFIER`).
        limits: the size checks applied where depth is known.

    Raises:
        PerceptionError: the cascade file is missing or not a cascade.
    """

    def __init__(
        self,
        classifier_filename: str | os.PathLike[str] = DEFAULT_CLASSIFIER,
        *,
        limits: FaceSizeLimits | None = None,
    ) -> None:
        path = Path(classifier_filename)
        if not path.is_file():
            raise PerceptionError(f"{path}: no such Haar cascade file")
        try:
            self.cascade = cv2.CascadeClassifier(str(path))
        except (cv2.error, SystemError) as err:  # OpenCV throws on a malformed file
            raise PerceptionError(f"{path}: not an OpenCV Haar cascade") from err
        if self.cascade.empty():
            raise PerceptionError(f"{path}: not an OpenCV Haar cascade")
        self.classifier_filename = path
        self.limits = limits or FaceSizeLimits()

    def detect_boxes(self, rgb: NDArray[Any]) -> list[tuple[int, int, int, int]]:
        """Face boxes ``(x, y, w, h)`` in an RGB (or grey) ``uint8`` image."""
        if rgb.ndim == 3:
            grey = cv2.cvtColor(np.ascontiguousarray(rgb[:, :, :3]), cv2.COLOR_RGB2GRAY)
        else:
            grey = np.ascontiguousarray(rgb)
        grey = cv2.equalizeHist(grey.astype(np.uint8))
        found = self.cascade.detectMultiScale(
            grey,
            scaleFactor=1.2,
            minNeighbors=2,
            flags=cv2.CASCADE_DO_CANNY_PRUNING,
            minSize=(1, 1),
        )
        return [(int(x), int(y), int(w), int(h)) for x, y, w, h in np.asarray(found).reshape(-1, 4)]

    def detect(
        self,
        rgb: NDArray[Any],
        depth_m: NDArray[Any] | None = None,
        k: NDArray[Any] | None = None,
    ) -> list[Face]:
        """Faces in ``rgb``; sized and placed in 3-D when ``depth_m`` (metres, same size
        as the image, 0 or NaN where unknown) and the 3x3 intrinsics ``k`` are given."""
        boxes = self.detect_boxes(rgb)
        if depth_m is None or k is None:
            return [Face(b, "unknown") for b in boxes]
        if depth_m.shape[:2] != rgb.shape[:2]:
            raise PerceptionError(
                f"depth image {depth_m.shape[:2]} and colour image {rgb.shape[:2]} differ in size"
            )
        fx, fy, cx, cy = float(k[0, 0]), float(k[1, 1]), float(k[0, 2]), float(k[1, 2])
        if fx <= 0 or fy <= 0:
            return [Face(b, "unknown") for b in boxes]
        return [self._sized(b, depth_m, fx, fy, cx, cy) for b in boxes]

    def _sized(
        self,
        box: tuple[int, int, int, int],
        depth_m: NDArray[Any],
        fx: float,
        fy: float,
        cx: float,
        cy: float,
    ) -> Face:
        x, y, w, h = box
        inner = depth_m[y + h // 4 : y + h - h // 4, x + w // 4 : x + w - w // 4]
        values = inner[np.isfinite(inner) & (inner > 0)]
        if values.size == 0:
            return Face(box, "unknown")
        z = float(np.median(values))
        u, v = x + w / 2.0, y + h / 2.0
        center = ((u - cx) * z / fx, (v - cy) * z / fy, z)
        width_m = w * z / fx
        lim = self.limits
        ok = lim.face_size_min_m <= width_m <= lim.face_size_max_m and z <= lim.max_face_z_m
        return Face(box, "good" if ok else "bad", center, width_m)


def draw_faces(rgb: NDArray[Any], faces: list[Face]) -> NDArray[np.uint8]:
    """A copy of the image with each face's box drawn as face_detector's display does
    (good green, unknown blue, bad red, 4 px)."""
    out = np.array(rgb, dtype=np.uint8, copy=True)
    if out.ndim == 2:
        out = np.asarray(cv2.cvtColor(out, cv2.COLOR_GRAY2RGB), dtype=np.uint8)
    for face in faces:
        x, y, w, h = face.box
        cv2.rectangle(out, (x, y), (x + w, y + h), _COLOURS[face.status], 4)
    return out
