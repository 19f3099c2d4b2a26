"""The key -> velocity logic against the two ROS 1 scripts, key by key."""

from __future__ import annotations

import itertools
import math

import pytest

from roverlab.teleop import (
    CTRL_C,
    HELP_TEXT,
    MOVE_BINDINGS,
    SMOOTH_HELP_TEXT,
    SPEED_BINDINGS,
    SmoothTeleop,
    TeleopError,
    TeleopTwistKeyboard,
    TwistCommand,
    twist_for_key,
    vels,
)

# (key, linear x, y, z, angular z) for speed 0.3, turn 0.5, from the script's moveBindings.
EXPECTED_MOVES = [
    ("i", 0.3, 0.0, 0.0, 0.0),
    ("o", 0.3, 0.0, 0.0, -0.5),
    ("j", 0.0, 0.0, 0.0, 0.5),
    ("l", 0.0, 0.0, 0.0, -0.5),
    ("u", 0.3, 0.0, 0.0, 0.5),
    (",", -0.3, 0.0, 0.0, 0.0),
    (".", -0.3, 0.0, 0.0, 0.5),
    ("m", -0.3, 0.0, 0.0, -0.5),
    ("O", 0.3, -0.3, 0.0, 0.0),
    ("I", 0.3, 0.0, 0.0, 0.0),
    ("J", 0.0, 0.3, 0.0, 0.0),
    ("L", 0.0, -0.3, 0.0, 0.0),
    ("U", 0.3, 0.3, 0.0, 0.0),
    ("<", -0.3, 0.0, 0.0, 0.0),
    (">", -0.3, -0.3, 0.0, 0.0),
    ("M", -0.3, 0.3, 0.0, 0.0),
    ("t", 0.0, 0.0, 0.3, 0.0),
    ("b", 0.0, 0.0, -0.3, 0.0),
]


def test_defaults_are_the_seed_scripts() -> None:
    # teleop_twist_keyboard.py: rospy.get_param("~speed", 0.3), ("~turn", 0.5)
    t = TeleopTwistKeyboard()
    assert (t.speed, t.turn) == (0.3, 0.5)
    assert t.key_timeout_s is None  # getKey() blocks
    assert t.banner() == (HELP_TEXT, "currently:\tspeed 0.3\tturn 0.5 ")
    # mbot_teleop.py: speed = .2, turn = 1, getKey() waits 0.1 s
    s = SmoothTeleop()
    assert (s.speed, s.turn) == (0.2, 1)
    assert s.key_timeout_s == 0.1
    assert s.banner() == (SMOOTH_HELP_TEXT, "currently:\tspeed 0.2\tturn 1 ")


def test_help_text_is_the_script_msg() -> None:
    assert HELP_TEXT.startswith("\nReading from the keyboard  and Publishing to Twist!\n")
    assert "   U    I    O\n   J    K    L\n   M    <    >\n" in HELP_TEXT
    assert HELP_TEXT.endswith("CTRL-C to quit\n")
    assert "space key, k : force stop\nanything else : stop smoothly\n" in SMOOTH_HELP_TEXT


def test_bindings_are_complete() -> None:
    assert set(MOVE_BINDINGS) == set("ioljum,.") | set("OIJLU<>M") | {"t", "b"}
    assert set(SPEED_BINDINGS) == set("qzwxec")


@pytest.mark.parametrize(("key", "lx", "ly", "lz", "az"), EXPECTED_MOVES)
def test_every_move_binding(key: str, lx: float, ly: float, lz: float, az: float) -> None:
    t = TeleopTwistKeyboard(speed=0.3, turn=0.5)
    result = t.handle_key(key)
    assert result.twist == TwistCommand(lx, ly, lz, az)
    assert not result.quit and result.lines == ()
    assert twist_for_key(key, 0.3, 0.5) == TwistCommand(lx, ly, lz, az)


