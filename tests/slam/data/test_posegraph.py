"""g2o pose graphs: reading and writing, chi2, Jacobians, the optimiser on the benchmarks."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest

from roverlab.slam.data import (
    PoseGraph,
    PoseGraphError,
    chi2,
    chordal_initialisation,
    edge_errors,
    odometry_initialisation,
    optimize,
    read_g2o,
    write_g2o,
)
from roverlab.slam.data import pose_solver as pg


def graph_of(
    poses: np.ndarray, pairs: list[tuple[int, int]], info: np.ndarray | None = None
) -> PoseGraph:
    """A graph whose measurements agree exactly with ``poses``."""
    fr = np.array([i for i, _ in pairs])
    to = np.array([j for _, j in pairs])
    xi, xj = poses[fr], poses[to]
    c, s = np.cos(xi[:, 2]), np.sin(xi[:, 2])
    dx, dy = xj[:, 0] - xi[:, 0], xj[:, 1] - xi[:, 1]
    z = np.stack(
        [
            c * dx + s * dy,
            -s * dx + c * dy,
            np.remainder(xj[:, 2] - xi[:, 2] + np.pi, 2 * np.pi) - np.pi,
        ],
        1,
    )
    if info is None:
        info = np.tile(np.diag([10.0, 10.0, 100.0]), (len(pairs), 1, 1))
    return PoseGraph(
        ids=np.arange(poses.shape[0]),
        poses=poses,
        edge_from=fr,
        edge_to=to,
        measurements=z,
        information=info,
    )


def ring(rng: np.random.Generator, n: int = 30, loops: int = 10) -> PoseGraph:
    """Poses round a circle (crossing theta = +-pi), odometry edges and random loop closures."""
    poses = np.zeros((n, 3))
    for k in range(1, n):
        th = poses[k - 1, 2]
        poses[k] = (
            poses[k - 1, 0] + math.cos(th),
            poses[k - 1, 1] + math.sin(th),
            math.remainder(th + 2 * math.pi / n, 2 * math.pi),
        )
    pairs = [(k, k + 1) for k in range(n - 1)]
    pairs += [
        (int(a), int(b)) for a, b in (sorted(rng.choice(n, 2, replace=False)) for _ in range(loops))
    ]
    return graph_of(poses, pairs)


def assert_poses_close(a: np.ndarray, b: np.ndarray, atol: float) -> None:
    np.testing.assert_allclose(a[:, :2], b[:, :2], atol=atol)
    np.testing.assert_allclose(
        np.remainder(a[:, 2] - b[:, 2] + np.pi, 2 * np.pi) - np.pi, 0.0, atol=atol
    )


def perturbed(graph: PoseGraph, rng: np.random.Generator, *, xy: float, theta: float) -> np.ndarray:
    x = graph.poses.copy()
    x[1:, :2] += rng.normal(0.0, xy, (x.shape[0] - 1, 2))
    x[1:, 2] += rng.uniform(-theta, theta, x.shape[0] - 1)
    return x


# ------------------------------------------------------------------ chi2 and Jacobians


def test_chi2_of_a_hand_computed_graph() -> None:
    # vertex 0 at (1, 2, 30 deg), vertex 1 at (2, 4, 100 deg); measured z = (2.1, 1.2, 1.3)
    th_i, th_j = math.radians(30), math.radians(100)
    z = (2.1, 1.2, 1.3)
    omega = np.array([[4.0, 0.5, 0.1], [0.5, 3.0, 0.2], [0.1, 0.2, 9.0]])
    graph = PoseGraph(
        ids=np.array([0, 1]),
        poses=np.array([[1.0, 2.0, th_i], [2.0, 4.0, th_j]]),
        edge_from=np.array([0]),
        edge_to=np.array([1]),
        measurements=np.array([z]),
        information=omega[None],
    )
    # R(th_i)^T (t_j - t_i), with t_j - t_i = (1, 2)
    ux = math.cos(th_i) * 1 + math.sin(th_i) * 2
    uy = -math.sin(th_i) * 1 + math.cos(th_i) * 2
    px, py = ux - z[0], uy - z[1]
    e = np.array(
        [
            math.cos(z[2]) * px + math.sin(z[2]) * py,
            -math.sin(z[2]) * px + math.cos(z[2]) * py,
            th_j - th_i - z[2],
        ]
    )
    assert e[2] == pytest.approx(math.radians(70) - 1.3)
    np.testing.assert_allclose(edge_errors(graph)[0], e, atol=1e-12)
    expected = float(e @ omega @ e)
    assert chi2(graph) == pytest.approx(expected, rel=1e-12)
    # worked out by hand (6 digits): R(30 deg)^T (1, 2) = (1.866025, 1.232051), minus z_t
    # = (-0.233975, 0.032051), rotated by -1.3 rad = (-0.031705, 0.234023); angle -0.078270;
    # Omega e = (-0.017636, 0.670562, -0.660796); e . Omega e = 0.209206
    np.testing.assert_allclose(edge_errors(graph)[0], [-0.031705, 0.234023, -0.078270], atol=2e-6)
    assert chi2(graph) == pytest.approx(0.209206, abs=3e-6)
    # the angle error wraps: +- 2 pi on a heading changes nothing
    shifted = graph.poses.copy()
    shifted[1, 2] -= 2 * math.pi
    assert chi2(graph, shifted) == pytest.approx(expected, rel=1e-12)


def test_angle_error_wraps_across_pi() -> None:
    graph = graph_of(np.array([[0.0, 0.0, 3.0], [1.0, 0.0, -3.0]]), [(0, 1)])
    assert graph.measurements[0, 2] == pytest.approx(2 * math.pi - 6.0)
    assert chi2(graph) == pytest.approx(0.0, abs=1e-20)


def test_jacobians_match_finite_differences() -> None:
    rng = np.random.default_rng(3)
    graph = ring(rng, n=8, loops=4)
    x = perturbed(graph, rng, xy=0.5, theta=0.5)
    e, a, b = pg._linearise(graph, x)
    h = 1e-6
    for v in range(graph.num_vertices):
        for d in range(3):
            xp, xm = x.copy(), x.copy()
            xp[v, d] += h
            xm[v, d] -= h
            num = (edge_errors(graph, xp) - edge_errors(graph, xm)) / (2 * h)
            ana = np.zeros_like(num)
            ana[graph.edge_from == v] += a[graph.edge_from == v][:, :, d]
            ana[graph.edge_to == v] += b[graph.edge_to == v][:, :, d]
            np.testing.assert_allclose(ana, num, atol=1e-7)
    np.testing.assert_allclose(e, edge_errors(graph, x))


# ------------------------------------------------------------------ g2o files


G2O = """# a small graph
VERTEX_SE2 10 0.0 0.0 0.0
VERTEX_SE2 12 1.0 0.0 0.1
VERTEX_SE2 15 2.0 0.5 1.5707963267948966
EDGE_SE2 10 12 1.0 0.0 0.1 500 1.5 0 500 0 2000
EDGE_SE2 12 15 0.95 0.55 1.47 400.25 0 3 400 0 1000

