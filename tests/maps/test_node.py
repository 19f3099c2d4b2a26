"""map_server and map_saver nodes on the deterministic executor."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context, QoSProfile
from roverlab.maps import MapError, load_map, save_map
from roverlab.maps.node import MapSaver, MapServer
from roverlab.msgs import (
    MapMetaData,
    OccupancyGrid,
    array_to_occupancy_grid,
    occupancy_grid_to_array,
    xytheta_from_pose,
)

LATCHED = QoSProfile(depth=1, durability="transient_local")


@pytest.fixture
def map_file(tmp_path: Path) -> tuple[Path, np.ndarray]:
    data = np.random.default_rng(7).choice(np.array([-1, 0, 100], np.int8), size=(24, 31))
    saved = save_map(tmp_path / "office", data, resolution=0.05, origin=(-1.0, 2.0, 0.25))
    return saved.yaml_path, data


def test_map_server_latches_map_for_late_subscribers(map_file: tuple[Path, np.ndarray]) -> None:
    path, data = map_file
    ctx = Context()
    server = MapServer(ctx, yaml_path=path)
    ctx.spin_for(2.0)
    maps: list[Any] = []
    metas: list[Any] = []
    late = ctx.create_node("late")
    late.create_subscription(OccupancyGrid, "/map", maps.append, LATCHED)
    late.create_subscription(MapMetaData, "/map_metadata", metas.append, LATCHED)
    ctx.spin_for(0.5)
    assert len(maps) == 1 and len(metas) == 1
    msg = maps[0]
    assert np.array_equal(occupancy_grid_to_array(msg), data)
    assert msg.header.frame_id == "map"
    assert msg.info.resolution == pytest.approx(0.05)
    assert xytheta_from_pose(msg.info.origin) == pytest.approx((-1.0, 2.0, 0.25))
    assert (metas[0].width, metas[0].height) == (31, 24)
    assert server.get_parameter("frame_id").value == "map"
    ctx.shutdown()


def test_map_server_static_map_service(map_file: tuple[Path, np.ndarray]) -> None:
    path, data = map_file
    ctx = Context()
    MapServer(ctx, yaml_path=path)
    client = ctx.create_node("amcl").create_client("nav_msgs/GetMap", "static_map")
    assert client.wait_for_service(timeout_sec=0.0)
    future = client.call_async({})
    assert ctx.spin_until_future_complete(future, timeout_sec=5)
    got = future.result().map
    assert np.array_equal(occupancy_grid_to_array(got), data)
    assert got.header.frame_id == "map" and got.info.width == 31
    ctx.shutdown()


def test_map_server_frame_id_parameter(map_file: tuple[Path, np.ndarray]) -> None:
    path, _ = map_file
    ctx = Context()
    MapServer(ctx, yaml_path=path, parameter_overrides={"frame_id": "world"})
    got: list[Any] = []
    ctx.create_node("sub").create_subscription(OccupancyGrid, "map", got.append, LATCHED)
    ctx.spin_for(0.1)
    assert got[0].header.frame_id == "world"
    ctx.shutdown()


def test_map_server_bad_file(tmp_path: Path) -> None:
    ctx = Context()
    with pytest.raises(MapError, match=re.escape("missing.yaml: map file not found")):
        MapServer(ctx, yaml_path=tmp_path / "missing.yaml")
    ctx.shutdown()


def test_map_saver_writes_files_after_one_map(tmp_path: Path) -> None:
    data = np.array([[0, 100, -1, 30], [10, 70, 0, 0]], dtype=np.int8)
    ctx = Context()
    lines: list[str] = []
    saver = MapSaver(ctx, path_prefix=tmp_path / "saved", report=lines.append)
    assert lines == ["Waiting for the map"] and not saver.done
    pub = ctx.create_node("slam").create_publisher(OccupancyGrid, "/map", LATCHED)
    ctx.spin_for(0.5)
    assert not saver.done  # nothing published yet
    grid = array_to_occupancy_grid(data, resolution=0.1, origin=(0.5, -0.5, 0.0))
    pub.publish(grid)
    ctx.spin_for(0.5)
    assert saver.done and saver.error is None and saver.finished
    image, yaml_path = tmp_path / "saved.pgm", tmp_path / "saved.yaml"
    assert saver.saved_paths == (image, yaml_path)
    assert lines == [
        "Waiting for the map",
        "Received a 4 X 2 map @ 0.100 m/pix",
        f"Writing map occupancy data to {tmp_path / 'saved'}.pgm",
        f"Writing map occupancy data to {tmp_path / 'saved'}.yaml",
        "Done",
    ]
    loaded = load_map(yaml_path).data
    assert loaded.tolist() == [[0, 100, -1, -1], [0, 100, 0, 0]]
    # the node ends itself as map_saver's process exits (status 0)
    assert saver.is_destroyed() and saver.exit_code == 0
    # later maps are ignored, as map_saver exits after the first
    mtime = image.stat().st_mtime_ns
    pub.publish(array_to_occupancy_grid(np.zeros((5, 5), np.int8), resolution=0.1))
    ctx.spin_for(0.5)
    assert image.stat().st_mtime_ns == mtime
    assert load_map(yaml_path).data.shape == (2, 4)
    ctx.shutdown()


def test_server_to_saver_is_byte_identical(
    map_file: tuple[Path, np.ndarray], tmp_path: Path
) -> None:
    path, _ = map_file
    ctx = Context()
    MapServer(ctx, yaml_path=path)
    saver = MapSaver(ctx, path_prefix=tmp_path / "copy")
    ctx.spin_for(0.1)
    assert saver.done
    assert (tmp_path / "copy.pgm").read_bytes() == (tmp_path / "office.pgm").read_bytes()
    original = (tmp_path / "office.yaml").read_text()
    assert (tmp_path / "copy.yaml").read_text() == original.replace("office.pgm", "copy.pgm")
    ctx.shutdown()


def test_map_saver_reports_write_errors(tmp_path: Path) -> None:
    ctx = Context()
    saver = MapSaver(ctx, path_prefix=tmp_path / "missing_dir" / "m", report=lambda _: None)
    ctx.create_node("slam").create_publisher(OccupancyGrid, "map", LATCHED).publish(
        array_to_occupancy_grid(np.zeros((2, 2), np.int8), resolution=0.1)
    )
    ctx.spin_for(0.1)
    assert saver.finished and not saver.done
    assert isinstance(saver.error, MapError) and "missing_dir" in str(saver.error)
    assert saver.is_destroyed() and saver.exit_code == 1
    ctx.shutdown()


def test_map_saver_thresholds_checked(tmp_path: Path) -> None:
    ctx = Context()
    with pytest.raises(MapError, match="smaller than"):
        MapSaver(ctx, path_prefix=tmp_path / "m", threshold_occupied=20, threshold_free=30)
    assert "/map_saver" not in ctx.nodes
    ctx.shutdown()


def test_map_saver_custom_topic_and_thresholds(tmp_path: Path) -> None:
    ctx = Context()
    saver = MapSaver(
        ctx,
        path_prefix=tmp_path / "m",
        map_topic="/slam_map",
        threshold_occupied=50,
        threshold_free=10,
    )
    pub = ctx.create_node("slam").create_publisher(OccupancyGrid, "/slam_map", LATCHED)
    pub.publish(array_to_occupancy_grid(np.array([[5, 20, 55]], np.int8), resolution=0.1))
    ctx.spin_for(0.1)
    assert saver.done
    assert load_map(tmp_path / "m.yaml").data.tolist() == [[0, -1, 100]]
    ctx.shutdown()
