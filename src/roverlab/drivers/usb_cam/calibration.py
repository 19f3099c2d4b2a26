"""camera_calibration_parsers' YAML: what ``camera_info_url`` points at.

The layout ``cameracalibrator.py`` writes (``ost.yaml``)::

    image_width: 640
    image_height: 480
    camera_name: head_camera
    camera_matrix: {rows: 3, cols: 3, data: [fx, 0, cx, 0, fy, cy, 0, 0, 1]}
    distortion_model: plumb_bob
    distortion_coefficients: {rows: 1, cols: 5, data: [k1, k2, t1, t2, k3]}
    rectification_matrix: {rows: 3, cols: 3, data: [...]}
    projection_matrix: {rows: 3, cols: 4, data: [...]}
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from roverlab.drivers.errors import DriverError
from roverlab.fileio import atomic_write_text

__all__ = ["CameraCalibration", "load_calibration", "save_calibration"]


def _eye(n: int) -> list[float]:
    return [float(v) for v in np.eye(n).reshape(-1)]


@dataclass(frozen=True, kw_only=True)
class CameraCalibration:
    """One camera's intrinsics (sensor_msgs/CameraInfo's K, D, R, P)."""

    image_width: int
    image_height: int
    camera_name: str = ""
    camera_matrix: list[float] = field(default_factory=lambda: [0.0] * 9)
    distortion_model: str = "plumb_bob"
    distortion_coefficients: list[float] = field(default_factory=list)
    rectification_matrix: list[float] = field(default_factory=lambda: _eye(3))
    projection_matrix: list[float] = field(default_factory=lambda: [0.0] * 12)

    def to_dict(self) -> dict[str, Any]:
        def mat(rows: int, cols: int, data: list[float]) -> dict[str, Any]:
            return {"rows": rows, "cols": cols, "data": [float(v) for v in data]}

        return {
            "image_width": self.image_width,
            "image_height": self.image_height,
            "camera_name": self.camera_name,
            "camera_matrix": mat(3, 3, self.camera_matrix),
            "distortion_model": self.distortion_model,
            "distortion_coefficients": mat(
                1, len(self.distortion_coefficients), self.distortion_coefficients
            ),
            "rectification_matrix": mat(3, 3, self.rectification_matrix),
            "projection_matrix": mat(3, 4, self.projection_matrix),
        }


def _matrix(data: dict[str, Any], key: str, size: int | None, where: str) -> list[float]:
    block = data.get(key)
    if block is None:
        raise DriverError(f"{where}: missing {key}")
    values = block.get("data") if isinstance(block, dict) else None
    if not isinstance(values, list) or not all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in values
    ):
        raise DriverError(f"{where}: {key}.data must be a list of numbers")
    if size is not None and len(values) != size:
        raise DriverError(f"{where}: {key} needs {size} numbers, got {len(values)}")
    rows, cols = (block.get("rows"), block.get("cols")) if isinstance(block, dict) else (0, 0)
    if isinstance(rows, int) and isinstance(cols, int) and rows * cols != len(values):
        raise DriverError(
            f"{where}: {key} is {block['rows']}x{block['cols']} but has {len(values)} numbers"
        )
    return [float(v) for v in values]


def load_calibration(path: str | os.PathLike[str]) -> CameraCalibration:
    """Read a calibration YAML file.

    Raises:
        DriverError: the file is missing, not YAML, or lacks a field (one line naming it).
    """
    p = Path(path)
    try:
        data = yaml.safe_load(p.read_text(encoding="utf-8"))
    except OSError as err:
        raise DriverError(f"{p}: cannot read camera calibration: {err.strerror}") from err
    except yaml.YAMLError as err:
        first = str(err).splitlines()[0]
        raise DriverError(f"{p}: malformed camera calibration YAML: {first}") from err
    if not isinstance(data, dict):
        raise DriverError(f"{p}: a camera calibration must be a YAML mapping")
    where = str(p)
    try:
        width, height = int(data["image_width"]), int(data["image_height"])
    except (KeyError, TypeError, ValueError) as err:
        raise DriverError(f"{where}: image_width and image_height must be integers") from err
    return CameraCalibration(
        image_width=width,
        image_height=height,
        camera_name=str(data.get("camera_name", "")),
        camera_matrix=_matrix(data, "camera_matrix", 9, where),
        distortion_model=str(data.get("distortion_model", "plumb_bob")),
        distortion_coefficients=_matrix(data, "distortion_coefficients", None, where),
        rectification_matrix=_matrix(data, "rectification_matrix", 9, where),
        projection_matrix=_matrix(data, "projection_matrix", 12, where),
    )


def save_calibration(calibration: CameraCalibration, path: str | os.PathLike[str]) -> None:
    """Write a calibration YAML file (atomically: a temporary file renamed into place)."""
    p = Path(path)
    text = yaml.safe_dump(calibration.to_dict(), sort_keys=False, default_flow_style=None)
    atomic_write_text(p, text)
