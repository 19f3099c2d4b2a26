"""Seed 002's patrol logic: places, order, statistics (pure)."""

from __future__ import annotations

import itertools
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from roverlab.navigation.patrol import (
    PatrolError,
    PatrolSequence,
    PatrolStats,
    Place,
    load_places,
    trunc,
)

PLACES = [Place(str(i), float(i), 0.0, 0.0) for i in range(1, 7)]


def test_rounds_cover_every_place_and_never_repeat_the_last() -> None:
    seq = PatrolSequence(PLACES, np.random.default_rng(3))
    visits = [seq.next().name for _ in range(600)]
    assert all(a != b for a, b in itertools.pairwise(visits))
    counts = Counter(visits)
    assert set(counts) == {p.name for p in PLACES}
    assert max(counts.values()) - min(counts.values()) <= 20  # rounds keep it even
    again = PatrolSequence(PLACES, np.random.default_rng(3))
    assert [again.next().name for _ in range(600)] == visits  # seeded


def test_stats_lines_are_slam_py_s() -> None:
    s = PatrolStats(goals=3, successes=2, distance_m=13.0789)
    assert s.success_line() == "Success so far: 2/3 = 66%"  # slam.py's integer percent
    assert s.time_line(125.9) == "Running time: 2.0 min Distance: 13.0 m"  # secs / 60, cut
    assert PatrolStats().success_line() == "Success so far: 0/0 = 0%"
    assert trunc(2.0833, 1) == 2.0 and trunc(0.99, 1) == 0.9 and trunc(5.0, 1) == 5.0


def test_locations_file_forms_and_errors(tmp_path: Path) -> None:
    f = tmp_path / "places.yaml"
    f.write_text(
        "frame_id: map\nlocations:\n"
        '  "1": {position: {x: 4.589, y: -0.376, z: 0.0}, '
        "orientation: {x: 0.0, y: 0.0, z: -0.447, w: 0.894}}\n"
        "  kitchen: {x: 1.0, y: 2.0, yaw: 1.57}\n"
    )
    frame, places = load_places(f)
    assert frame == "map" and [p.name for p in places] == ["1", "kitchen"]
    assert places[0].x == 4.589 and places[0].yaw == pytest.approx(-0.9273, abs=1e-3)
    for text, needle in (
        ("locations: [1, 2]", "expected a mapping"),
        ("locations: {a: {x: 1, y: 2}}", "at least two"),
        ("locations: {a: {x: 1}, b: {x: 1, y: 2}}", "needs x, y"),
        ("locations: {a: {x: .nan, y: 0}, b: {x: 1, y: 2}}", "not finite"),
        ("locations: {a: {x: 1, y: [}", "malformed YAML"),
    ):
        f.write_text(text)
        with pytest.raises(PatrolError, match=needle):
            load_places(f)
    with pytest.raises(PatrolError, match="cannot read"):
        load_places(tmp_path / "missing.yaml")
