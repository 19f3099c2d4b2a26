"""Gazebo's own settings in a world file that the simulator runs otherwise are named in
``World.notes`` (printed as ``note:`` lines, which ``--strict`` does not refuse)."""

from __future__ import annotations

from pathlib import Path

from roverlab.world import load_sdf
from tests.world.test_sdf import box_model, world_sdf, write

GAZEBO_DEFAULTS = """<physics name='default_physics' default='0' type='ode'>
  <max_step_size>0.001</max_step_size><real_time_factor>1</real_time_factor>
  <real_time_update_rate>1000</real_time_update_rate></physics>"""


def test_physics_timing_other_than_gazebo_s_defaults_and_world_plugins_are_noted(
    tmp_path: Path,
) -> None:
    fast = GAZEBO_DEFAULTS.replace(">1000<", ">0<").replace(">0.001<", ">0.004<")
    plugins = (
        "<plugin name='ros_state' filename='libgazebo_ros_state.so'/>"
        "<plugin name='mine' filename='libmy_world_plugin.so'><rate>5</rate></plugin>"
    )
    body = fast + plugins + box_model("wall", "0 0 0 0 0 0")
    path = write(tmp_path / "w.world", world_sdf(body))
    w = load_sdf(path)
    assert w.notes == (
        f"{path}: <physics> not used (the simulator steps at its physics_rate parameter, "
        "100 Hz by default, and runs at --rate): max_step_size 0.004, real_time_update_rate 0",
        f"{path}: world plugins not run: libgazebo_ros_state.so, libmy_world_plugin.so",
    )
    assert w.warnings == () and len(w.shapes) == 1


def test_gazebo_s_default_physics_is_not_noted(tmp_path: Path) -> None:
    # every world Gazebo saves repeats these: real time, as roverlab runs by default
    body = GAZEBO_DEFAULTS + box_model("wall", "0 0 0 0 0 0")
    assert load_sdf(write(tmp_path / "w.world", world_sdf(body))).notes == ()
