"""BARN's published baseline recomputed: the real C++ move_base (navfn +
base_local_planner/TrajectoryPlannerROS with ``dwa: true``, BARN's own parameter files)
driving roverlab's simulator over ROS 1, on BARN's worlds, scored as ``roverlab nav bench
--suite barn`` scores roverlab's own move_base.

Per world: a real ``roscore`` on a free loopback port; roverlab's simulator in this
process (the BARN world, the bundled Jackal with its diff_drive_controller and laser,
spawned at BARN's start, ``/clock`` paced at ``--rate`` times real time) joined to that
master over TCPROS; Debian's ``roslaunch`` starting move_base from
``barn_ros1_move_base.launch`` (BARN's ``move_base_DWA.launch`` with its parameter files);
BARN's goal, ``(0, 10)`` ahead of the start in the odometry frame, sent by Debian's rospy
actionlib (``barn_ros1_goal.py``). Ground truth and contacts come from the simulator in
this process, and the episode's rules, score and files (``world_N.json/.csv/.png``,
``summary.json``, ``worlds.csv``) are roverlab.navbench's, so the two runs differ only in
the move_base.

    scripts/build-ros1-navigation.sh /work/rosnav_ws
    python benchmarks/barn_ros1_baseline.py --ws /work/rosnav_ws --rate 2 \\
        --worlds ../shared/data/barn/worlds --out runs/barn-ros1 --every 5
    python benchmarks/barn_ros1_baseline.py --out runs/barn-ros1 --compare runs/final2-dwa-0.5

A world whose JSON is already in ``--out`` is skipped, so a run can be resumed. With
``--compare DIR`` (a ``roverlab nav bench --suite barn`` output) nothing runs: it prints
the table of both on the worlds both have.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from roverlab.cli.common import stop_on_signals
from roverlab.core import Context
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.fileio import atomic_write_bytes
from roverlab.navbench.fixed import (
    FixedResult,
    _draw_grid,
    _in_frame,
    _odom_origin,
    episode_files,
    reference_score,
)
from roverlab.navbench.report import GoalRecord
from roverlab.navbench.suite import (
    BARN_GOAL,
    BARN_START,
    _csv,
    barn_reference,
    barn_worlds,
    summarize,
)
from roverlab.navigation.costmap.footprint import footprint_radii
from roverlab.sim.app import Simulation
from roverlab.sim.node import SpawnPose
from roverlab.world import load_world

HERE = Path(__file__).resolve().parent
LAUNCH = HERE / "barn_ros1_move_base.launch"
GOAL_SCRIPT = HERE / "barn_ros1_goal.py"
SAMPLE_S = 0.05
GOAL_TOLERANCE_M = 1.0
TIME_LIMIT_S = 100.0
START_MOVE_M = 0.1
SYSTEM_PATH = "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin"

#: ../shared/data/barn/worlds beside the repository (the project's data folder)
BARN_WORLDS = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "barn" / "worlds"


def ros_env(ws: Path) -> dict[str, str]:
    """The environment of ``ws/devel/setup.bash`` over Debian's own PATH (no venv)."""
    out = subprocess.run(
        ["bash", "-c", f"source {ws}/devel/setup.bash && env -0"],
        env={"HOME": os.environ.get("HOME", "/root"), "PATH": SYSTEM_PATH},
        capture_output=True, check=True,
    )  # fmt: skip
    return dict(item.split("=", 1) for item in out.stdout.decode().split("\0") if "=" in item)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_master(uri: str, timeout_s: float) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            xmlrpc.client.ServerProxy(uri).getPid("/barn_bench")
            return
        except OSError:
            time.sleep(0.2)
    raise RuntimeError(f"roscore at {uri} did not answer within {timeout_s:g} s")


