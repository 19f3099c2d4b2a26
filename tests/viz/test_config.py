"""Display configurations: the seeds' .rviz files, the dashboard's JSON, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from roverlab.viz.config import (
    CONFIG_FORMAT,
    DISPLAY_KINDS,
    ConfigError,
    DashboardConfig,
    DisplayConfig,
    config_from_dict,
    default_config,
    load_config,
    load_rviz,
    parse_rviz,
    save_config,
)

FIXTURES = Path(__file__).parent / "fixtures"


def test_gmapping_rviz_from_seed_000_loads() -> None:
    config = load_rviz(FIXTURES / "gmapping.rviz")
    assert config.fixed_frame == "map"
    assert [d.kind for d in config.displays] == [
        "grid",
        "odometry",
        "odometry",
        "robot_model",
        "map",
        "laser_scan",
    ]
    assert config.unsupported == []
    grid, odom, ekf, robot, gmap, scan = config.displays
    assert grid.option("cell_size") == 0.5 and grid.option("cell_count") == 80
    assert grid.option("color") == [88, 88, 90] and grid.option("reference_frame") == "map"
    assert not odom.enabled and odom.topic == "/odom" and odom.option("keep") == 100
    assert odom.option("color") == [255, 25, 0]  # from Shape/Color
    assert odom.option("length") == pytest.approx(1.3)  # Shaft Length + Head Length
    assert ekf.name == "Odometry EKF"
    assert robot.enabled and robot.topic == "/robot_description"
    assert gmap.topic == "/map" and gmap.option("alpha") == 0.5
    assert gmap.option("color_scheme") == "map" and gmap.option("draw_behind") is True
    assert scan.topic == "/scan" and scan.option("color") == [255, 0, 0]
    assert scan.option("decay_s") == 0.0 and scan.option("size_px") == 3.0


def test_test_rviz_from_seed_001_loads() -> None:
    config = load_rviz(FIXTURES / "test.rviz")
    assert config.fixed_frame == "odom"
    kinds = {d.kind: d for d in config.displays}
    assert list(kinds) == ["grid", "robot_model", "tf", "odometry"]
    assert kinds["grid"].option("reference_frame") == ""  # <Fixed Frame>
    assert not kinds["tf"].enabled and kinds["tf"].option("show_names") is True
    assert kinds["odometry"].option("keep") == 10
    assert kinds["odometry"].option("position_tolerance") == pytest.approx(0.1)


def test_unknown_display_classes_are_listed_not_errors() -> None:
    text = """
Visualization Manager:
  Displays:
    - Class: rviz/Axes
      Name: Axes
    - Class: rviz/Group
      Name: Nav
      Displays:
        - Class: rviz/Path
          Name: Plan
          Topic: /plan
          Color: 0; 0; 255
          Line Width: 0.05
        - Class: rviz_default_plugins/Map
          Name: Costmap
          Topic: /costmap
          Color Scheme: costmap
    - Class: rviz/Image
      Name: Cam
      Topic: /camera/image_raw
      Transport Hint: compressed
  Global Options:
    Fixed Frame: /odom
"""
    config = parse_rviz(text, "nav.rviz")
    assert config.unsupported == ["Axes (rviz/Axes)"]
    assert config.fixed_frame == "odom"
    plan, costmap, cam = config.displays
    assert plan.kind == "path" and plan.option("color") == [0, 0, 255]
    assert plan.option("line_width") == 0.05
    assert costmap.kind == "map" and costmap.option("color_scheme") == "costmap"
    assert cam.kind == "image" and cam.topic == "/camera/image_raw/compressed"


def test_point_colour_transformer_properties_are_read() -> None:
    text = """
Visualization Manager:
  Displays:
    - Class: rviz/LaserScan
      Name: Scan
      Topic: /scan
      Color Transformer: Intensity
      Channel Name: intensities
      Autocompute Intensity Bounds: false
      Min Intensity: 100
      Max Intensity: 3000
      Use rainbow: false
      Invert Rainbow: true
      Min Color: 0; 0; 255
      Max Color: 255; 255; 0
    - Class: rviz/PointCloud2
      Name: Cloud
      Topic: /points
      Color Transformer: AxisColor
      Axis: X
      Autocompute Value Bounds:
        Max Value: 4
        Min Value: -1
        Value: false
      Use Fixed Frame: false