EDGE_SE2 10 15 2.0 0.5 1.57 100 0 0 100 0 1000
FIX 12
"""


def test_g2o_round_trip(tmp_path: Path) -> None:
    path = tmp_path / "g.g2o"
    path.write_text(G2O)
    graph = read_g2o(path)
    assert graph.ids.tolist() == [10, 12, 15]
    assert graph.vertices_given
    assert graph.fixed.tolist() == [1]
    assert graph.edge_from.tolist() == [0, 1, 0] and graph.edge_to.tolist() == [1, 2, 2]
    np.testing.assert_array_equal(
        graph.information[0], [[500, 1.5, 0], [1.5, 500, 0], [0, 0, 2000]]
    )
    np.testing.assert_array_equal(graph.information[1], [[400.25, 0, 3], [0, 400, 0], [3, 0, 1000]])
    out = tmp_path / "out.g2o"
    new_poses = graph.poses + 0.125
    write_g2o(out, graph, new_poses)
    back = read_g2o(out)
    np.testing.assert_array_equal(back.poses, new_poses)
    np.testing.assert_array_equal(back.measurements, graph.measurements)
    np.testing.assert_array_equal(back.information, graph.information)
    assert back.ids.tolist() == [10, 12, 15] and back.fixed.tolist() == [1]
    assert (
        out.read_text().splitlines()[3]
        == "EDGE_SE2 10 12 1.0 0.0 0.1 500.0 1.5 0.0 500.0 0.0 2000.0"
    )
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_graph_without_vertices_is_chained_from_odometry(tmp_path: Path) -> None:
    path = tmp_path / "e.g2o"
    # 1 -> 2 is given backwards (2 -> 1), vertex 3 only through a loop closure from 0
    path.write_text(
        "EDGE_SE2 0 1 1.0 0.0 1.5707963267948966 1 0 0 1 0 1\n"
        "EDGE_SE2 2 1 -1.0 0.0 0.0 1 0 0 1 0 1\n"
        "EDGE_SE2 0 3 0.0 -2.0 0.5 1 0 0 1 0 1\n"
    )
    graph = read_g2o(path)
    assert not graph.vertices_given
    np.testing.assert_allclose(
        graph.poses, [[0, 0, 0], [1, 0, math.pi / 2], [1, 1, math.pi / 2], [0, -2, 0.5]], atol=1e-12
    )
    assert chi2(graph) == pytest.approx(0.0, abs=1e-20)
    np.testing.assert_allclose(odometry_initialisation(graph), graph.poses)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("VERTEX_SE2 0 0 0\n", r"g\.g2o:1: malformed VERTEX_SE2 line: VERTEX_SE2 needs 4 values"),
        ("VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 x\n", r"g\.g2o:2: malformed EDGE_SE2"),
        ("VERTEX_XY 0 1 2\n", r"g\.g2o:1: unsupported g2o element 'VERTEX_XY'"),
        (
            "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 7 1 0 0 1 0 0 1 0 1\n",
            "names vertex 7, which has no VERTEX_SE2",
        ),
        ("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n", "appears twice"),
        ("# empty\n", "no VERTEX_SE2 or EDGE_SE2"),
        (
            "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 inf\n",
            "non-finite",
        ),
    ],
)
def test_g2o_errors(tmp_path: Path, text: str, match: str) -> None:
    path = tmp_path / "g.g2o"
    path.write_text(text)
    with pytest.raises(PoseGraphError, match=match):
        read_g2o(path)


def test_graph_validation() -> None:
    poses = np.zeros((2, 3))
    good = {
        "ids": np.array([0, 1]),
        "poses": poses,
        "edge_from": np.array([0]),
        "edge_to": np.array([1]),
        "measurements": np.zeros((1, 3)),
        "information": np.eye(3)[None],
    }
    PoseGraph(**good)
    with pytest.raises(PoseGraphError, match="outside"):
        PoseGraph(**{**good, "edge_to": np.array([2])})
    with pytest.raises(PoseGraphError, match="itself"):
        PoseGraph(**{**good, "edge_to": np.array([0])})
    with pytest.raises(PoseGraphError, match="symmetric"):
        PoseGraph(**{**good, "information": np.triu(np.ones((3, 3)))[None]})
    with pytest.raises(PoseGraphError, match="shape"):
        chi2(PoseGraph(**good), np.zeros((3, 3)))


# ------------------------------------------------------------------ optimiser


def test_noise_free_ring_is_solved_exactly() -> None:
    rng = np.random.default_rng(11)
    graph = ring(rng)
    start = perturbed(graph, rng, xy=0.3, theta=0.3)
    assert chi2(graph, start) > 100
    for method in ("auto", "levenberg-marquardt"):
        x, report = optimize(graph, start, method=method)  # type: ignore[arg-type]
        assert report.converged, report.reason
        assert report.final_chi2 < 1e-12
        assert report.final_chi2 == pytest.approx(chi2(graph, x), abs=1e-15)
        assert_poses_close(x, graph.poses, atol=1e-7)
        assert report.history[0] == pytest.approx(chi2(graph, start))
        if method == "levenberg-marquardt":  # LM keeps only steps that lower chi2
            assert np.all(np.diff(report.history) < 0)
    # the same inputs give the same result, bit for bit
    x1, _ = optimize(graph, start)
    x2, _ = optimize(graph, start)
    np.testing.assert_array_equal(x1, x2)


def test_chordal_start_escapes_local_minima() -> None:
    rng = np.random.default_rng(32)
    graph = ring(rng)
    start = perturbed(graph, rng, xy=3.0, theta=2.5)
    _, local = optimize(graph, start, max_iterations=200)
    assert local.final_chi2 > 100  # a local minimum far from the truth
    x = chordal_initialisation(graph, start)
    assert_poses_close(x, graph.poses, atol=1e-9)  # noise free: exact at once
    _, report = optimize(graph, start, init="chordal")
    assert report.final_chi2 < 1e-12


def test_gauss_newton_falls_back_to_levenberg_marquardt(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(33)
    graph = ring(rng)
    start = perturbed(graph, rng, xy=3.0, theta=2.5)
    _, plain = optimize(graph, start, max_iterations=200)
    assert plain.history[1] > plain.history[0]  # the first undamped step raises chi2 here
    # with a watchdog of one step, LM takes over from the start at once
    monkeypatch.setattr(pg, "_WATCHDOG_STEPS", 1)
    x, report = optimize(graph, start, max_iterations=200)
    assert report.gauss_newton_steps == 1 < report.iterations
    assert report.converged and report.final_chi2 < report.initial_chi2
    lm_x, lm = optimize(graph, start, max_iterations=200, method="levenberg-marquardt")
    assert lm.gauss_newton_steps == 0 and lm.iterations == report.iterations - 1
    np.testing.assert_array_equal(x, lm_x)


def test_fixed_vertices_stay_and_bad_arguments() -> None:
    rng = np.random.default_rng(5)
    base = ring(rng, n=10, loops=3)
    graph = PoseGraph(
        ids=base.ids,
        poses=base.poses,
        edge_from=base.edge_from,
        edge_to=base.edge_to,
        measurements=base.measurements,
        information=base.information,
        fixed=np.array([4]),
    )
    start = perturbed(graph, rng, xy=0.2, theta=0.2)
    start[4] = (7.0, -3.0, 1.0)
    x, report = optimize(graph, start)
    np.testing.assert_array_equal(x[4], start[4])
    assert report.final_chi2 < 1e-12
    with pytest.raises(PoseGraphError, match="max_iterations"):
        optimize(graph, max_iterations=-1)
    with pytest.raises(PoseGraphError, match="unknown initialisation"):
        optimize(graph, init="magic")  # type: ignore[arg-type]
    with pytest.raises(PoseGraphError, match="unknown method"):
        optimize(graph, method="newton")  # type: ignore[arg-type]
    _, none = optimize(graph, max_iterations=0)
    assert none.iterations == 0 and not none.converged


def test_disconnected_vertex_is_an_error() -> None:
    poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    graph = graph_of(poses, [(0, 1), (2, 3)])
    with pytest.raises(PoseGraphError, match="vertices 2, 3 are not connected"):
        optimize(graph)
    with pytest.raises(PoseGraphError, match="not connected"):
        chordal_initialisation(graph)


# ------------------------------------------------------------------ the benchmark graphs

REFERENCE = {
    "input_INTEL_g2o": 215.83,
    "input_M3500_g2o": 137.91,
    "sesync_CSAIL": 40.56,
    "sesync_city10000": 511.99,
}


@pytest.mark.parametrize("name", list(REFERENCE))
def test_benchmark_graphs_reach_the_reference_chi2(posegraphs: Path, name: str) -> None:
    graph = read_g2o(posegraphs / f"{name}.g2o")
    t0 = time.perf_counter()
    x, report = optimize(graph)
    elapsed = time.perf_counter() - t0
    reference = REFERENCE[name]
    print(
        f"{name}: chi2 {report.initial_chi2:.6g} -> {report.final_chi2:.4f} "
        f"(reference {reference}) in {report.iterations} iterations, {elapsed:.2f} s"
    )
    assert report.converged, report.reason
    assert report.final_chi2 == pytest.approx(reference, rel=1e-3)
    assert chi2(graph, x) == pytest.approx(report.final_chi2, rel=1e-12)
    np.testing.assert_array_equal(x[0], graph.poses[0])  # the first pose is fixed
    assert elapsed < 60.0  # a few seconds for city10000 on a quiet machine


@pytest.mark.parametrize("name", ["input_INTEL_g2o", "input_M3500_g2o"])
def test_benchmark_graphs_from_the_chordal_start(posegraphs: Path, name: str) -> None:
    graph = read_g2o(posegraphs / f"{name}.g2o")
    start = chordal_initialisation(graph)
    assert chi2(graph, start) < 2 * REFERENCE[name]  # already close to the optimum
    _, report = optimize(graph, init="chordal")
    assert report.final_chi2 == pytest.approx(REFERENCE[name], rel=1e-3)
    assert report.iterations <= 10


def test_optimised_graph_written_and_read_back(posegraphs: Path, tmp_path: Path) -> None:
    graph = read_g2o(posegraphs / "sesync_CSAIL.g2o")
    assert not graph.vertices_given
    x, report = optimize(graph)
    out = tmp_path / "csail.g2o"
    write_g2o(out, graph, x)
    back = read_g2o(out)
    assert back.vertices_given
    assert chi2(back) == pytest.approx(report.final_chi2, rel=1e-12)