@pytest.mark.parametrize(
    ("key", "speed", "turn"),
    [
        ("q", 0.3 * 1.1, 0.5 * 1.1),
        ("z", 0.3 * 0.9, 0.5 * 0.9),
        ("w", 0.3 * 1.1, 0.5),
        ("x", 0.3 * 0.9, 0.5),
        ("e", 0.3, 0.5 * 1.1),
        ("c", 0.3, 0.5 * 0.9),
    ],
)
def test_speed_keys_scale_and_keep_direction(key: str, speed: float, turn: float) -> None:
    t = TeleopTwistKeyboard()
    t.handle_key("u")  # forward + left
    result = t.handle_key(key)
    assert (t.speed, t.turn) == (speed, turn)
    # the script republishes the last direction at the new speeds
    assert result.twist == TwistCommand(speed, 0.0, 0.0, turn)
    assert result.lines == (vels(speed, turn),)
    assert twist_for_key(key, 0.3, 0.5) is None


def test_vels_prints_numbers_as_python2_str() -> None:
    assert repr(0.4 * 1.1) == "0.44000000000000006"  # what Python 3's str() would print
    assert vels(0.4 * 1.1, 0.3 * 1.1 * 1.1) == "currently:\tspeed 0.44\tturn 0.363 "
    assert vels(1.0, 2) == "currently:\tspeed 1.0\tturn 2 "
    assert vels(1e16, 1e-5) == "currently:\tspeed 1e+16\tturn 1e-05 "


@pytest.mark.parametrize("key", ["k", "K", " ", "a", "\r", "\x1b", "é", "", "\x04"])
def test_any_other_key_stops(key: str) -> None:
    t = TeleopTwistKeyboard()
    assert t.handle_key("U").twist == TwistCommand(0.3, 0.3, 0.0, 0.0)
    result = t.handle_key(key)
    assert result.twist == TwistCommand()
    assert result.twist is not None and result.twist.is_zero
    assert not result.quit
    assert t.direction == (0, 0, 0, 0)
    assert twist_for_key(key, 0.3, 0.5) == TwistCommand()


def test_ctrl_c_quits_without_publishing() -> None:
    t = TeleopTwistKeyboard()
    t.handle_key("i")
    result = t.handle_key(CTRL_C)
    assert result.quit and result.twist is None and result.lines == ()


def test_help_reprinted_every_15_speed_changes() -> None:
    t = TeleopTwistKeyboard()
    reprinted = []
    for n in range(1, 46):
        result = t.handle_key("q" if n % 2 else "z")
        assert result.lines[0] == vels(t.speed, t.turn)
        if HELP_TEXT in result.lines:
            assert result.lines == (vels(t.speed, t.turn), HELP_TEXT)
            reprinted.append(n)
    assert reprinted == [15, 30, 45]
    assert t.status == 0


def test_movement_and_stop_keys_do_not_count_towards_the_reprint() -> None:
    t = TeleopTwistKeyboard()
    for _ in range(14):
        t.handle_key("w")
        t.handle_key("i")
        t.handle_key("k")
    assert t.status == 14
    assert t.handle_key("w").lines[-1] == HELP_TEXT


def test_speed_never_overflows_to_inf() -> None:
    t = TeleopTwistKeyboard(speed=1e308, turn=1e308)
    t.handle_key("u")
    for _ in range(10):
        result = t.handle_key("q")
        assert result.twist is not None
        assert math.isfinite(result.twist.linear_x) and math.isfinite(result.twist.angular_z)
    # 1e308 * 1.1**6 is still finite; the 7th press would overflow and is ignored
    assert t.speed == t.turn == pytest.approx(1e308 * 1.1**6)
    assert "inf" not in vels(t.speed, t.turn)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, -0.1, "0.3", True])
def test_bad_speeds_are_rejected(bad: object) -> None:
    with pytest.raises(TeleopError):
        TeleopTwistKeyboard(speed=bad)  # type: ignore[arg-type]
    with pytest.raises(TeleopError):
        SmoothTeleop(turn=bad)  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- smooth