"""
    scan, cloud = parse_rviz(text, "colours.rviz").displays
    assert scan.option("channel_name") == "intensities"
    assert scan.option("autocompute_intensity_bounds") is False
    assert (scan.option("min_intensity"), scan.option("max_intensity")) == (100.0, 3000.0)
    assert scan.option("use_rainbow") is False and scan.option("invert_rainbow") is True
    assert scan.option("min_color") == [0, 0, 255] and scan.option("max_color") == [255, 255, 0]
    assert cloud.option("axis") == "X" and cloud.option("autocompute_value_bounds") is False
    assert (cloud.option("min_value"), cloud.option("max_value")) == (-1.0, 4.0)
    assert cloud.option("use_fixed_frame") is False
    with pytest.raises(ConfigError, match="axis"):
        parse_rviz(text.replace("Axis: X", "Axis: W"), "bad.rviz")


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("a: [", "not a valid .rviz"),
        ("Panels: []", "no 'Visualization Manager'"),
        ("Visualization Manager:\n  Displays: 3", "'Displays' must be a list"),
        (
            "Visualization Manager:\n  Displays:\n    - Class: rviz/Map\n      Alpha: lots",
            "Alpha must be a number",
        ),
        (
            "Visualization Manager:\n  Displays:\n    - Class: rviz/LaserScan\n      Color: red",
            "bad colour",
        ),
    ],
)
def test_bad_rviz_files_give_one_clear_error(text: str, needle: str) -> None:
    with pytest.raises(ConfigError, match=needle) as info:
        parse_rviz(text, "bad.rviz")
    assert "bad.rviz" in str(info.value)


def test_dashboard_json_round_trips(tmp_path: Path) -> None:
    config = load_rviz(FIXTURES / "gmapping.rviz")
    config.displays.append(DisplayConfig("marker", "M", True, "/m", {}))
    path = save_config(config, tmp_path / "sub" / "dash.json")
    data = json.loads(path.read_text())
    assert data["format"] == CONFIG_FORMAT and data["version"] == 1
    # every option is written, defaults included
    assert set(data["displays"][5]["options"]) == set(DISPLAY_KINDS["laser_scan"].options)
    back = load_config(path)
    assert back.fixed_frame == config.fixed_frame
    assert [d.to_dict() for d in back.displays] == [d.to_dict() for d in config.displays]
    assert not list(tmp_path.glob("sub/.dash.json.*")), "temp file left behind"


def test_load_config_reads_rviz_files_too() -> None:
    assert load_config(FIXTURES / "test.rviz").fixed_frame == "odom"


@pytest.mark.parametrize(
    ("mutate", "needle"),
    [
        (lambda d: d.update(format="x"), "not a roverlab dashboard config"),
        (lambda d: d.update(version=9), "unsupported config version"),
        (lambda d: d["displays"][0].update(kind="teapot"), "unknown display kind"),
        (lambda d: d["displays"][1]["options"].update(alhpa=1), "no option 'alhpa'"),
        (lambda d: d["displays"][1]["options"].update(alpha="x"), "must be a number"),
        (lambda d: d["displays"][1]["options"].update(color_scheme="neon"), "must be one of"),
        (lambda d: d["displays"][0].update(colour=1), "unknown display key"),
    ],
)
def test_bad_json_configs_are_rejected(mutate: object, needle: str) -> None:
    data = default_config().to_dict()
    mutate(data)  # type: ignore[operator]
    with pytest.raises(ConfigError, match=needle):
        config_from_dict(data, "page")


def test_default_config_has_every_kind_and_validates() -> None:
    config = default_config("odom")
    assert config.fixed_frame == "odom"
    assert {d.kind for d in config.displays} == set(DISPLAY_KINDS)
    again = config_from_dict(config.to_dict())
    assert isinstance(again, DashboardConfig) and len(again.displays) == len(config.displays)


def test_unreadable_file_is_a_config_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read"):
        load_config(tmp_path / "missing.rviz")
    bad = tmp_path / "bad.json"
    bad.write_text("{ nope")
    with pytest.raises(ConfigError, match="not valid JSON"):
        load_config(bad)


def test_rviz_views_pick_the_3d_view() -> None:
    orbit = load_rviz(FIXTURES / "test.rviz").view
    assert orbit["mode"] == "Orbit" and orbit["target_frame"] == ""
    assert orbit["distance"] == pytest.approx(6.24399, abs=1e-4)
    assert orbit["yaw"] == pytest.approx(0.84040, abs=1e-4)
    assert orbit["pitch"] == pytest.approx(0.37040, abs=1e-4)
    assert orbit["focal_point"][0] == pytest.approx(-0.67816, abs=1e-4)
    text = (FIXTURES / "test.rviz").read_text()
    top = parse_rviz(
        text.replace("Class: rviz/Orbit", "Class: rviz/TopDownOrtho\n      Scale: 110\n      X: 2"),
        "top.rviz",
    ).view
    assert top["mode"] == "TopDownOrtho" and top["scale"] == 110 and top["x"] == 2
    follow = parse_rviz(
        text.replace("Class: rviz/Orbit", "Class: rviz/ThirdPersonFollower").replace(
            "Target Frame: <Fixed Frame>", "Target Frame: base_link"
        ),
        "follow.rviz",
    ).view
    assert follow["mode"] == "ThirdPersonFollower" and follow["target_frame"] == "base_link"
    no_views = parse_rviz(text.split("  Views:")[0], "none.rviz")
    assert no_views.view == {"mode": "2D"}


def test_saved_view_round_trips_and_bad_view_is_one_error(tmp_path: Path) -> None:
    config = load_rviz(FIXTURES / "test.rviz")
    path = save_config(config, tmp_path / "dash.json")
    assert load_config(path).view == config.view
    data = config.to_dict()
    data["view"] = {"mode": "Fisheye"}
    with pytest.raises(ConfigError, match="view must be a mapping with mode one of"):
        config_from_dict(data, "dash.json")
    data["view"] = {"mode": "Orbit", "distance": "far"}
    with pytest.raises(ConfigError, match=r"dash\.json: view distance must be a number"):
        config_from_dict(data, "dash.json")


def test_rviz_frame_rate_is_read_saved_and_checked(tmp_path: Path) -> None:
    text = (FIXTURES / "test.rviz").read_text()
    assert "    Frame Rate: 30\n" in text
    assert parse_rviz(text, "test.rviz").frame_rate_hz == 30.0
    five = parse_rviz(text.replace("Frame Rate: 30", "Frame Rate: 5"), "five.rviz")
    assert five.frame_rate_hz == 5.0
    assert parse_rviz(text.replace("    Frame Rate: 30\n", ""), "none.rviz").frame_rate_hz == 30.0
    path = save_config(five, tmp_path / "dash.json")
    assert json.loads(path.read_text())["frame_rate_hz"] == 5.0
    assert load_config(path).frame_rate_hz == 5.0
    data = five.to_dict()
    del data["frame_rate_hz"]  # a file saved before the option: rviz's default
    assert config_from_dict(data).frame_rate_hz == 30.0
    for bad in (0, -3, "fast", True):
        data["frame_rate_hz"] = bad
        with pytest.raises(ConfigError, match=r"dash\.json: Frame Rate must be a number >= 1"):
            config_from_dict(data, "dash.json")
    with pytest.raises(ConfigError, match=r"bad\.rviz: Global Options: Frame Rate must be"):
        parse_rviz(text.replace("Frame Rate: 30", "Frame Rate: 0"), "bad.rviz")
    with pytest.raises(ConfigError, match=r"bad\.rviz: Global Options: Frame Rate must be a"):
        parse_rviz(text.replace("Frame Rate: 30", "Frame Rate: fast"), "bad.rviz")
    with pytest.raises(ConfigError, match="Frame Rate must be a number >= 1"):
        DashboardConfig(frame_rate_hz=0.5)
