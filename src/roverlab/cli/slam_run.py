"""``roverlab slam run``: a SLAM method over a recorded log, offline."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
import yaml
from PIL import Image, ImageDraw

from roverlab.mapping.hector import HectorParams, HectorSLAM
from roverlab.maps import save_map
from roverlab.slam.errors import SlamError
from roverlab.slam.logs import load_log
from roverlab.slam.trajectory import write_tum

METHODS = ("hector", "gmapping", "graph")


def _params(items: list[str] | None) -> dict[str, object]:
    out: dict[str, object] = {}
    for item in items or []:
        name, sep, value = item.partition(":=")
        if not sep or not name:
            raise SlamError(f"--param expects name:=value, got {item!r}")
        out[name] = yaml.safe_load(value)
    return out


def _png(path: Path, data: np.ndarray, resolution: float, origin: tuple[float, float],
         poses: np.ndarray) -> None:  # fmt: skip
    """The map (map_saver's grey levels, top row = max y) with the trajectory in red."""
    img = np.full(data.shape, 205, dtype=np.uint8)
    img[data == 0] = 254
    img[data == 100] = 0
    rgb = Image.fromarray(np.flipud(img)).convert("RGB")
    draw = ImageDraw.Draw(rgb)
    h = data.shape[0]
    cols = (poses[:, 0] - origin[0]) / resolution
    rows = h - 1 - (poses[:, 1] - origin[1]) / resolution
    draw.line(list(zip(cols.tolist(), rows.tolist(), strict=True)), fill=(220, 30, 30), width=2)
    tmp = path.with_name(path.name + ".part")
    rgb.save(tmp, format="PNG")
    tmp.replace(path)


def run(
    log: Annotated[
        Path, typer.Argument(help="CARMEN .clf(.gz/.bz2), ROS 1 .bag, ROS 2 bag or .mcap.")
    ],
    method: Annotated[
        str, typer.Option("--method", "-m", help="hector, gmapping or graph.")
    ] = "hector",
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("slam_out"),
    param: Annotated[
        list[str] | None,
        typer.Option("--param", "-p", help="A method parameter, ROS name:=value (repeatable)."),
    ] = None,
    scan_topic: Annotated[
        str, typer.Option("--scan-topic", help="Bags: the LaserScan topic.")
    ] = "/scan",
    odom_topic: Annotated[
        str, typer.Option("--odom-topic", help="Bags: the Odometry topic.")
    ] = "/odom",
    first: Annotated[
        int | None, typer.Option("--first", help="Use only the first N scans of the log.")
    ] = None,
) -> None:
    """Map a recorded log: DIR/map.yaml + map.pgm, DIR/map.png, DIR/trajectory.tum."""
    if method not in METHODS:
        raise SlamError(f"unknown method {method!r} (hector, gmapping or graph)")
    if method != "hector":
        raise SlamError(f"method {method!r} is not available yet (hector is)")
    params = HectorParams.from_ros(_params(param))
    started = time.monotonic()
    if log.suffix in (".clf", ".gz", ".bz2"):
        records = load_log(log)
    else:
        records = load_log(log, scan_topic=scan_topic, odom_topic=odom_topic)
    if first is not None:
        if first < 2:
            raise SlamError(f"--first must be at least 2, got {first}")
        records = records[:first]
    typer.echo(f"{len(records)} scans from {log}", err=True)
    slam = HectorSLAM(params)
    result = slam.run_log(records)
    wall = time.monotonic() - started
    out.mkdir(parents=True, exist_ok=True)
    m = result.map
    save_map(out / "map", m.data, resolution=m.resolution, origin=(m.origin[0], m.origin[1], 0.0))
    _png(out / "map.png", m.data, m.resolution, m.origin, np.asarray(result.poses))
    write_tum(out / "trajectory.tum", result.trajectory)
    duration = float(records.timestamps[-1] - records.timestamps[0]) if len(records) > 1 else 0.0
    factor = duration / wall if wall > 0 else math.inf
    typer.echo(
        f"{method}: {len(records)} scans, {duration:.0f} s of data in {wall:.1f} s "
        f"({factor:.0f}x real time); wrote {out}/map.yaml, map.pgm, map.png, trajectory.tum",
        err=True,
    )
