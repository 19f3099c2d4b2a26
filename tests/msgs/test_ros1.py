"""ROS 1 serialisation: Noetic's definitions and md5sums, bytes both ways, bag-carried types.

The md5 table is Noetic's (``rosmsg md5``); one test holds it against Debian's real message
classes (python3-*-msgs 1.15), and one feeds our bytes to those classes.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from roverlab import msgs
from roverlab.msgs import EXPOSED_TYPES, SerializationError, UnknownTypeError
from roverlab.msgs.ros1 import (
    deserialize_ros1,
    register_ros1_definition,
    ros1_definition,
    ros1_typename,
    serialize_ros1,
)

NOETIC = get_typestore(Stores.ROS1_NOETIC)
SYSTEM_PYTHON = Path("/usr/bin/python3")

#: Noetic's md5sums of the types roverlab publishes and records (from `rosmsg md5`).
MD5: dict[str, str] = {
    "std_msgs/Header": "2176decaecbce78abc3b96ef049fabed",
    "std_msgs/String": "992ce8a1687cec8c8bd883ec73ca41d1",
    "std_msgs/Bool": "8b94c1b53db61fb6aed406028ad6332a",
    "std_msgs/Byte": "ad736a2e8818154c487bb80fe42ce43b",
    "std_msgs/Char": "1bf77f25acecdedba0e224b162199717",
    "std_msgs/Empty": "d41d8cd98f00b204e9800998ecf8427e",
    "std_msgs/ColorRGBA": "a29a96539573343b1310c73607334b00",
    "std_msgs/Float32": "73fcbf46b49191e672908e50842a83d4",
    "std_msgs/Float64": "fdb28210bfa9d7c91146260178d9a584",
    "std_msgs/Int8": "27ffa0c9c4b8fb8492252bcad9e5c57b",
    "std_msgs/Int16": "8524586e34fbd7cb1c08c5f5f1ca0e57",
    "std_msgs/Int32": "da5909fbe378aeaf85e547e830cc1bb7",
    "std_msgs/Int64": "34add168574510e6e17f5d23ecc077ef",
    "std_msgs/UInt8": "7c8164229e7d2c17eb95e9231617fdee",
    "std_msgs/UInt16": "1df79edf208b629fe6b81923a544552d",
    "std_msgs/UInt32": "304a39449588c7f8ce2df6e8001c5fce",
    "std_msgs/UInt64": "1b2a79973e8bf53d7b53acb71299cb57",
    "std_msgs/Float32MultiArray": "6a40e0ffa6a17a503ac3f8616991b1f6",
    "std_msgs/Float64MultiArray": "4b7d974086d4060e7db4613a7e6c3ba4",
    "std_msgs/MultiArrayLayout": "0fed2a11c13e11c5571b4e2a995a91a3",
    "std_msgs/MultiArrayDimension": "4cd0c83a8683deae40ecdac60e53bfa8",
    "geometry_msgs/Point": "4a842b65f413084dc2b10fb484ea7f17",
    "geometry_msgs/Point32": "cc153912f1453b708d221682bc23d9ac",
    "geometry_msgs/PointStamped": "c63aecb41bfdfd6b7e1fac37c7cbe7bf",
    "geometry_msgs/Quaternion": "a779879fadf0160734f906b8c19c7004",
    "geometry_msgs/QuaternionStamped": "e57f1e547e0e1fd13504588ffc8334e2",
    "geometry_msgs/Vector3": "4a842b65f413084dc2b10fb484ea7f17",
    "geometry_msgs/Vector3Stamped": "7b324c7325e683bf02a9b14b01090ec7",
    "geometry_msgs/Pose": "e45d45a5a1ce597b249e23fb30fc871f",
    "geometry_msgs/Pose2D": "938fa65709584ad8e77d238529be13b8",
    "geometry_msgs/PoseStamped": "d3812c3cbc69362b77dc0b19b345f8f5",
    "geometry_msgs/PoseWithCovariance": "c23e848cf1b7533a8d7c259073a97e6f",
    "geometry_msgs/PoseWithCovarianceStamped": "953b798c0f514ff060a53a3498ce6246",
    "geometry_msgs/PoseArray": "916c28c5764443f268b296bb671b9d97",
    "geometry_msgs/Twist": "9f195f881246fdfa2798d1d3eebca84a",
    "geometry_msgs/TwistStamped": "98d34b0043a2093cf9d9345ab6eef12e",
    "geometry_msgs/TwistWithCovariance": "1fe8a28e6890a4cc3ae4c3ca5c7d82e6",
    "geometry_msgs/TwistWithCovarianceStamped": "8927a1a12fb2607ceea095b2dc440a96",
    "geometry_msgs/Accel": "9f195f881246fdfa2798d1d3eebca84a",
    "geometry_msgs/AccelStamped": "d8a98a5d81351b6eb0578c78557e7659",
    "geometry_msgs/AccelWithCovariance": "ad5a718d699c6be72a02b8d6a139f334",
    "geometry_msgs/AccelWithCovarianceStamped": "96adb295225031ec8d57fb4251b0a886",
    "geometry_msgs/Wrench": "4f539cf138b23283b520fd271b567936",
    "geometry_msgs/WrenchStamped": "d78d3cb249ce23087ade7e7d0c40cfa7",
    "geometry_msgs/Transform": "ac9eff44abf714214112b05d54a3cf9b",
    "geometry_msgs/TransformStamped": "b5764a33bfeb3588febc2682852579b0",
    "geometry_msgs/Polygon": "cd60a26494a087f577976f0329fa120e",
    "geometry_msgs/PolygonStamped": "c6be8f7dc3bee7fe9e8d296070f53340",
    "sensor_msgs/LaserScan": "90c7ef2dc6895d81024acba2ac42f369",
    "sensor_msgs/Imu": "6a62c6daae103f4ff57a132d6f95cec2",
    "sensor_msgs/Image": "060021388200f6f0f447d0fcd9c64743",
    "sensor_msgs/CompressedImage": "8f7a12909da2c9d3332d540a0977563f",
    "sensor_msgs/CameraInfo": "c9a58c1b0b154e0e6da7578cb991d214",
    "sensor_msgs/RegionOfInterest": "bdb633039d588fcccb441a4d43ccfe09",
    "sensor_msgs/PointCloud": "d8e9c3f5afbdd8a130fd1d2763945fca",
    "sensor_msgs/PointCloud2": "1158d486dd51d683ce2f1be655c3c181",
    "sensor_msgs/PointField": "268eacb2962780ceac86cbd17e328150",
    "sensor_msgs/JointState": "3066dcd76a6cfaef579bd0f34173e9fd",
    "sensor_msgs/Range": "c005c34273dc426c67a020a87bc24148",
    "sensor_msgs/NavSatFix": "2d3a8cd499b9b4a0249fb98fd05cfa48",
    "sensor_msgs/NavSatStatus": "331cdbddfa4bc96ffc3b9ad98900a54c",
    "sensor_msgs/Joy": "5a9ea5f83505693b71e785041e67a8bb",
    "sensor_msgs/BatteryState": "4ddae7f048e32fda22cac764685e3974",
    "sensor_msgs/MagneticField": "2f3b0b43eed0c9501de0fa3ff89a45aa",
    "sensor_msgs/Temperature": "ff71b307acdbe7c871a5a6d7ed359100",
    "nav_msgs/Odometry": "cd5e73d190d741a2f92e81eda573aca7",
    "nav_msgs/OccupancyGrid": "3381f2d731d4076ec5c71b0759edbe4e",
    "nav_msgs/MapMetaData": "10cfc8a2818024d3248802c00c95f11b",
    "nav_msgs/Path": "6227e2b7e9cce15051f669a5e197bbf7",
    "nav_msgs/GridCells": "b9e4f5df6d28e272ebde00a3994830f5",
    "tf2_msgs/TFMessage": "94810edda583a504dfda3829e70d7eec",
    "rosgraph_msgs/Clock": "a9c97c1d230cfc112e270351a944ee47",
    "rosgraph_msgs/Log": "acffd30cd6b6de30f120938c17c593fb",
    "visualization_msgs/Marker": "4048c9de2a16f4ae8e0538085ebf1b97",
    "visualization_msgs/MarkerArray": "d155b9ce5188fbaf89745847fd5882d7",
    "actionlib_msgs/GoalID": "302881f31927c1df708a2dbab0e80ee8",
    "actionlib_msgs/GoalStatusArray": "8b2b82f13216d0a8ea88bd3af735e619",
    # python3-diagnostic-msgs is not among Debian's packages; these are ROS wiki's
    "diagnostic_msgs/DiagnosticArray": "60810da900de1dd6ddd437c3503511da",
    "diagnostic_msgs/DiagnosticStatus": "d0ce08bc6e5ba34c7754f563a9cabaf1",
    "diagnostic_msgs/KeyValue": "cf57fdc6617a881a88c16e768132149c",
}

#: Types of the runtime whose ROS 1 layout is Noetic's with the same fields (every field
#: survives a round trip); the others (Marker, Range) lose their ROS 2-only fields.
CHANGED = {
    "sensor_msgs/msg/Range",
    "visualization_msgs/msg/Marker",
    "visualization_msgs/msg/MarkerArray",
}


def test_md5_table_is_what_ros1_definition_gives() -> None:
    got = {name: ros1_definition(name)[1] for name in MD5}
    assert got == MD5


def test_every_exposed_type_noetic_has_is_in_the_table() -> None:
    names = {ros1_typename(t) for t in EXPOSED_TYPES}
    in_noetic = {n for n in names if "/msg/".join(n.split("/")) in NOETIC.fielddefs}
    in_noetic -= {"builtin_interfaces/Time", "builtin_interfaces/Duration"}  # ROS 1 primitives
    assert in_noetic <= set(MD5), in_noetic - set(MD5)


def test_definitions_parse_back_to_the_same_md5() -> None:
    for name in ("sensor_msgs/LaserScan", "tf2_msgs/TFMessage", "visualization_msgs/MarkerArray"):
        text, md5 = ros1_definition(name)
        full = "/msg/".join(name.split("/"))
        store = get_typestore(Stores.EMPTY)
        store.register(get_types_from_msg(text, full))
        assert store.generate_msgdef(full, ros_version=1) == (text, md5)
    text, _ = ros1_definition("nav_msgs/Odometry")
    assert text.startswith("std_msgs/Header header\n")
    assert "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id" in text


@pytest.mark.parametrize("typename", sorted(set(EXPOSED_TYPES) - CHANGED))
def test_round_trip_in_noetic_layout(
    typename: str, filler: Callable[[str], Any], same: Callable[[Any, Any], None]
) -> None:
    msg = msgs.Empty() if typename == "std_msgs/msg/Empty" else filler(typename)
    data = serialize_ros1(msg)
    if typename in NOETIC.fielddefs:  # rosbags' own Noetic classes read every byte
        assert bytes(NOETIC.serialize_ros1(NOETIC.deserialize_ros1(data, typename), typename)) == (
            data
        )
    same(deserialize_ros1(data, typename), msg)


def test_header_seq_is_written_and_stamps_kept() -> None:
    odom = msgs.Odometry(header_frame_id="odom", child_frame_id="base_footprint")
    odom.header.stamp = msgs.time_from_ns(12_000_000_345)
    data = serialize_ros1(odom, seq=77)
    ros1: Any = NOETIC.deserialize_ros1(data, "nav_msgs/msg/Odometry")
    assert (ros1.header.seq, ros1.header.stamp.sec, ros1.header.stamp.nanosec) == (77, 12, 345)
    back = deserialize_ros1(data, "nav_msgs/Odometry")
    assert msgs.time_to_ns(back.header.stamp) == 12_000_000_345
    assert back.child_frame_id == "base_footprint"
    assert serialize_ros1(back) == serialize_ros1(odom)  # seq 0 unless given


def test_types_with_other_layouts_keep_their_common_fields() -> None:
    marker = msgs.Marker(header_frame_id="map", ns="walls", id=4, text="hi")
    marker.texture_resource = "file://x.png"  # ROS 2 only
    array = msgs.MarkerArray(markers=[marker])
    data = serialize_ros1(array)
    ros1: Any = NOETIC.deserialize_ros1(data, "visualization_msgs/msg/MarkerArray")
    assert (ros1.markers[0].ns, ros1.markers[0].id, ros1.markers[0].text) == ("walls", 4, "hi")
    back = deserialize_ros1(data, "visualization_msgs/MarkerArray").markers[0]
    assert (back.ns, back.id, back.text, back.texture_resource) == ("walls", 4, "hi", "")
    assert back.pose.orientation.w == 1.0
    rng = msgs.Range(radiation_type=1, field_of_view=0.5, min_range=0.1, max_range=4.0, range=2.0)
    got = deserialize_ros1(serialize_ros1(rng), "sensor_msgs/Range")
    assert (got.radiation_type, got.range, got.max_range) == (1, 2.0, 4.0)


def test_bad_bytes_are_one_serialization_error() -> None:
    data = serialize_ros1(
        msgs.make_scan(
            ranges=np.ones(10), angle_min=-1.0, angle_max=1.0, range_min=0.1, range_max=5.0
        )
    )
    with pytest.raises(SerializationError, match="LaserScan"):
        deserialize_ros1(data[:-3], "sensor_msgs/LaserScan")
    with pytest.raises(SerializationError, match="left over"):
        deserialize_ros1(data + b"\0", "sensor_msgs/LaserScan")
    with pytest.raises(SerializationError):
        deserialize_ros1(b"\xff" * 40, "sensor_msgs/LaserScan")
    with pytest.raises(UnknownTypeError):
        deserialize_ros1(data, "nope_msgs/Scan")


def test_a_type_known_only_from_its_definition_text() -> None:
    text = "Header header\nfloat64 value\nstring[] names\ngeometry_msgs/Point[2] corners\n"
    name = "roverlab_test_msgs/msg/Reading"
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(get_types_from_msg(text, name))
    full_text, md5 = store.generate_msgdef(name, ros_version=1)
    cls = store.types[name]
    point = store.types["geometry_msgs/msg/Point"]
    header = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"]
    msg = cls(header(5, stamp(3, 4), "base"), 2.5, ["a", "b"], [point(1, 2, 3), point(4, 5, 6)])
    data = bytes(store.serialize_ros1(msg, name))

    assert register_ros1_definition("roverlab_test_msgs/Reading", full_text, md5) == name
    got = deserialize_ros1(data, "roverlab_test_msgs/Reading")
    assert (got.value, got.names, got.corners[1].y, got.header.stamp.nanosec) == (
        2.5,
        ["a", "b"],
        5.0,
        4,
    )
    assert ros1_definition(name) == (full_text, md5)
    assert serialize_ros1(got, seq=5) == data
    with pytest.raises(UnknownTypeError, match="md5sum"):
        register_ros1_definition("sensor_msgs/LaserScan", "float64 x\n", "0" * 32)


_DEBIAN_SCRIPT = r"""
import importlib, json, sys
job = json.load(sys.stdin)
out = {"md5": {}, "bytes": {}}
def cls_of(name):
    pkg, short = name.split("/")
    return getattr(importlib.import_module(pkg + ".msg"), short)
