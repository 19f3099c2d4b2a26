"""Fixed start -> goal episodes and BARN's suite (``roverlab nav bench --suite barn``,
``--start/--goal``): BARN's reference path and score, the world listing, the summary, the
picture with a goal off the map, bad options, and one live episode on odometry alone
(the Jackal-sized robot through its diff_drive_controller, costmaps from the laser)."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.description import find_package
from roverlab.navbench import BenchGrid, GoalRecord
from roverlab.navbench.fixed import FixedConfig, barn_score, run_fixed
from roverlab.navbench.report import draw
from roverlab.navbench.suite import (
    BARN_GOAL,
    BARN_START,
    barn_configs,
    barn_reference,
    barn_worlds,
    run_suite,
    summarize,
)
from tests.helpers.barn_layout import write_barn_layout
from tests.helpers.nodes import run_main


def test_barn_score_and_reference(tmp_path: Path) -> None:
    assert barn_score(True, 10.0, 6.0) == pytest.approx(6.0 / 12.0)  # clipped to 2 x optimal
    assert barn_score(True, 30.0, 6.0) == pytest.approx(6.0 / 30.0)
    assert barn_score(True, 100.0, 6.0) == pytest.approx(6.0 / 48.0)  # at most 8 x optimal
    assert barn_score(False, 20.0, 6.0) == 0.0
    np.save(tmp_path / "path_7.npy", np.array([[15, 0], [15, 29]]))
    ref = barn_reference(tmp_path / "path_7.npy")
    # run.py: x = col * 0.15 - 0.075 - 4.5, y = row * 0.15 + 0.075 + 5, start and goal added
    assert ref[0] == BARN_START[:2] and ref[-1] == BARN_GOAL[:2]
    assert ref[1] == pytest.approx((-2.325, 5.075)) and ref[2] == pytest.approx((-2.325, 9.425))
    np.save(tmp_path / "bad.npy", np.zeros(3))
    with pytest.raises(Exception, match=r"bad\.npy: expected \(K, 2\) cells"):
        barn_reference(tmp_path / "bad.npy")


def test_barn_worlds_pair_paths_and_sort_by_number(tmp_path: Path) -> None:
    worlds = tmp_path / "worlds"
    worlds.mkdir()
    (tmp_path / "path_files").mkdir()
    for n in (10, 2, 1):
        (worlds / f"world_{n}.world").write_text("<sdf/>")
    (worlds / "notes.txt").write_text("")
    np.save(tmp_path / "path_files" / "path_2.npy", np.array([[15, 0]]))
    found = barn_worlds(worlds)
    assert [n for n, _, _ in found] == [1, 2, 10]
    assert found[1][2] == tmp_path / "path_files" / "path_2.npy" and found[0][2] is None
    (tmp_path / "params").mkdir()
    base = FixedConfig(world="", out=tmp_path, start=(0, 0, 0), goal=(0, 0, 0), robot="x")
    cfgs = barn_configs(worlds, base, only=2)
    assert [c.name for c in cfgs] == ["world_1", "world_2"]
    assert cfgs[0].params_dir == tmp_path / "params" and cfgs[0].localization == "odom"
    assert (cfgs[1].start, cfgs[1].goal, cfgs[1].goal_tolerance_m) == (BARN_START, BARN_GOAL, 1.0)
    assert cfgs[1].reference is not None and cfgs[0].reference is None
    with pytest.raises(Exception, match=r"no world_N\.world files"):
        barn_worlds(tmp_path / "params")


def test_summary_rates_score_and_worst_control_cycle() -> None:
    rows = [
        {"world": "a", "status": "succeeded", "time_s": 20.0, "score": 0.3,
         "control_ms_p99": 12.0, "sim_time_s": 21.0, "cpu_s": 1.0},
        {"world": "b", "status": "collided", "time_s": 5.0, "score": 0.0,
         "control_ms_p99": 40.0, "sim_time_s": 6.0, "cpu_s": 0.5},
        {"world": "c", "status": "timeout", "time_s": 100.0, "score": 0.0,
         "control_ms_p99": 8.0, "sim_time_s": 101.0, "cpu_s": 2.5},
        {"world": "d", "error": "LaunchError: x"},
    ]  # fmt: skip
    s = summarize(rows, planner="dwa")
    assert (s["worlds"], s["errors"], s["planner"]) == (3, 1, "dwa")
    assert (
        s["success_rate"]
        == s["collision_rate"]
        == s["timeout_rate"]
        == pytest.approx(1 / 3, abs=1e-4)
    )
    assert s["score_mean"] == pytest.approx(0.1) and s["time_mean_s"] == 20.0
    assert s["control_ms_p99_max"] == 40.0 and s["control_ms_p99_worst_world"] == "b"
    assert s["rtf_per_cpu_s"] == pytest.approx(128.0 / 4.0)


def test_the_summary_line_never_rounds_a_failure_away() -> None:
    from roverlab.cli.nav import percent

    assert percent(249 / 250) == "99.6 %" and percent(1 / 250) == "0.4 %"
    assert percent(1.0) == "100.0 %" and percent(0.0) == "0.0 %" and percent(None) == "-"
    assert percent(9999 / 10000) == ">99.9 %" and percent(1 / 10000) == "<0.1 %"


def test_picture_grows_to_show_a_goal_off_the_map(tmp_path: Path) -> None:
    costs = np.zeros((20, 20), dtype=np.uint8)
    costs[0, :] = 254
    grid = BenchGrid(costs, 0.05, (0.0, 0.0))  # a 1 x 1 m map
    rec = GoalRecord(
        index=0, start=(0.5, 0.5, 0.0), goal=(0.5, 4.0, 0.0), status="ABORTED", text="",
        succeeded=False, time_s=1.0, driven_m=0.0, shortest_m=math.nan, end=(0.5, 0.5, 0.0),
        error_m=3.5, yaw_error=0.0, contacts=0, contact_points=[], planner_calls=0,
        controller_calls=0, failures={}, recoveries=0, path=np.array([[0.5, 0.5]]),
    )  # fmt: skip
    img = draw(grid, [rec], reference=((0.5, 0.5), (0.5, 4.0)))
    arr = np.asarray(img.convert("RGB"))
    assert arr.shape[0] > 3 * arr.shape[1]  # 4.5 m tall, 1 m wide
    red = np.argwhere((arr == (214, 39, 40)).all(axis=2))
    assert len(red) and red[:, 0].min() < arr.shape[0] * 0.2  # the goal's cross, near the top
    assert (arr == (230, 120, 200)).all(axis=2).any()  # the reference path


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--suite", "mars", "--worlds", "."], "error: unknown suite 'mars': use barn"),
        (["--start", "1,2", "--goal", "3,4"],
         "error: --start must be X,Y,YAW (numbers), got '1,2'"),
        (["--start", "0,0,0", "--goal", "a,b"], "error: --goal must be X,Y[,YAW] (numbers)"),
        (["--start", "0,0,0", "--goal", "1,0", "--on-collision", "bounce"],
         "error: --on-collision must be end or continue, got 'bounce'"),
        (["--start", "0,0,0", "--goal", "1,0", "--localization", "gps"],
         "error: unknown localization 'gps': use odom, amcl, ground_truth"),
        (["--suite", "barn", "--worlds", "nowhere"], "error: nowhere: worlds folder not found"),
        (["--start", "0,0,0", "--goal", "1,0", "--time-limit", "0"],
         "error: --time-limit must be > 0, got 0"),
    ],
)  # fmt: skip
def test_bad_fixed_goal_options_are_one_line_exit_2(
    tmp_path: Path, args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert run_main(["nav", "bench", "--out", str(tmp_path / "out"), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(message) and "\n" not in err, err


# move_base files in BARN's layout, written for this test (odometry frame, laser costmaps)
_PLANNER = """\
TrajectoryPlannerROS: {max_vel_x: 0.5, min_vel_x: 0.1, acc_lim_x: 10.0, acc_lim_theta: 20.0,
  max_vel_theta: 1.57, min_in_place_vel_theta: 0.314, xy_goal_tolerance: 0.25,
  yaw_goal_tolerance: 0.157, sim_time: 2.0, vx_samples: 6, vtheta_samples: 20, dwa: true,
  controller_frequency: 10.0, occdist_scale: 0.1, pdist_scale: 0.75, gdist_scale: 1.0}
