"""hector's revisit check (:mod:`roverlab.slam.hector.revisit`): what counts as another
place, and when candidates from several scans agree. The ring corridor it was made for is
in ``test_simulated.py``."""

from __future__ import annotations

import math

import numpy as np

from roverlab.slam.hector.revisit import Revisit, differs

ALONG_X = np.array([1.0, 0.0])


def test_a_shift_only_along_the_weak_direction_is_the_same_place() -> None:
    here = np.array([2.0, 1.0, 0.0])
    # a corridor along x: 1 m along it is what a stretched first pass looks like
    assert not differs(here + np.array([1.0, 0.05, 0.0]), here, ALONG_X)
    assert differs(here + np.array([0.0, 0.3, 0.0]), here, ALONG_X)
    assert differs(here + np.array([0.0, 0.0, 0.15]), here, ALONG_X)
    # the weak direction is in the robot frame: facing +y, a corridor along y
    up = np.array([0.0, 0.0, math.pi / 2])
    assert not differs(up + np.array([0.0, 1.0, 0.0]), up, ALONG_X)
    assert differs(up + np.array([1.0, 0.0, 0.0]), up, ALONG_X)


def test_candidates_count_only_while_they_agree_with_the_odometry() -> None:
    """Scan after scan, a loop correction is found where the odometry moves it (0.05 m
    ahead, turning); a glitched scan's candidate lies elsewhere and starts the count
    again, and so does the next true one after it."""
    step = np.array([0.05, 0.0, 0.01])
    rev = Revisit()
    cand = np.array([1.0, -0.7, 0.04])
    counts = []
    for _ in range(3):
        counts.append(rev.offer(cand, step))
        c, s = math.cos(cand[2]), math.sin(cand[2])
        cand = cand + np.array([c * step[0], s * step[0], step[2]])
    assert counts == [1, 2, 3]
    assert rev.offer(cand + np.array([0.0, 2.0, 0.0]), step) == 1  # a glitch
    assert rev.offer(cand, step) == 1
    rev.reset()
    assert rev.count == 0