for name in job["md5"]:
    try:
        out["md5"][name] = cls_of(name)._md5sum
    except ImportError:
        pass
for name, hexdata in job["bytes"].items():
    msg = cls_of(name)().deserialize(bytes.fromhex(hexdata))
    import io
    buf = io.BytesIO()
    msg.serialize(buf)
    out["bytes"][name] = buf.getvalue().hex()
json.dump(out, sys.stdout)
"""


def _debian_ros_msgs() -> bool:
    if not SYSTEM_PYTHON.exists() or shutil.which("roscore") is None:
        return False
    probe = subprocess.run(
        [str(SYSTEM_PYTHON), "-c", "import sensor_msgs.msg, tf2_msgs.msg"],
        capture_output=True,
        check=False,
    )
    return probe.returncode == 0


def test_debian_message_classes_agree(filler: Callable[[str], Any]) -> None:
    if not _debian_ros_msgs():
        pytest.skip("Debian's ROS 1 message packages (scripts/install-system-deps.sh) missing")
    samples = {
        "sensor_msgs/LaserScan": filler("sensor_msgs/msg/LaserScan"),
        "nav_msgs/Odometry": filler("nav_msgs/msg/Odometry"),
        "tf2_msgs/TFMessage": filler("tf2_msgs/msg/TFMessage"),
        "sensor_msgs/CameraInfo": filler("sensor_msgs/msg/CameraInfo"),
        "nav_msgs/OccupancyGrid": filler("nav_msgs/msg/OccupancyGrid"),
        "visualization_msgs/MarkerArray": msgs.MarkerArray(
            markers=[msgs.Marker(ns="n", id=2, points=[msgs.Point(x=1.0)])]
        ),
    }
    ours = {name: serialize_ros1(msg, seq=9).hex() for name, msg in samples.items()}
    job = json.dumps({"md5": list(MD5), "bytes": ours})
    done = subprocess.run(
        [str(SYSTEM_PYTHON), "-c", _DEBIAN_SCRIPT],
        input=job,
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    )
    theirs = json.loads(done.stdout)
    assert len(theirs["md5"]) >= len(MD5) - 3
    assert theirs["md5"] == {name: MD5[name] for name in theirs["md5"]}
    assert theirs["bytes"] == ours  # Debian's classes read every byte and write them back