"""


def _room(tmp_path: Path) -> FixedConfig:
    params = tmp_path / "params"
    write_barn_layout(params, _PLANNER, padding=0.05, global_hz=5, global_size_m=12.0, local_hz=10)
    world = tmp_path / "room.yaml"
    world.write_text(
        "name: room\nwalls:\n- points: [[-1, -2], [5, -2], [5, 2], [-1, 2]]\n  closed: true\n"
        "cylinders:\n- {center: [1.8, 1.1], radius: 0.2, height: 0.5}\n"
    )
    return FixedConfig(
        world=str(world), out=tmp_path / "out", start=(0.0, 0.0, 0.0), goal=(3.5, 0.0, 0.0),
        robot="jackal", params_dir=params, time_limit_s=40.0,
        reference=((0.0, 0.0), (3.5, 0.0)),
    )  # fmt: skip


def test_live_episode_on_odometry_alone(tmp_path: Path) -> None:
    cfg = _room(tmp_path)
    summary = run_suite([cfg], tmp_path / "out")
    assert summary["worlds"] == 1 and summary["success_rate"] == 1.0, summary
    assert summary["collision_rate"] == 0.0 and summary["rtf_per_cpu_s"] > 0
    assert 0 < summary["control_ms_p99_max"] < 200
    rec = json.loads((tmp_path / "out" / "room.json").read_text())
    # the clock starts at the first 0.1 m; success 1 m short of the goal
    assert rec["status"] == "succeeded" and rec["error_m"] <= 1.0 and rec["contacts"] == 0
    assert 2.4 / 0.5 - 0.05 <= rec["time_s"] < rec["sim_time_s"]
    assert rec["score"] == pytest.approx(barn_score(True, rec["time_s"], 3.5 / 2.0), abs=1e-3)
    rows = list(csv.DictReader((tmp_path / "out" / "room.csv").open()))
    assert float(rows[-1]["x"]) > 2.4  # the driven path, ground truth
    assert Image.open(tmp_path / "out" / "room.png").size[0] > 100


def test_teb_with_the_jackal_file_replans_while_it_drives(tmp_path: Path) -> None:
    """The bundled Jackal TEB file sets move_base's planner_frequency (1 Hz, as
    teb_local_planner_tutorials): BARN's launch loads no move_base_params.yaml, and with
    move_base's default 0 the plan made from the start, before the posts were seen, was
    kept until TEB failed. DWA with BARN's own files still plans once."""
    teb_file = (
        find_package("robot_navigation") / "param" / "Jackal" / "teb_local_planner_params.yaml"
    )
    teb, _ = run_fixed(replace(_room(tmp_path), planner="teb", teb_params=teb_file), write=False)
    assert teb.status == "succeeded", teb.status
    assert teb.record.planner_calls >= math.floor(teb.sim_time_s) - 1, (teb.record, teb.sim_time_s)
    dwa, _ = run_fixed(_room(tmp_path), write=False)
    assert dwa.status == "succeeded" and dwa.record.planner_calls == 1, dwa.record


