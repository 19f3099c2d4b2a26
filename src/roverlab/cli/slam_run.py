"""``roverlab slam run``: a SLAM method over a recorded log, offline."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Annotated, NamedTuple

import numpy as np
import typer

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
from roverlab.maps import save_map
from roverlab.maps.plot import write_map_png
from roverlab.slam.data.errors import SlamError
from roverlab.slam.data.logs import LaserLog
from roverlab.slam.data.trajectory import Trajectory, write_tum
from roverlab.slam.gmapping import GMapping, GMappingParams
from roverlab.slam.graph import GraphParams, GraphSLAM
from roverlab.slam.graph.params import NODE_PARAMETERS
from roverlab.slam.hector import HectorParams, HectorSLAM

METHODS = ("hector", "gmapping", "graph")
# map edge beyond the odometry's bounding box when hector's map is sized from the log: this
# much (m) plus a share of the box (odometry drifts, so the true path is not inside it)
_HECTOR_MARGIN_M = 5.0
_HECTOR_MARGIN_SHARE = 0.15
_HECTOR_GROW_MAX = 8192  # cells per side: 1 GB for three levels
_PLAUSIBLE_MARGIN_M = 50.0  # a building is at most twice the odometry's box + this
_PLAUSIBLE_MAX_M = 400.0  # and no building is larger (hector's largest map: 8192 * 5 cm)


def plausible_extent_m(records: LaserLog) -> float:
    """How far (m) from its start an estimate can be before it has run away: twice the
    odometry's extent plus 50 m (no drift makes a building bigger than that), at most
    :data:`_PLAUSIBLE_MAX_M` (odometry that jumps must not make a building of any size);
    that for a log without odometry."""
    if not _has_odometry(records):
        return _PLAUSIBLE_MAX_M
    extent = float(np.ptp(records.odom_poses[:, :2], axis=0).max())
    return min(2.0 * extent + _PLAUSIBLE_MARGIN_M, _PLAUSIBLE_MAX_M)


def run_graph(records: LaserLog, params: dict[str, object]) -> MethodResult:
    slam = GraphSLAM(GraphParams.from_ros(params))
    result = slam.run_log(progress(records, "graph"), max_extent_m=plausible_extent_m(records))
    m = result.map
    g = slam.graph()
    notes = [f"graph: {g.num_vertices} keyframes, {g.num_edges} constraints"]
    if slam.rim_searches:
        notes[0] += f", {slam.rim_searches} matches searched again beyond the angular window"
    if slam.degenerate_scans:
        notes[0] += (
            f", {slam.degenerate_scans} scans degenerate along a corridor kept the odometry "
            "along it"
        )
    if slam.runaway is not None:
        notes.append(slam.runaway.warning())
    dropped = sorted(k for k in params if k in NODE_PARAMETERS)
    if dropped:  # GraphParams.from_ros accepts slam_toolbox's node settings and drops them
        notes.append(
            "warning: slam_toolbox node parameters have no effect on an offline run "
            f"(ignored): {', '.join(dropped)}"
        )
    return MethodResult(m.data, m.resolution, m.origin, result.poses, result.trajectory, notes)


class MethodResult(NamedTuple):
    """What every method gives back: the map, one pose per scan, the trajectory."""

    data: np.ndarray  # (H, W) int8 -1/0/100, row 0 at the lowest y
    resolution: float
    origin: tuple[float, float]
    poses: np.ndarray  # (N, 3)
    trajectory: Trajectory
    notes: list[str]


def hector_auto_size(records: LaserLog, params: dict[str, object]) -> dict[str, object]:
    """hector's map is fixed in size (ROS default 1024 cells of 2.5 cm = 25.6 m, smaller than
    most buildings). Offline the whole odometry is known, so unless the user set
    ``map_size`` / ``map_start_x`` / ``map_start_y``, size the map to the odometry's
    bounding box (in the frame of the first pose) plus a margin."""
    if any(k in params for k in ("map_size", "map_start_x", "map_start_y")) or len(records) < 2:
        return params
    base = HectorParams.from_ros(params)  # the user's resolution and levels, else hector's
    res, levels = base.map_resolution, base.map_multi_res_levels
    odo = records.odom_poses
    c, s = math.cos(odo[0, 2]), math.sin(odo[0, 2])
    d = odo[:, :2] - odo[0, :2]
    x = c * d[:, 0] + s * d[:, 1]
    y = -s * d[:, 0] + c * d[:, 1]
    lo_x, hi_x = min(float(x.min()), 0.0), max(float(x.max()), 0.0)
    lo_y, hi_y = min(float(y.min()), 0.0), max(float(y.max()), 0.0)
    box = max(hi_x - lo_x, hi_y - lo_y)
    margin = _HECTOR_MARGIN_M + _HECTOR_MARGIN_SHARE * box
    span = box + 2 * margin
    step = 2 ** max(levels - 1, 0) * 64
    cells = max(base.map_size, int(math.ceil(span / res / step)) * step)
    # odometry that jumps (a log glitch) must not size a map past any building
    cells = max(base.map_size, min(cells, _HECTOR_GROW_MAX))
    size_m = cells * res
    out = dict(params)
    out["map_size"] = cells
    # centre the box in the map
    # (a map capped below the box keeps the start inside it)
    out["map_start_x"] = min(max(0.5 - 0.5 * (lo_x + hi_x) / size_m, 0.05), 0.95)
    out["map_start_y"] = min(max(0.5 - 0.5 * (lo_y + hi_y) / size_m, 0.05), 0.95)
    return out


def _has_odometry(records: LaserLog) -> bool:
    """Whether the log's odometry moves at all (a log read without odometry has the
    identity at every scan)."""
    odo = records.odom_poses
    return len(records) > 1 and bool(np.ptp(odo, axis=0).max() > 1e-9)


def hector_odometry(records: LaserLog, params: dict[str, object]) -> tuple[dict[str, object], str]:
    """hector's start estimate offline: ROS's ``use_tf_pose_start_estimate`` (odometry from
    TF as the start of each match) is roverlab's ``use_odometry``. Unless the user set
    either, a log with odometry uses it; the note says which."""
    out = dict(params)
    tf_start = out.pop("use_tf_pose_start_estimate", None)
    if "use_odometry" in out:
        chosen = bool(out["use_odometry"])
        why = "(use_odometry)"
    elif tf_start is not None:
        chosen = bool(tf_start)
        why = "(use_tf_pose_start_estimate)"
        if not chosen:
            why += ": pure scan matching, as ROS's hector"
    else:
        chosen = _has_odometry(records)
        why = (
            "(the log has odometry; use_odometry:=false for pure scan matching)"
            if chosen
            else "(the log has none): pure scan matching, as ROS's hector"
        )
    out["use_odometry"] = chosen
    if chosen:
        return out, (
            f"hector: odometry is the start estimate of each match {why}; along directions "
            "a scan cannot fix (corridors) the odometry increment is kept"
        )
    return out, f"hector: no odometry {why}"


def hector_plausible_cells(records: LaserLog, hp: HectorParams) -> int:
    """The largest map (cells per side) a run may grow to: the map doubled until it spans
    twice the odometry's extent plus 50 m (no drift makes a building bigger than that), at
    most :data:`_HECTOR_GROW_MAX` (a log without odometry: that). Beyond it the estimate
    has run away."""
    if not _has_odometry(records):
        return max(hp.map_size, _HECTOR_GROW_MAX)
    extent = float(np.ptp(records.odom_poses[:, :2], axis=0).max())
    need = (2.0 * extent + _PLAUSIBLE_MARGIN_M) / hp.map_resolution
    cells = hp.map_size
    while cells < need and 2 * cells <= _HECTOR_GROW_MAX:
        cells *= 2
    return cells


def run_hector(records: LaserLog, params: dict[str, object]) -> MethodResult:
    params, odo_note = hector_odometry(records, params)
    use_offset = bool(params.pop("use_tf_scan_transformation", True))
    sized = hector_auto_size(records, params)
    hp = HectorParams.from_ros(sized)
    notes = [odo_note]
    if sized is not params:
        notes.append(
            f"hector map sized to the log: map_size {hp.map_size} "
            f"({hp.map_size * hp.map_resolution:.1f} m), map_start_x {hp.map_start_x:.3f}, "
            f"map_start_y {hp.map_start_y:.3f}"
        )
    if not use_offset:
        notes.append("hector: use_tf_scan_transformation false: scans taken in the base frame")
    # the odometry's box can be wrong (drift, a log without odometry): grow rather than
    # fail, up to a building's plausible size; beyond it the estimate ran away
    slam = HectorSLAM(hp, grow_max_size=hector_plausible_cells(records, hp))
    result = slam.run_log(
        progress(records, "hector"), use_laser_offset=use_offset, stop_on_runaway=True
    )
    if int(slam.grid.sizes[0]) != hp.map_size:
        notes.append(f"hector map grown to {int(slam.grid.sizes[0])} cells per side")
    g = slam.guard_counts
    if hp.use_odometry and (g.degenerate or g.jumps or g.collapsed or g.rival or g.revisits):
        notes.append(
            f"hector: {g.degenerate} degenerate matches kept the odometry along the weak "
            f"direction, {g.jumps} matches jumping faster than the robot can move and "
            f"{g.collapsed} collapsed matches were replaced by the odometry, "
            f"{g.rival} matches from the scan-only prediction fitted better than the "
            f"odometry's, {g.revisits} corrections found on a revisit were taken "
            f"({g.unmapped} scans left unmapped while they were confirmed)"
        )
    if slam.runaway is not None:
        notes.append(slam.runaway.warning())
    m = result.map
    return MethodResult(m.data, m.resolution, m.origin, result.poses, result.trajectory, notes)


def run_gmapping(
    records: LaserLog, params: dict[str, object], *, seed: int, smooth: bool
) -> MethodResult:
    slam = GMapping(GMappingParams.from_ros(params), rng=np.random.default_rng(seed))
    result = slam.run_log(
        progress(records, "gmapping"),
        interpolate=smooth,
        max_extent_m=plausible_extent_m(records),
    )
    m = result.map
    stamps = list(records.timestamp_texts)[: len(result.poses)]
    traj = Trajectory.from_poses(stamps, result.poses)
    notes = [
        f"gmapping: {slam.updates} filter updates, {slam.resamples} resamplings, "
        f"{slam.recoveries} odometry-failure recoveries"
    ]
    if slam.runaway is not None:
        notes.append(slam.runaway.warning())
    return MethodResult(m.data, m.resolution, m.origin_xy, result.poses, traj, notes)


def run(
    log: LogArgument,
    method: Annotated[
        str, typer.Option("--method", "-m", help="hector, gmapping or graph.")
    ] = "hector",
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("slam_out"),
    param: ParamOption = None,
    scan_topic: ScanTopicOption = "/scan",
    odom_topic: OdomTopicOption = "/odom",
    tf_topic: TfTopicOption = "/tf",
    odom_frame: OdomFrameOption = "odom",
    base_frame: BaseFrameOption = None,
    first: FirstOption = None,
    seed: Annotated[
        int, typer.Option("--seed", help="Seed of the random draws (gmapping's particles).")
    ] = 0,
    smooth: Annotated[
        bool,
        typer.Option(
            "--smooth/--no-smooth",
            help="gmapping: scans between two filter updates get a pose blended from both "
            "updates (offline smoothing), instead of the last update moved by odometry "
            "(what a live slam_gmapping reports).",
        ),
    ] = True,
    logged_odometry: LoggedOdometryOption = False,
) -> None:
    """Map a recorded log: DIR/map.yaml + map.pgm, DIR/map.png, DIR/trajectory.tum."""
    if method not in METHODS:
        raise SlamError(f"unknown method {method!r} (hector, gmapping or graph)")
    params = parse_params(param, SlamError)
    # parameter errors before the (long) log reading
    if method == "hector":
        HectorParams.from_ros(params)
    elif method == "gmapping":
        GMappingParams.from_ros(params)
    else:
        GraphParams.from_ros(params)
    started = time.monotonic()
    records, note = LogSource(
        log, scan_topic, odom_topic, tf_topic, odom_frame, base_frame, first, logged_odometry
    ).read(SlamError)
    typer.echo(f"{len(records)} scans from {log}", err=True)
    if note is not None:
        typer.echo(note, err=True)
    if method == "hector":
        res = run_hector(records, params)
    elif method == "gmapping":
        res = run_gmapping(records, params, seed=seed, smooth=smooth)
    else:
        res = run_graph(records, params)
    wall = time.monotonic() - started
    for note in res.notes:
        typer.echo(note, err=True)
    out.mkdir(parents=True, exist_ok=True)
    save_map(out / "map", res.data, resolution=res.resolution,
             origin=(res.origin[0], res.origin[1], 0.0))  # fmt: skip
    write_map_png(out / "map.png", res.data, res.resolution, res.origin, np.asarray(res.poses))
    write_tum(out / "trajectory.tum", res.trajectory)
    duration = float(records.timestamps[-1] - records.timestamps[0]) if len(records) > 1 else 0.0
    factor = duration / wall if wall > 0 else math.inf
    typer.echo(
        f"{method}: {len(records)} scans, {duration:.0f} s of data in {wall:.1f} s "
        f"({factor:.0f}x real time); wrote {out}/map.yaml, map.pgm, map.png, trajectory.tum",
        err=True,
    )
