"""``bag play --clock`` feeds slam_gmapping a recorded run: its map matches the live one."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from roverlab.bag import BagRecorder
from roverlab.core import Context, QoSProfile
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport
from roverlab.msgs import classes as mc
from roverlab.msgs.factory import Twist
from roverlab.sim.app import Simulation
from roverlab.sim.node import SpawnPose
from roverlab.slam.gmapping.node import SlamGMapping
from roverlab.world.yaml_world import world_from_dict
from tests.helpers.procs import Proc

ROOM = {
    "name": "room",
    "walls": [{"points": [[-3, -2], [3, -2], [3, 2], [-3, 2]], "closed": True}],
    "boxes": [{"center": [1.2, 0.8], "size": [0.5, 0.5, 1.0]}],
}
GMAPPING = {
    "particles": 8,
    "map_update_interval": 1.0,
    "base_frame": "base_footprint",
    "seed": 3,
    "transform_publish_period": 0.0,  # no map -> odom in the bag: the replay makes its own
}


def _live_run(bag: Path) -> Any:
    ctx = Context()
    Simulation(
        context=ctx,
        world=world_from_dict(ROOM, source=Path("room.yaml")),
        robot="mybot",
        cameras=False,
        spawn=SpawnPose(-1.0, 0.0, 0.0),
        seed=1,
    )
    ctx.add_transport(BagRecorder(bag))
    node = SlamGMapping(ctx, parameter_overrides=GMAPPING)
    cmd = ctx.create_node("driver").create_publisher(Twist, "/cmd_vel", 1)
    for v, w, secs in [(0.0, 0.6, 4.0), (0.25, 0.0, 3.0), (0.0, -0.6, 3.0)]:
        cmd.publish(Twist(linear_x=v, angular_z=w))
        ctx.spin_for(secs)
    ctx.shutdown()
    assert node.map_msg is not None and node.scans_processed >= 6
    return node.map_msg


def _t(grid: Any) -> float:
    return float(grid.header.stamp.sec + grid.header.stamp.nanosec * 1e-9)


def test_play_clock_feeds_gmapping_and_the_map_matches(tmp_path: Path, daemon: str) -> None:
    bag = tmp_path / "live.mcap"
    live = _live_run(bag)
    args = [f"_{k}:={v}" for k, v in GMAPPING.items()]
    rl = [sys.executable, "-m", "roverlab.cli"]
    slam = Proc([*rl, "run", "--clock", "external", "gmapping", "slam_gmapping", *args])
    ctx = Context(clock="wall", publish_clock=False)
    ctx.add_transport(ZenohTransport(ZenohOptions(connect=(daemon,))))
    maps: list[Any] = []
    ctx.create_node("map_listener").create_subscription(
        mc.OccupancyGrid, "/map", maps.append, QoSProfile(depth=10)
    )
    ctx.spin_in_thread()
    try:
        time.sleep(3.0)  # the node is up and listening
        play = Proc([*rl, "bag", "play", str(bag), "--clock", "--topics", "/scan", "/tf",
                     "/tf_static"])  # fmt: skip
        assert play.popen.wait(timeout=150) == 0, play.stderr()
        assert "published" in play.stderr()
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and (not maps or _t(maps[-1]) < _t(live) - 0.5):
            time.sleep(0.2)
    finally:
        ctx.shutdown()
        err = slam.stop()
    assert maps, err
    got = maps[-1]
    # the same last map update, in bag time (stamped with the /clock of the moment)
    assert abs(_t(got) - _t(live)) < 0.5
    assert (got.info.width, got.info.height) == (live.info.width, live.info.height)
    a, b = np.asarray(got.data), np.asarray(live.data)
    known = (a != -1) | (b != -1)
    agree = float((a[known] == b[known]).mean())
    print(f"replayed map: {agree:.2%} of {known.sum()} known cells agree with the live one")
    assert known.sum() > 2000 and agree > 0.95, agree