def _linear(s: SmoothTeleop, key: str) -> float:
    twist = s.handle_key(key).twist
    assert twist is not None and twist.linear_y == twist.linear_z == 0.0
    return twist.linear_x


def test_smooth_ramps_up_by_0_02_per_step() -> None:
    s = SmoothTeleop()
    values = [_linear(s, "i") for _ in range(12)]
    assert values[:10] == pytest.approx([0.02 * n for n in range(1, 11)])
    # adding 0.02 ten times gives 0.19999999999999998; min(target, ...) then lands on 0.2
    assert values[9] < 0.2 and values[10:] == [0.2, 0.2]
    assert all(b > a for a, b in itertools.pairwise(values[:10]))


def test_smooth_turn_ramps_by_0_1_per_step() -> None:
    s = SmoothTeleop(turn=0.35)
    turns = []
    for _ in range(5):
        twist = s.handle_key("j").twist
        assert twist is not None and twist.linear_x == 0.0
        turns.append(twist.angular_z)
    assert turns == pytest.approx([0.1, 0.2, 0.3, 0.35, 0.35])
    twist = s.handle_key("l").twist  # reverse: down by 0.1 per step
    assert twist is not None and twist.angular_z == pytest.approx(0.25)


@pytest.mark.parametrize("stop_key", [" ", "k"])
def test_smooth_space_and_k_stop_at_once(stop_key: str) -> None:
    s = SmoothTeleop()
    for _ in range(8):
        s.handle_key("u")
    assert s.command().linear_x == pytest.approx(0.16)
    result = s.handle_key(stop_key)
    assert result.twist == TwistCommand()
    assert _linear(s, "") == 0.0  # and it stays stopped


def test_smooth_stops_after_5_idle_steps_then_ramps_down() -> None:
    s = SmoothTeleop(speed=0.1)
    values = [_linear(s, "i")] + [_linear(s, "") for _ in range(9)]
    # steps 1-5 ramp up (the target holds through 4 idle steps); the 5th idle step
    # (count > 4) sets the target to zero and the speed ramps down again
    assert values == pytest.approx([0.02, 0.04, 0.06, 0.08, 0.1, 0.08, 0.06, 0.04, 0.02, 0.0])
    assert s.idle_count == 9


def test_smooth_unknown_keys_count_as_idle_and_movement_keys_reset() -> None:
    s = SmoothTeleop(speed=0.1)
    for _ in range(5):
        s.handle_key("i")
    for _ in range(4):
        assert _linear(s, "a") == pytest.approx(0.1)
    assert _linear(s, "i") == pytest.approx(0.1)  # count back to 0
    for _ in range(4):
        assert _linear(s, "") == pytest.approx(0.1)
    assert _linear(s, "q") == pytest.approx(0.11)  # a speed key resets the count too
    assert s.speed == pytest.approx(0.11)
    assert _linear(s, "") == pytest.approx(0.11)
    for _ in range(3):
        s.handle_key("")
    assert _linear(s, "") == pytest.approx(0.09)  # 5th idle step after 'q'


def test_smooth_has_no_holonomic_keys() -> None:
    s = SmoothTeleop()
    s.handle_key("i")
    s.handle_key("J")  # not bound: an idle step, the robot keeps going
    twist = s.handle_key("t").twist
    assert twist == TwistCommand(linear_x=pytest.approx(0.06))  # type: ignore[arg-type]


def test_smooth_speed_keys_print_and_reprint_help() -> None:
    s = SmoothTeleop()
    result = s.handle_key("e")
    assert result.lines == ("currently:\tspeed 0.2\tturn 1.1 ",)
    for _ in range(13):
        assert SMOOTH_HELP_TEXT not in s.handle_key("c").lines
    assert s.handle_key("c").lines[-1] == SMOOTH_HELP_TEXT


def test_smooth_ctrl_c_quits() -> None:
    s = SmoothTeleop()
    s.handle_key("i")
    result = s.handle_key(CTRL_C)
    assert result.quit and result.twist is None
