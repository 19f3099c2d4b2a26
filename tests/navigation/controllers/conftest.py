"""Parameters of a small differential-drive robot (0.15 m radius) for the local planners."""

from __future__ import annotations

import pytest

from roverlab.navigation.controllers import DWAParams, TebParams

DWA = {
    "max_vel_x": 0.26, "min_vel_x": 0.0, "max_vel_y": 0.0, "min_vel_y": 0.0,
    "max_vel_trans": 0.26, "min_vel_trans": 0.05, "max_vel_theta": 1.5, "min_vel_theta": 0.4,
    "acc_lim_x": 2.5, "acc_lim_y": 0.0, "acc_lim_theta": 3.2, "xy_goal_tolerance": 0.1,
    "yaw_goal_tolerance": 0.17, "sim_time": 1.5, "vx_samples": 10, "vy_samples": 1,
    "vth_samples": 20, "controller_frequency": 10.0, "occdist_scale": 0.02,
    "goal_distance_bias": 20.0,
}  # fmt: skip
TEB = {
    "max_vel_x": 0.26, "max_vel_x_backwards": 0.1, "max_vel_theta": 1.5, "acc_lim_x": 2.5,
    "acc_lim_theta": 3.2, "min_obstacle_dist": 0.1, "inflation_dist": 0.3,
    "footprint_model": {"type": "circular", "radius": 0.15}, "xy_goal_tolerance": 0.1,
    "yaw_goal_tolerance": 0.17, "weight_kinematics_forward_drive": 10.0,
}  # fmt: skip


@pytest.fixture
def dwa_params() -> DWAParams:
    return DWAParams.from_ros(DWA)[0]


@pytest.fixture
def teb_params() -> TebParams:
    return TebParams.from_ros(TEB)[0]
