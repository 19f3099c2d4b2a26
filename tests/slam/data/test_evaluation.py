"""The Kuemmerle relative-pose metric: exact cases, matching, the Radish odometry score."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.slam.data import (
    EvaluationError,
    LaserLog,
    Relations,
    Trajectory,
    evaluate,
    read_relations,
    read_tum,
    write_tum,
)


def random_trajectory(rng: np.random.Generator, count: int = 200) -> list[SE2]:
    pose = SE2()
    out = [pose]
    for _ in range(count - 1):
        pose = pose * SE2(rng.uniform(0.0, 0.5), rng.uniform(-0.1, 0.1), rng.uniform(-0.6, 0.6))
        out.append(pose)
    return out


def relations_of(
    poses: list[SE2],
    pairs: list[tuple[int, int]],
    texts: list[str],
    perturb: Callable[[int, SE2], SE2],
) -> Relations:
    rows = []
    for k, (i, j) in enumerate(pairs):
        rel = perturb(k, ~poses[i] * poses[j])
        rows.append((rel.x, rel.y, rel.theta))
    return Relations(
        first=np.array([float(texts[i]) for i, _ in pairs]),
        second=np.array([float(texts[j]) for _, j in pairs]),
        poses=np.array(rows),
        first_texts=tuple(texts[i] for i, _ in pairs),
        second_texts=tuple(texts[j] for _, j in pairs),
    )


@pytest.fixture
def scene() -> tuple[list[SE2], list[str], list[tuple[int, int]]]:
    rng = np.random.default_rng(7)
    poses = random_trajectory(rng)
    texts = [f"{1000.0 + 0.25 * k:.6f}" for k in range(len(poses))]
    pairs = [(int(i), int(j)) for i, j in rng.integers(0, len(poses), size=(300, 2)) if i != j]
    return poses, texts, pairs


def test_perfect_trajectory_scores_zero(
    scene: tuple[list[SE2], list[str], list[tuple[int, int]]],
) -> None:
    poses, texts, pairs = scene
    rel = relations_of(poses, pairs, texts, lambda _, r: r)
    m = evaluate(Trajectory.from_poses(texts, poses), rel)
    assert m.matched == m.total == len(pairs)
    assert m.trans_mean == pytest.approx(0.0, abs=1e-12)
    assert m.rot_mean_deg == pytest.approx(0.0, abs=1e-10)
    # relative poses do not care where the map frame is
    moved = [SE2(5.0, -3.0, 2.0) * p for p in poses]
    m2 = evaluate(Trajectory.from_poses(texts, moved), rel)
    assert m2.trans_mean == pytest.approx(0.0, abs=1e-9)
    assert m2.rot_std_deg == pytest.approx(0.0, abs=1e-8)


def test_known_perturbations_give_known_errors(
    scene: tuple[list[SE2], list[str], list[tuple[int, int]]],
) -> None:
    poses, texts, pairs = scene

    # true relation = estimated one moved by (0.3, 0.4) or (0.06, 0.08) in its frame, and
    # turned by +-2 or 4 degrees: errors 0.5 / 0.1 m and 2 / 4 degrees, alternately
    def perturb(k: int, r: SE2) -> SE2:
        big = k % 2 == 0
        d = (
            SE2(0.3, 0.4, math.radians(2.0) * (1 if k % 4 == 0 else -1))
            if big
            else SE2(0.06, 0.08, math.radians(4.0))
        )
        return r * d

    rel = relations_of(poses, pairs, texts, perturb)
    m = evaluate(Trajectory.from_poses(texts, poses), rel)
    n_big = sum(1 for k in range(len(pairs)) if k % 2 == 0)
    n = len(pairs)
    trans = np.where(np.arange(n) % 2 == 0, 0.5, 0.1)
    rot = np.where(np.arange(n) % 2 == 0, 2.0, 4.0)
    assert n_big > 0
    np.testing.assert_allclose(m.trans_errors, trans, atol=1e-9)
    np.testing.assert_allclose(m.rot_errors_deg, rot, atol=1e-9)
    assert m.trans_mean == pytest.approx(trans.mean(), abs=1e-9)
    assert m.trans_std == pytest.approx(trans.std(), abs=1e-9)
    assert m.rot_mean_deg == pytest.approx(rot.mean(), abs=1e-9)
    assert m.rot_std_deg == pytest.approx(rot.std(), abs=1e-9)
    assert m.trans_squared_mean == pytest.approx(float(np.mean(trans**2)), abs=1e-9)
    assert m.rot_squared_mean_deg2 == pytest.approx(float(np.mean(rot**2)), abs=1e-7)


def test_hand_computed_relation() -> None:
    # x_i = (1, 2, 90 deg), x_j = (1, 3, 90 deg): x_i^-1 x_j = (1, 0, 0)
    traj = Trajectory.from_poses(["1.0", "2.0"], [SE2(1, 2, math.pi / 2), SE2(1, 3, math.pi / 2)])
    rel = Relations(
        first=np.array([1.0, 1.0]),
        second=np.array([2.0, 2.0]),
        poses=np.array([[1.0, 0.0, 0.1], [0.0, 1.0, 2 * math.pi - 0.01]]),
    )
    m = evaluate(traj, rel)
    np.testing.assert_allclose(m.trans_errors, [0.0, math.sqrt(2.0)], atol=1e-12)
    np.testing.assert_allclose(m.rot_errors_deg, [math.degrees(0.1), math.degrees(0.01)], atol=1e-9)


def test_matching_by_text_and_by_float() -> None:
    traj = Trajectory.from_poses(
        ["976052857.337530", "976052857.348896", "976052858.000000"],
        [SE2(), SE2(1, 0, 0), SE2(2, 0, 0)],
    )
    rel = Relations(
        first=np.array([976052857.33753, 976052857.337530, 976052857.33753]),
        second=np.array([976052857.3488961, 976052857.34891, 976052859.0]),
        poses=np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]),
    )
    m = evaluate(traj, rel)  # floats only: within 1 us matches, 14 us or a missing scan does not
    assert (m.matched, m.total) == (1, 3)
    texts = Relations(
        first=rel.first,
        second=rel.second,
        poses=rel.poses,
        first_texts=("976052857.337530",) * 3,
        second_texts=("976052857.348896", "976052857.34891", "976052858.000000"),
    )
    m = evaluate(traj, texts)
    assert (m.matched, m.total) == (2, 3)
    assert m.trans_errors.tolist() == pytest.approx([0.0, 1.0])
    far = Relations(first=np.array([5.0]), second=np.array([6.0]), poses=np.zeros((1, 3)))
    with pytest.raises(EvaluationError, match="none of the 1 relations"):
        evaluate(traj, far)


def test_read_relations(tmp_path: Path) -> None:
    path = tmp_path / "r.relations"
    path.write_text(
        "976052905.167303 976052911.885496 -0.056990 -0.128430 0.000000 0.000000 0.000000 "
        "-1.682210\n"
        "\n# comment\n"
        "1.5 2.5 1 2 0 0 0 0.5\n"
    )
    rel = read_relations(path)
    assert len(rel) == 2
    assert rel.first_texts == ("976052905.167303", "1.5")
    assert rel.second_texts == ("976052911.885496", "2.5")
    np.testing.assert_array_equal(rel.poses, [[-0.05699, -0.12843, -1.68221], [1.0, 2.0, 0.5]])
    path.write_text("1 2 3 4 5 6 7 8\n1 2 3\n")
    with pytest.raises(EvaluationError, match=r"r\.relations:2: expected 8 values"):
        read_relations(path)
    path.write_text("1 2 3 4 5 6 7 y\n")
    with pytest.raises(EvaluationError, match=r"r\.relations:1: not a number"):
        read_relations(path)
    path.write_text("# nothing\n")
    with pytest.raises(EvaluationError, match="no relations"):
        read_relations(path)
    with pytest.raises(EvaluationError, match="cannot read"):
        read_relations(tmp_path / "absent.relations")


@pytest.mark.parametrize(
    ("name", "relations", "published"), [("intel", 2984, 0.220), ("fr079", 1685, 0.258)]
)
def test_raw_odometry_scores_worse_than_scan_matching(
    radish: Path,
    radish_log: Callable[[str], LaserLog],
    tmp_path: Path,
    name: str,
    relations: int,
    published: float,
) -> None:
    log = radish_log(name)
    rel = read_relations(radish / f"{name}.relations")
    m = evaluate(log.odometry(), rel)
    print(f"{name} raw odometry:", *m.lines(), sep="\n  ")
    assert m.matched == m.total == relations
    assert m.trans_mean > 5 * published  # odometry drifts: far above scan matching's error
    assert m.rot_mean_deg > 5.0
    # through a TUM file the timestamps still match exactly, and the score is the same
    path = tmp_path / "odom.tum"
    write_tum(path, log.odometry())
    m2 = evaluate(read_tum(path), rel)
    assert m2.matched == relations
    assert m2.trans_mean == pytest.approx(m.trans_mean, rel=1e-9)
