"""``roverlab amcl run``: amcl over a recorded log on a known map, offline."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from PIL import Image, ImageDraw

from roverlab.cli.apps import command_app
from roverlab.cli.log_input import (
    BaseFrameOption,
    FirstOption,
    LogArgument,
    LoggedOdometryOption,
    LogSource,
    OdomFrameOption,
    OdomTopicOption,
    ParamOption,
    ScanTopicOption,
    TfTopicOption,
    parse_params,
    progress,
)
from roverlab.geometry import SE2
from roverlab.localization.amcl import (
    Amcl,
    AmclError,
    AmclMapError,
    AmclParams,
    AmclRun,
    localize_log,
    map_for_amcl,
)
from roverlab.maps import OccupancyMap, load_map, occupancy_to_image
from roverlab.slam.data.trajectory import read_tum, write_tum

__all__ = ["app", "run"]

app = command_app(
    name="amcl",
    help="Localization on a known map (ROS 1 amcl), offline on recorded logs.",
    no_args_is_help=True,
)

_INITIAL_PARAMS = ("initial_pose_x", "initial_pose_y", "initial_pose_a")
_CLOUD_COLOURS = ((40, 90, 220), (20, 160, 60), (230, 140, 0), (170, 40, 200))


def _initial(text: str) -> SE2:
    parts = text.split(",")
    try:
        x, y, a = (float(v) for v in parts)
    except ValueError:
        raise AmclError(f"--initial expects X,Y,YAW (m, m, rad), got {text!r}") from None
    return SE2(x, y, a)


def start_pose(
    map_yaml: Path, initial: str | None, params: dict[str, object]
) -> tuple[SE2 | None, str]:
    """The start pose and where it comes from: ``--initial``; else ``initial_pose_*``
    parameters; else the first pose of ``trajectory.tum`` beside the map (a ``slam run``
    output); else None (amcl's default, the origin)."""
    if initial is not None:
        return _initial(initial), "--initial"
    if any(k in params for k in _INITIAL_PARAMS):
        return None, "initial_pose_* parameters"
    beside = map_yaml.parent / "trajectory.tum"
    if beside.is_file():
        traj = read_tum(beside)
        if len(traj):
            x, y, a = (float(v) for v in traj.poses[0])
            return SE2(x, y, a), f"the first pose of {beside}"
    return None, "the origin (amcl's default initial pose)"


def write_png(path: Path, occupancy: OccupancyMap, run: AmclRun) -> None:
    """The map with the trajectory (red) and the particle clouds of the run's snapshots
    (one colour each), cropped to the known cells and the trajectory plus a margin;
    written through a temporary file."""
    data = occupancy.data
    res = occupancy.info.resolution
    ox, oy, _ = occupancy.info.origin
    poses = run.trajectory.poses
    clouds = [s.particles for s in run.snapshots]
    pts = np.concatenate([poses[:, :2], *(c[:, :2] for c in clouds)]) if len(poses) else None
    rows_k, cols_k = np.nonzero(data >= 0)
    c_lo, c_hi = [cols_k.min(initial=data.shape[1])], [cols_k.max(initial=0)]
    r_lo, r_hi = [rows_k.min(initial=data.shape[0])], [rows_k.max(initial=0)]
    if pts is not None and len(pts):
        c_lo.append(int(np.floor((pts[:, 0].min() - ox) / res)))
        c_hi.append(int(np.ceil((pts[:, 0].max() - ox) / res)))
        r_lo.append(int(np.floor((pts[:, 1].min() - oy) / res)))
        r_hi.append(int(np.ceil((pts[:, 1].max() - oy) / res)))
    pad = 20
    c0, c1 = max(0, min(c_lo) - pad), min(data.shape[1], max(c_hi) + pad + 1)
    r0, r1 = max(0, min(r_lo) - pad), min(data.shape[0], max(r_hi) + pad + 1)
    if c1 <= c0 or r1 <= r0:
        c0, c1, r0, r1 = 0, data.shape[1], 0, data.shape[0]
    img = Image.fromarray(occupancy_to_image(data[r0:r1, c0:c1])).convert("RGB")
    draw = ImageDraw.Draw(img)
    h = r1 - r0
    x0, y0 = ox + c0 * res, oy + r0 * res

    def pixels(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (xy[:, 0] - x0) / res, h - 1 - (xy[:, 1] - y0) / res

    for k, cloud in enumerate(clouds):
        colour = _CLOUD_COLOURS[k % len(_CLOUD_COLOURS)]
        u, v = pixels(cloud)
        du, dv = 3.0 * np.cos(cloud[:, 2]), -3.0 * np.sin(cloud[:, 2])
        for a, b, c, d in zip(u.tolist(), v.tolist(), du.tolist(), dv.tolist(), strict=True):
            draw.line([(a, b), (a + c, b + d)], fill=colour, width=1)
    if len(poses) > 1:
        u, v = pixels(poses)
        draw.line(list(zip(u.tolist(), v.tolist(), strict=True)), fill=(220, 30, 30), width=2)
    for k, snap in enumerate(run.snapshots):
        label = "start" if snap.scan < 0 else f"scan {snap.scan}"
        draw.text((4, 4 + 12 * k), label, fill=_CLOUD_COLOURS[k % len(_CLOUD_COLOURS)])
    tmp = path.with_name(path.name + ".part")
    img.save(tmp, format="PNG")
    tmp.replace(path)


@app.command("run")
def run(
    log: LogArgument,
    map_yaml: Annotated[
        Path, typer.Option("--map", "-m", help="The map (map_server YAML), e.g. DIR/map.yaml.")
    ],
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("amcl_out"),
    initial: Annotated[
        str | None,
        typer.Option(
            "--initial",
            help="Start pose X,Y,YAW in the map (m, m, rad); default: the first pose of "
            "trajectory.tum beside the map (a `slam run` output), else the origin.",
        ),
    ] = None,
    global_start: Annotated[
        bool, typer.Option("--global", help="Start from particles spread over the free cells.")
    ] = False,
    param: ParamOption = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the filter's random draws.")] = 0,
    scan_topic: ScanTopicOption = "/scan",
    odom_topic: OdomTopicOption = "/odom",
    tf_topic: TfTopicOption = "/tf",
    odom_frame: OdomFrameOption = "odom",
    base_frame: BaseFrameOption = None,
    first: FirstOption = None,
    logged_odometry: LoggedOdometryOption = False,
) -> None:
    """Localise a recorded log on MAP: DIR/trajectory.tum (robot pose in the map at every
    scan) and DIR/amcl.png (map, trajectory, particle clouds)."""
    if initial is not None and global_start:
        raise AmclError("--initial and --global exclude each other")
    raw = parse_params(param, AmclError)
    warnings: list[str] = []
    params = AmclParams.from_ros(raw, warnings=warnings)
    for w in warnings:
        typer.echo(f"warning: {w}", err=True)
    occupancy = load_map(map_yaml)
    try:
        amcl_map = map_for_amcl(occupancy, params)
    except AmclMapError as err:
        raise AmclMapError(f"{map_yaml}: {err}") from err
    if global_start:
        pose, source = None, "--global"
    else:
        pose, source = start_pose(map_yaml, initial, raw)
    amcl = Amcl(params, amcl_map, rng=np.random.default_rng(seed), initial_pose=pose,
                global_start=global_start)  # fmt: skip
    started = time.monotonic()
    records, note = LogSource(
        log, scan_topic, odom_topic, tf_topic, odom_frame, base_frame, first, logged_odometry
    ).read(AmclError)
    read_s = time.monotonic() - started
    n = len(records)
    typer.echo(f"{n} scans from {log}; start: {source}", err=True)
    if note is not None:
        typer.echo(note, err=True)
    snaps = sorted({-1, n // 3, (2 * n) // 3, n - 1})
    result = localize_log(progress(records, "amcl"), amcl, snapshot_at=snaps)
    wall = time.monotonic() - started
    for note, count in result.notes.items():
        typer.echo(f"warning: {note} ({count} scans)", err=True)
    out.mkdir(parents=True, exist_ok=True)
    write_tum(out / "trajectory.tum", result.trajectory)
    write_png(out / "amcl.png", occupancy, result)
    duration = records.duration_s
    factor = duration / wall if wall > 0 else math.inf
    typer.echo(
        f"amcl: {n} scans, {result.updates} filter updates, {result.resamples} resamplings, "
        f"{amcl.pf.count} particles at the end; {duration:.0f} s of data in {wall:.1f} s "
        f"({factor:.0f}x real time, log reading {read_s:.1f} s); wrote {out}/trajectory.tum, "
        "amcl.png",
        err=True,
    )
