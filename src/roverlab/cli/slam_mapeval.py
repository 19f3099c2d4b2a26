"""``roverlab slam mapeval``: score a saved map against a simulated world's ground truth."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from roverlab.geometry import SE2
from roverlab.maps import load_map
from roverlab.slam.data.errors import SlamError
from roverlab.slam.data.mapquality import (
    OccupancyMapLike,
    evaluate_map,
    ground_truth,
    write_overlay_png,
)
from roverlab.world import load_world


def mapeval(
    map_yaml: Annotated[Path, typer.Argument(help="A map_server map: NAME.yaml (+ image).")],
    world: Annotated[
        str, typer.Option("--world", "-w", help="The world the map was made in (name or file).")
    ],
    spawn: Annotated[
        tuple[float, float, float],
        typer.Option(
            "--spawn",
            help="Where the robot started (x y yaw, world frame): the map frame's pose.",
        ),
    ] = (0.0, 0.0, 0.0),
    z: Annotated[
        float, typer.Option("--z", help="Height of the scan plane above the floor (m).")
    ] = 0.15,
    search: Annotated[
        float,
        typer.Option(
            "--search", help="Alignment search around --spawn: +- this many m (and 5 deg)."
        ),
    ] = 0.3,
    png: Annotated[
        Path | None,
        typer.Option("--png", help="Also draw the aligned map over the ground truth here."),
    ] = None,
    min_accuracy: Annotated[
        float | None,
        typer.Option(
            "--min-accuracy",
            help="Exit 1 unless at least this share (0..1) of the known cells is correct "
            "and the 95th percentile of the walls' distance is within one cell.",
        ),
    ] = None,
) -> None:
    """How well a map matches the world: share of known cells right, walls' distance."""
    loaded = load_map(map_yaml)
    ox, oy, oyaw = loaded.info.origin
    if abs(oyaw) > 1e-9:
        raise SlamError(f"{map_yaml}: maps with a rotated origin (yaw {oyaw}) are not supported")
    grid = OccupancyMapLike(
        data=loaded.data, origin_xy=(float(ox), float(oy)), resolution=loaded.info.resolution
    )
    gt = ground_truth(load_world(world), resolution=grid.resolution, z_m=z)
    prior = SE2(spawn[0], spawn[1], spawn[2])
    quality = evaluate_map(grid, gt, prior=prior, search_xy_m=search,
                           search_theta_rad=math.radians(5.0))  # fmt: skip
    typer.echo(quality.summary())
    if png is not None:
        write_overlay_png(png, grid, gt, quality.alignment)
        typer.echo(f"wrote {png}", err=True)
    if min_accuracy is not None and (
        quality.accuracy < min_accuracy or quality.wall_distance_p95 > 1.0
    ):
        raise typer.Exit(1)
