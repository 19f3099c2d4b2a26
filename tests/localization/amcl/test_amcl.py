"""amcl's per-scan logic: update gating, resampling interval, the published pose, models,
global localization, bad input and seeding, on a synthetic room."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.localization.amcl import Amcl, AmclInputError, AmclParams, select_beams
from tests.localization.amcl.helpers import BEARINGS, room_map, scan_at

# a loop through the room, in the map frame (the room's free area is x 0..6, y 0..3.9)
LOOP = [(1.0, 0.7), (5.4, 0.7), (5.4, 2.2), (3.0, 2.9), (0.6, 3.4), (0.6, 0.7)]


def _route(step_m: float = 0.05) -> list[SE2]:
    """Poses every ``step_m`` along :data:`LOOP` (turning on the spot at the corners)."""
    out: list[SE2] = []
    for (x0, y0), (x1, y1) in itertools.pairwise(LOOP):
        yaw = math.atan2(y1 - y0, x1 - x0)
        n = max(1, int(math.hypot(x1 - x0, y1 - y0) / step_m))
        if out:
            for a in np.linspace(out[-1].theta, out[-1].theta + math.remainder(
                    yaw - out[-1].theta, 2 * math.pi), 8)[1:]:  # fmt: skip
                out.append(SE2(x0, y0, float(a)))
        out.extend(SE2(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n, yaw) for k in range(n))
    return out


ODOM_FROM_MAP = SE2(1.0, -2.0, 0.5)


def _run(amcl: Amcl, route: list[SE2], *, odom_from_map: SE2 = ODOM_FROM_MAP,
         seed: int = 0, **scan_kw: Any) -> list[float]:  # fmt: skip
    """Feed scans along ``route``; odometry is the true pose seen from another frame.
    Returns the position error after each scan."""
    rng = np.random.default_rng(seed)
    errors = []
    for truth in route:
        odom = odom_from_map * truth
        r = scan_at(truth, rng=rng, noise=0.01)
        amcl.process_scan(odom_pose=odom, ranges=r, bearings=BEARINGS, range_min=0.05,
                          range_max=10.0, **scan_kw)  # fmt: skip
        est = amcl.pose_at(odom)
        assert est is not None
        errors.append(math.hypot(est.x - truth.x, est.y - truth.y))
    return errors


def _amcl(seed: int = 0, **params: Any) -> Amcl:
    start = params.pop("start", SE2(1.0, 0.7, 0.0))
    return Amcl(AmclParams.from_ros(params), room_map(), rng=np.random.default_rng(seed),
                initial_pose=start)  # fmt: skip


def test_amcl_step_rules_for_beams() -> None:
    assert select_beams(720, 30, "likelihood_field").tolist() == list(range(0, 720, 24))
    assert select_beams(181, 30, "beam").tolist() == list(range(0, 181, 6))
    assert select_beams(360, 30, "likelihood_field_prob").tolist() == list(range(0, 360, 12))
    assert select_beams(20, 30, "likelihood_field").tolist() == list(range(20))
    assert select_beams(0, 30, "beam").size == 0


def test_update_gating_resample_interval_and_publication() -> None:
    amcl = _amcl(resample_interval=2)  # ROS's interval (roverlab's default is 1)
    odom = SE2(0.0, 0.0, 0.0)

    def scan(pose: SE2) -> Any:
        truth = SE2(1.0, 0.7, 0.0) * pose
        return amcl.process_scan(odom_pose=pose, ranges=scan_at(truth), bearings=BEARINGS,
                                 range_max=10.0)  # fmt: skip

    first = scan(odom)  # the first scan: sensor update and a pose, no resampling
    assert first.updated and not first.resampled and first.estimate is not None
    assert first.map_to_odom is not None and first.beams == 30
    small = scan(SE2(0.15, 0.15, 0.4))  # below update_min_d on each axis and update_min_a
    assert not small.updated and small.estimate is None
    moved = scan(SE2(0.21, 0.0, 0.0))  # x moved more than 0.2: update, 2nd one: resample
    assert moved.updated and moved.resampled and moved.estimate is not None
    turned = scan(SE2(0.21, 0.0, 0.6))  # turned more than pi/6
    assert turned.updated and not turned.resampled
    amcl.request_nomotion_update()
    forced = scan(SE2(0.21, 0.0, 0.6))
    assert forced.updated and forced.resampled
    still = scan(SE2(0.21, 0.0, 0.6))  # the request is used up
    assert not still.updated
    assert amcl.updates == 4
    every = _amcl()  # resample_interval 1: every update resamples and publishes, the first too
    first = every.process_scan(odom_pose=odom, ranges=scan_at(SE2(1.0, 0.7, 0.0)),
                               bearings=BEARINGS, range_max=10.0)  # fmt: skip
    assert first.updated and first.resampled and first.estimate is not None


def test_tracking_a_drive_from_an_offset_start() -> None:
    amcl = _amcl(start=SE2(1.2, 0.5, 0.1))  # 0.28 m and 0.1 rad off
    errors = _run(amcl, _route())
    assert max(errors[-100:]) < 0.08
    assert np.median(errors[len(errors) // 3 :]) < 0.04
    est = amcl.last_estimate
    assert est is not None and est.clusters >= 1 and est.cluster_weight > 0.9
    assert 0 < est.covariance[0, 0] < 0.01 and est.covariance[0, 2] == 0.0


@pytest.mark.parametrize(
    "params",
    [
        {"laser_model_type": "beam"},
        {"laser_model_type": "likelihood_field"},
        {"do_beamskip": True},
        {"odom_model_type": "diff"},
        {  # ROS 1 amcl's defaults
            "laser_model_type": "likelihood_field",
            "laser_sigma_hit": 0.2,
            "odom_model_type": "diff",
            "resample_interval": 2,
        },
        {"odom_model_type": "omni"},
        {"odom_model_type": "omni-corrected"},
        {"selective_resampling": True, "resample_interval": 1},
    ],
)
def test_other_models_track_too(params: dict[str, Any]) -> None:
    route = _route(0.08)
    errors = _run(_amcl(start=SE2(1.1, 0.6, 0.05), **params), route)
    assert np.median(errors[len(errors) // 2 :]) < 0.06, params


def test_global_localization_finds_the_robot() -> None:
    amcl = Amcl(AmclParams(), room_map(), rng=np.random.default_rng(2), global_start=True)
    assert amcl.pf.count == 5000
    route = _route()
    errors = _run(amcl, route + route)
    assert max(errors[-200:]) < 0.1
    assert amcl.pf.count < 2000


def test_seeded_runs_repeat() -> None:
    route = _route(0.1)[:60]

    def run(seed: int) -> np.ndarray:
        amcl = _amcl(seed, recovery_alpha_slow=0.001, recovery_alpha_fast=0.1)
        _run(amcl, route)
        return amcl.pf.poses

    assert np.array_equal(run(5), run(5))
    assert not np.array_equal(run(5), run(6))


def test_a_scan_without_valid_readings_skips_the_sensor_update() -> None:
    amcl = _amcl()
    bad = np.full(BEARINGS.shape, np.nan)
    bad[::2] = np.inf
    r = amcl.process_scan(odom_pose=SE2(), ranges=bad, bearings=BEARINGS, range_max=10.0)
    assert r.updated and r.beams == 0
    assert r.note == "the scan has no finite reading within (0, 10) m: sensor update skipped"
    assert r.estimate is not None  # the pose is still published
    moved = amcl.process_scan(odom_pose=SE2(0.3, 0, 0), ranges=bad, bearings=BEARINGS,
                              range_max=10.0)  # fmt: skip
    assert moved.updated and moved.resampled  # motion is integrated all the same
    beam = _amcl(laser_model_type="beam")
    r = beam.process_scan(odom_pose=SE2(), ranges=np.full(360, np.nan), bearings=BEARINGS,
                          range_max=10.0)  # fmt: skip
    assert r.beams == 0 and "no reading that is not NaN" in r.note
    # inf counts as a max-range reading for the beam model (z_max)
    beam.request_nomotion_update()
    r = beam.process_scan(odom_pose=SE2(), ranges=np.full(360, np.inf), bearings=BEARINGS,
                          range_max=10.0)  # fmt: skip
    assert r.beams == 30 and r.note == ""


def test_short_readings_count_as_max_range_and_limits_apply() -> None:
    amcl = _amcl(laser_min_range=1.0, laser_max_range=2.5)
    truth = SE2(1.0, 0.7, 0.0)
    r = amcl.process_scan(odom_pose=SE2(), ranges=scan_at(truth), bearings=BEARINGS,
                          range_max=10.0)  # fmt: skip
    ranges = scan_at(truth)[select_beams(360, 30, "likelihood_field")]
    assert r.beams == int(((ranges > 1.0) & (ranges < 2.5)).sum())


def test_bad_scans_and_poses_are_clear_errors() -> None:
    amcl = _amcl()
    with pytest.raises(AmclInputError, match="360 ranges but 359 bearings"):
        amcl.process_scan(odom_pose=SE2(), ranges=np.ones(360), bearings=BEARINGS[:-1])
    with pytest.raises(AmclInputError, match="odometry pose must be finite"):
        amcl.process_scan(odom_pose=SE2(math.nan, 0, 0), ranges=np.ones(360), bearings=BEARINGS)
    with pytest.raises(AmclInputError, match="bearings must be finite"):
        amcl.process_scan(odom_pose=SE2(), ranges=np.ones(2), bearings=[0.0, math.inf])
    with pytest.raises(
        AmclInputError,
        match=r"initial pose \(9.000, 1.000\) is outside the map "
        r"\(x -1.00 .. 7.00, y -0.50 .. 4.50\)",
    ):
        amcl.set_initial_pose(SE2(9.0, 1.0, 0.0), np.eye(3) * 0.1)
    with pytest.raises(AmclInputError, match="outside the map"):
        Amcl(AmclParams(initial_pose_x=-20.0), room_map(), rng=np.random.default_rng(0))
    with pytest.raises(AmclInputError, match="finite"):
        amcl.set_initial_pose(SE2(1.0, math.inf, 0.0), np.eye(3))
    # the filter is untouched by the rejected poses
    r = amcl.process_scan(odom_pose=SE2(), ranges=scan_at(SE2(1.0, 0.7, 0.0)),
                          bearings=BEARINGS, range_max=10.0)  # fmt: skip
    assert r.estimate is not None and abs(r.estimate.pose.x - 1.0) < 0.2