@pytest.mark.slow
def test_a_fixed_episode_is_a_function_of_its_seed(tmp_path: Path) -> None:
    cfg = _room(tmp_path)
    a, _ = run_fixed(cfg, write=False)
    b, _ = run_fixed(cfg, write=False)
    assert (a.status, a.time_s, a.record.driven_m) == (b.status, b.time_s, b.record.driven_m)


def test_each_setup_is_warmed_up_once_per_process_with_a_short_episode(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import roverlab.navbench.fixed as fixed

    made: list[FixedConfig] = []

    class Fake:
        def __init__(self, cfg: FixedConfig, log: object) -> None:
            made.append(cfg)
            self.ctx, self._tmp = self, self

        def run(self) -> None:
            pass

        def shutdown(self) -> None:
            pass

        def cleanup(self) -> None:
            pass

    monkeypatch.setattr(fixed, "_Episode", Fake)
    monkeypatch.setattr(fixed, "_warmed", set())
    base = FixedConfig(world="w", out=tmp_path, start=(0, 0, 0), goal=(1, 0, 0), planner="teb")
    fixed._warm_up(base)
    fixed._warm_up(replace(base, world="other", seed=3))  # same setup: no second warm-up
    fixed._warm_up(replace(base, planner="dwa"))
    assert [(c.planner, c.time_limit_s) for c in made] == [("teb", 3.0), ("dwa", 3.0)]


def test_the_episode_stops_after_the_same_event_as_a_condition_checked_every_event(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The episode's spin ends by ``executor.stop()`` from the sampling timer; the plain
    version (``ctx.wait_for`` with the outcome as condition, checked before every event)
    ends after the same event: the same trace, clock and outcome."""
    import roverlab.navbench.fixed as fixed
    from roverlab.batch import episode_stop

    cfg = replace(_room(tmp_path), time_limit_s=1.5)  # ends as a timeout, 1.5 s in

    def episode() -> fixed.FixedResult:
        ep = fixed._Episode(cfg, lambda _line: None)
        try:
            return ep.run()
        finally:
            ep.ctx.shutdown()
            ep._tmp.cleanup()

    fast = episode()

    def plain(self: fixed._Episode, timeout_s: float) -> None:
        stop = episode_stop()
        self.ctx.wait_for(lambda: self.outcome is not None or stop.is_set(), timeout_s)

    monkeypatch.setattr(fixed._Episode, "_spin_until_decided", plain)
    slow = episode()
    assert fast.status == slow.status == "timeout"
    assert fast.sim_time_s == slow.sim_time_s and fast.time_s == slow.time_s
    assert np.array_equal(fast.trace, slow.trace) and len(fast.trace) > 20