def proc_cpu_s(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` (0 when it is gone)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def child_pid(parent: int, name: str) -> int | None:
    """The pid of ``parent``'s child whose command line contains ``name``."""
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            ppid = int((d / "stat").read_text().rsplit(")", 1)[1].split()[1])
            cmd = (d / "cmdline").read_bytes()
        except (OSError, IndexError, ValueError):
            continue
        if ppid == parent and name.encode() in cmd:
            return int(d.name)
    return None


def stop(
    proc: subprocess.Popen[Any] | None, sig: int = signal.SIGINT, wait_s: float = 10.0
) -> None:
    """Stop a process group we started: ``sig``, then SIGKILL after ``wait_s``."""
    if proc is None or proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, sig)
        proc.wait(wait_s)
    except (ProcessLookupError, subprocess.TimeoutExpired):
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(5.0)


def padded_footprint(params: Path) -> np.ndarray:
    """costmap_2d's footprint from BARN's ``costmap_common_params.yaml``, padded."""
    common = yaml.safe_load((params / "costmap_common_params.yaml").read_text())
    fp = np.asarray(common["footprint"], dtype=np.float64)
    pad = float(common.get("footprint_padding", 0.0))
    return fp + np.sign(fp) * pad


class GoalLink:
    """The rospy actionlib goal process and what it reports (read in a thread)."""

    def __init__(self, env: dict[str, str], goal: tuple[float, float, float]) -> None:
        self.proc = subprocess.Popen(
            ["/usr/bin/python3", str(GOAL_SCRIPT), *(repr(v) for v in goal)],
            env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            text=True, start_new_session=True,
        )  # fmt: skip
        self.t_sent: float | None = None
        self.state = "PENDING"
        self.text = ""
        self.recoveries: list[dict[str, Any]] = []
        self.error = ""
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            try:
                ev = json.loads(line)
            except ValueError:
                continue
            kind = ev.get("event")
            if kind == "sent":
                self.t_sent = float(ev["t"])
            elif kind == "state":
                self.state, self.text = ev["state"], ev.get("text", "")
            elif kind == "recovery":
                self.recoveries.append(ev)
            elif kind == "error":
                self.error = ev.get("text", "")

    @property
    def done(self) -> bool:
        return self.state not in ("PENDING", "ACTIVE")

    def cancel(self) -> None:
        try:
            assert self.proc.stdin is not None
            self.proc.stdin.write("cancel\n")
            self.proc.stdin.flush()
        except (OSError, ValueError):
            pass


def run_world(
    n: int, world: Path, ref: Path | None, *, params: Path, ws_env: dict[str, str],
    rate: float, seed: int, logdir: Path,
) -> tuple[FixedResult, dict[str, bytes], dict[str, Any]]:  # fmt: skip
    """One BARN episode with the real move_base; its result, files and extra fields."""
    port = free_port()
    master = f"http://127.0.0.1:{port}/"
    home = Path(tempfile.mkdtemp(prefix="barn-ros1-"))
    env = ws_env | {"ROS_MASTER_URI": master, "ROS_IP": "127.0.0.1", "ROS_HOME": str(home)}
    env.pop("ROS_HOSTNAME", None)
    core = launch = None
    link: GoalLink | None = None
    ctx: Context | None = None
    mb_log = logdir / f"world_{n}.move_base.log"
    try:
        core = subprocess.Popen(
            ["roscore", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, start_new_session=True,
        )  # fmt: skip
        wait_master(master, 30.0)
        # before any rospy node starts: rospy reads it once, at init_node
        xmlrpc.client.ServerProxy(master).setParam("/barn_bench", "/use_sim_time", True)
        ctx = Context(clock="paced", rate=rate)
        sim = Simulation(
            ctx, world=load_world(str(world)), robot="jackal", spawn=SpawnPose(*BARN_START),
            seed=seed, cameras=False,
        )  # fmt: skip
        s = sim.simulator
        ctx.add_transport(Ros1Transport(master))
        with mb_log.open("w") as fh:
            launch = subprocess.Popen(
                ["roslaunch", "--wait", str(LAUNCH), f"param_dir:={params}"],
                env=env, stdout=fh, stderr=subprocess.STDOUT, start_new_session=True,
            )  # fmt: skip
        goal = _in_frame(_odom_origin(s), BARN_GOAL)
        link = GoalLink(env, goal)
        trace: list[tuple[float, float, float, float]] = []
        contacts: list[tuple[float, float]] = []
        st: dict[str, Any] = {"t_start": None, "outcome": None, "c0": None}

        def now() -> float:
            return ctx.now().nanoseconds / 1e9

        def sample() -> None:
            t = now()
            trace.append((t, s.x, s.y, s.yaw))
            if st["outcome"] is not None or link.t_sent is None:
                return
            if st["c0"] is None:
                st["c0"] = st["contacts"] = s.contacts
            if st["t_start"] is None and math.hypot(s.x - BARN_START[0], s.y - BARN_START[1]) >= (
                START_MOVE_M
            ):
                st["t_start"] = t
            if s.contacts != st["contacts"]:
                st["contacts"] = s.contacts
                contacts.append((s.x, s.y))
                st["outcome"] = "collided"
            elif math.hypot(s.x - BARN_GOAL[0], s.y - BARN_GOAL[1]) <= GOAL_TOLERANCE_M:
                st["outcome"] = "succeeded"
            elif t - (st["t_start"] if st["t_start"] is not None else link.t_sent) >= (
                TIME_LIMIT_S
            ):
                st["outcome"] = "timeout"
            elif link.done:
                st["outcome"] = "timeout"  # given up (or "reached" short of the tolerance)

        ctx.create_node("barn_bench").create_timer(SAMPLE_S, sample)
        wall0, cpu0 = time.perf_counter(), time.process_time()
        if not ctx.wait_for(lambda: link.t_sent is not None or bool(link.error), 120.0):
            raise RuntimeError("move_base's action server did not come up in 120 sim s")
        if link.error:
            raise RuntimeError(link.error)
        mb_pid = child_pid(launch.pid, "move_base")
        mb_cpu0 = proc_cpu_s(mb_pid) if mb_pid else 0.0
        start = (s.x, s.y, s.yaw)
        ctx.wait_for(lambda: st["outcome"] is not None, TIME_LIMIT_S * 3 + 60.0)
        outcome = st["outcome"] or "timeout"
        t_end = now()
        mb_cpu = (proc_cpu_s(mb_pid) - mb_cpu0) if mb_pid else math.nan
        cpu = time.process_time() - cpu0
        wall = time.perf_counter() - wall0
        done = link.done
        mb_status, text = (link.state, link.text) if done else ("ACTIVE", "")
        if not done:
            link.cancel()
            ctx.wait_for(lambda: link.done, 3.0)
        t_sent = link.t_sent
        assert t_sent is not None
        tr = np.array([row for row in trace if row[0] >= t_sent] or [(t_sent, *start)])
        xy = tr[:, 1:3]
        driven = float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0
        end = (s.x, s.y, s.yaw)
        elapsed = t_end - (st["t_start"] if st["t_start"] is not None else t_sent)
        reference = barn_reference(ref) if ref else None
        ref_m, score = reference_score(outcome == "succeeded", elapsed, reference)
        rec = GoalRecord(
            index=0, start=start, goal=BARN_GOAL, status=mb_status, text=text,
            succeeded=outcome == "succeeded", time_s=elapsed, driven_m=driven,
            shortest_m=ref_m if ref_m is not None else math.nan, end=end,
            error_m=math.hypot(end[0] - BARN_GOAL[0], end[1] - BARN_GOAL[1]),
            yaw_error=abs(math.remainder(end[2] - BARN_GOAL[2], math.tau)),
            contacts=s.contacts - (st["c0"] or 0), contact_points=contacts,
            planner_calls=0, controller_calls=0, failures={},
            recoveries=len(link.recoveries), path=xy,
        )  # fmt: skip
        result = FixedResult(
            name=f"world_{n}", status=outcome, record=rec, time_s=elapsed, reference_m=ref_m,
            score=score, control_ms_p99=math.nan, control_wall_ms_p99=math.nan,
            planner_ms_p99=math.nan, sim_time_s=t_end, cpu_s=cpu + mb_cpu, wall_s=wall,
            trace=tr,
        )  # fmt: skip
        pts = np.vstack([np.asarray([BARN_START[:2], BARN_GOAL[:2], *(reference or [])]), xy])
        grid = _draw_grid(sim, pts, footprint_radii(padded_footprint(params))[0])
        files = episode_files(result, grid, reference)
        log_text = mb_log.read_text(errors="replace") if mb_log.is_file() else ""
        extra = {
            "move_base": "ros-planning/navigation noetic-devel (C++), over ROS 1",
            "sim_rate": rate,
            "sim_cpu_s": round(cpu, 3),
            "move_base_cpu_s": round(mb_cpu, 3) if math.isfinite(mb_cpu) else None,
            "sim_time_per_wall_s": round((t_end - t_sent) / wall, 3) if wall > 0 else None,
            "recovery_behaviors": [r.get("name") for r in link.recoveries],
            "control_loop_missed": log_text.count("Control loop missed its desired rate"),
            "map_update_missed": log_text.count("Map update loop missed its desired rate"),
        }
        return result, files, extra
    finally:
        if link is not None:
            stop(link.proc, signal.SIGTERM, 5.0)
        stop(launch)
        if ctx is not None:
            ctx.shutdown()
        stop(core)
        subprocess.run(["rm", "-rf", str(home)], check=False)


def spread(ids: list[int], every: int) -> list[int]:
    """``ids`` reordered so that any prefix is an even sample: every ``every``-th one
    first (0, every, 2 every, ...), then the next offset, and so on."""
    return [ids[i] for off in range(every) for i in range(off, len(ids), every)]


def compare(ours: Path, others: list[Path]) -> str:
    """A markdown table: real move_base (``ours``) vs roverlab's (each of ``others``, a
    ``nav bench --suite barn`` output) on the worlds all have, and the worlds where the
    real one's outcome differs from the first other's."""

    def load(d: Path) -> dict[str, dict[str, Any]]:
        out = {}
        for p in d.glob("world_*.json"):
            if p.name.count(".") == 1:
                row = json.loads(p.read_text())
                out[row["world"]] = row
        return out

    a = load(ours)
    runs = [(f"roverlab ({d.name})", load(d)) for d in others]
    common = set(a)
    for _, rows in runs:
        common &= set(rows)
    worlds = sorted(common, key=lambda w: int(w.split("_")[1]))
    lines = [
        f"Worlds: {len(worlds)}",
        "",
        "| move_base | worlds | success | collisions | timeouts | score mean | time mean |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, rows in [("real C++ move_base (ROS 1)", a), *runs]:
        sm = summarize([rows[w] for w in worlds])
        lines.append(
            f"| {label} | {sm['worlds']} | {sm['success_rate']:.1%} | "
            f"{sm['collision_rate']:.1%} | {sm['timeout_rate']:.1%} | "
            f"{sm['score_mean']:.4f} | {sm['time_mean_s']:.1f} s |"
        )
    if runs:
        b = runs[0][1]
        diff = [w for w in worlds if a[w]["status"] != b[w]["status"]]
        lines += ["", f"Outcomes differ from {runs[0][0]} in {len(diff)} worlds:"]
        for w in diff:
            lines.append(
                f"- {w}: real {a[w]['status']} ({a[w]['move_base_status']}, "
                f"{a[w]['time_s']} s, {a[w]['text'] or '-'}), roverlab {b[w]['status']} "
                f"({b[w]['move_base_status']}, {b[w]['time_s']} s)"
            )
        both = [w for w in worlds if a[w]["status"] == b[w]["status"] == "succeeded"]
        if both:
            ta = np.array([a[w]["time_s"] for w in both])
            tb = np.array([b[w]["time_s"] for w in both])
            lines.append(
                f"\nBoth succeeded in {len(both)} worlds: time real/roverlab median "
                f"{np.median(ta / tb):.2f}, real faster in {int((ta < tb - 0.5).sum())}, "
                f"within 0.5 s in {int((abs(ta - tb) <= 0.5).sum())}, "
                f"slower in {int((ta > tb + 0.5).sum())}."
            )
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ws = os.environ.get("ROS1_NAVIGATION_WS")
    ap.add_argument("--ws", type=Path, default=Path(ws) if ws else None,
                    help="catkin workspace of scripts/build-ros1-navigation.sh "
                    "(default: $ROS1_NAVIGATION_WS)")  # fmt: skip
    ap.add_argument("--worlds", type=Path, default=BARN_WORLDS)
    ap.add_argument("--params", type=Path, default=None, help="default: WORLDS/../params")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--rate", type=float, default=1.0, help="sim seconds per wall second")
    ap.add_argument("--every", type=int, default=1, help="run order: every N-th world first")
    ap.add_argument("--limit", type=int, default=None, help="at most this many worlds")
    ap.add_argument("--only", type=str, default="", help="comma-separated world numbers")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--compare", type=Path, action="append", default=None,
                    help="print the table against this nav bench output (repeatable)")  # fmt: skip
    args = ap.parse_args()
    if args.compare is not None:
        print(compare(args.out, args.compare))
        return 0
    if args.ws is None:
        print("error: give --ws WORKSPACE or set ROS1_NAVIGATION_WS", file=sys.stderr)
        return 2
    move_base = args.ws / "devel" / "lib" / "move_base" / "move_base"
    if not move_base.is_file():
        print(f"error: {move_base}: not built (scripts/build-ros1-navigation.sh {args.ws})",
              file=sys.stderr)  # fmt: skip
        return 2
    params = (args.params or args.worlds.parent / "params").resolve()
    env = ros_env(args.ws.resolve())
    worlds = {n: (w, r) for n, w, r in barn_worlds(args.worlds)}
    ids = sorted(worlds)
    if args.only:
        ids = [int(v) for v in args.only.split(",")]
    ids = spread(ids, max(1, args.every))[: args.limit]
    args.out.mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    wall0 = time.perf_counter()
    # SIGINT/SIGTERM/SIGHUP end the run after the world under way, its files and the
    # summary written and its roscore, roslaunch and move_base stopped (a second SIGINT
    # interrupts at once)
    with stop_on_signals(threading.Event()) as stopping:
        for i, n in enumerate(ids):
            if stopping.is_set():
                print(f"stopped after {len(rows)} worlds; resume with the same command")
                return 130
            run_one(i, n, ids, worlds, rows, args, params, env, wall0)
    return 0


def run_one(
    i: int, n: int, ids: list[int], worlds: dict[int, tuple[Path, Path | None]],
    rows: list[dict[str, Any]], args: argparse.Namespace, params: Path,
    env: dict[str, str], wall0: float,
) -> None:  # fmt: skip
    """Run world ``n`` unless its JSON is there, then rewrite the summary and table."""
    done = args.out / f"world_{n}.json"
    if not done.is_file():
        w, r = worlds[n]
        try:
            result, files, extra = run_world(
                n, w, r, params=params, ws_env=env, rate=args.rate, seed=args.seed,
                logdir=args.out,
            )  # fmt: skip
        except (RuntimeError, OSError) as err:
            print(f"[{i + 1}/{len(ids)}] world_{n}: error: {err}", flush=True)
            return
        row = result.to_json() | extra
        files[f"world_{n}.json"] = (json.dumps(row, indent=1) + "\n").encode()
        for fname, data in files.items():
            atomic_write_bytes(args.out / fname, data)
    row = json.loads(done.read_text())
    row["episode"] = i
    for key in ("path", "contact_points", "warnings", "start", "goal", "end"):
        row.pop(key, None)
    rows.append(row)
    print(
        f"[{i + 1}/{len(ids)}] {row['world']}: {row['status']} in {row['time_s']:.1f} s, "
        f"score {row['score'] or 0:.3f} ({row['move_base_status']}"
        f"{': ' + row['text'] if row.get('text') else ''})",
        flush=True,
    )
    planner = yaml.safe_load((params / "base_local_planner_params.yaml").read_text())
    summary = summarize(
        rows, date=datetime.now(UTC).strftime("%Y-%m-%d"),
        planner="move_base (C++, ROS 1): navfn + TrajectoryPlannerROS dwa:true",
        robot="jackal", localization="odom",
        max_speed=planner["TrajectoryPlannerROS"].get("max_vel_x"), params=str(params),
        launch=str(LAUNCH), seed=args.seed, workers=1, suite="barn", sim_rate=args.rate,
        wall_s=round(time.perf_counter() - wall0, 2),
        machine={"cpus": os.cpu_count(), "load_average": list(os.getloadavg())},
    )  # fmt: skip
    atomic_write_bytes(args.out / "summary.json", (json.dumps(summary, indent=1) + "\n").encode())
    atomic_write_bytes(args.out / "worlds.csv", _csv(rows))


if __name__ == "__main__":
    sys.exit(main())
