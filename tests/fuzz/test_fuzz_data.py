"""Fuzzing the data parsers: CARMEN logs, g2o pose graphs, TUM trajectories, relations,
the CLI's message YAML, rosparam files and CDR bytes from the network (see
tests/fuzz/mutation.py for the rule every parser must keep)."""

from __future__ import annotations

from typing import Any

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from roverlab.core.parameters import load_parameter_file
from roverlab.msgs import LaserScan, deserialize, parse_yaml_message, serialize
from roverlab.slam.data.evaluation import read_relations
from roverlab.slam.data.logs import read_clf
from roverlab.slam.data.posegraph import read_g2o
from roverlab.slam.data.trajectory import read_tum
from tests.fuzz.mutation import FUZZ, clean, in_folder, mutated

_RANGES = " ".join(f"{1.0 + 0.01 * i:.2f}" for i in range(180))
CLF = (
    "# CARMEN log\nPARAM robot_frontlaser_offset 0.0 nohost 0\n"
    "ODOM 0.0 0.0 -0.002 0.0 0.0 0.0 976052857.3 nohost 0.0\n"
    f"FLASER 180 {_RANGES} 0.0 0.0 0.0 0.0 0.0 0.0 976052857.4 nohost 0.1\n"
    "ODOM 0.1 0.0 -0.002 0.1 0.0 0.0 976052857.5 nohost 0.2\n"
    f"FLASER 180 {_RANGES} 0.1 0.0 0.0 0.1 0.0 0.0 976052857.6 nohost 0.3\n"
)
G2O = (
    "VERTEX_SE2 0 0.0 0.0 0.0\nVERTEX_SE2 1 1.0 0.0 0.1\nVERTEX_SE2 2 2.0 0.1 0.2\n"
    "EDGE_SE2 0 1 1.0 0.0 0.1 500 0 0 500 0 5000\n"
    "EDGE_SE2 1 2 1.0 0.1 0.1 500 0 0 500 0 5000\n"
    "EDGE_SE2 0 2 2.0 0.1 0.2 500 0 0 500 0 5000\n"
)
TUM = (
    "# timestamp tx ty tz qx qy qz qw\n"
    "1.0 0.0 0.0 0.0 0.0 0.0 0.0 1.0\n2.0 1.0 0.0 0.0 0.0 0.0 0.0499792 0.9987503\n"
    "3.0 2.0 0.1 0.0 0.0 0.0 0.0998334 0.9950042\n"
)
RELATIONS = (
    "1.0 2.0 1.0 0.0 0.0 0.0 0.0 0.1\n2.0 3.0 1.0 0.1 0.0 0.0 0.0 0.1\n"
    "1.0 3.0 2.0 0.1 0.0 0.0 0.0 0.2\n"
)
TWIST_YAML = "{linear: {x: 0.2, y: 0.0, z: 0.0}, angular: {x: 0.0, y: 0.0, z: 0.5}}"
POSE_YAML = (
    "header: {frame_id: map}\npose:\n  position: {x: 1.0, y: 2.0}\n"
    "  orientation: {z: 0.0, w: 1.0}\n"
)
PARAMS = (
    "amcl:\n  ros__parameters:\n    min_particles: 500\n    laser_model_type: likelihood_field\n"
    "    initial_pose: [0.0, 0.0, 0.0]\n"
)


@FUZZ
@given(mutated(CLF))
def test_carmen(text: str) -> None:
    with in_folder("fuzz.clf", text) as path:
        clean(lambda: list(read_clf(path)), name="fuzz.clf")


@FUZZ
@given(mutated(G2O))
def test_g2o(text: str) -> None:
    with in_folder("fuzz.g2o", text) as path:
        clean(read_g2o, path, name="fuzz.g2o")


@FUZZ
@given(mutated(TUM))
def test_tum(text: str) -> None:
    with in_folder("fuzz.tum", text) as path:
        clean(read_tum, path, name="fuzz.tum")


@FUZZ
@given(mutated(RELATIONS))
def test_relations(text: str) -> None:
    with in_folder("fuzz.relations", text) as path:
        clean(read_relations, path, name="fuzz.relations")


@FUZZ
@given(mutated(TWIST_YAML) | mutated(POSE_YAML))
def test_message_yaml(text: str) -> None:
    typename = "geometry_msgs/msg/Twist" if "linear" in text else "geometry_msgs/msg/PoseStamped"
    clean(parse_yaml_message, typename, text)


@FUZZ
@given(mutated(PARAMS))
def test_parameter_file(text: str) -> None:
    with in_folder("params.yaml", text) as path:
        clean(load_parameter_file, path, name="params.yaml")


def _scan_bytes() -> bytes:
    scan: Any = LaserScan(
        angle_min=-1.57, angle_max=1.57, angle_increment=0.01, range_min=0.1, range_max=10.0,
        ranges=np.linspace(0.5, 5.0, 315, dtype=np.float32),
    )  # fmt: skip
    return serialize(scan)


SCAN = _scan_bytes()


@st.composite
def corrupted(draw: Any, data: bytes) -> bytes:
    """``data`` with bytes overwritten (lengths and counts included), or cut short."""
    out = bytearray(data)
    for _ in range(draw(st.integers(1, 8))):
        at = draw(st.integers(0, len(out) - 1))
        out[at] = draw(st.integers(0, 255))
    if draw(st.booleans()):
        out = out[: draw(st.integers(0, len(out)))]
    return bytes(out)


@FUZZ
@given(corrupted(SCAN) | st.binary(max_size=64))
def test_cdr_bytes(data: bytes) -> None:
    clean(deserialize, data, "sensor_msgs/msg/LaserScan")
    clean(deserialize, data, "geometry_msgs/msg/Twist")
    clean(deserialize, data, "nav_msgs/msg/OccupancyGrid")
