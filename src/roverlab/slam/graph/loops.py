"""The edges of the graph mapper's pose graph: Karto's ``MapperGraph`` links and loop closing.

:class:`LoopClosing`, a base class of :class:`~roverlab.slam.graph.slam.GraphSLAM`, adds an
edge (Karto keeps the first between two keyframes), links a new keyframe to its *near
chains* (``LinkNearChains``), finds the chains a loop may close with
(``FindPossibleLoopClosure``), matches them coarsely then finely (``TryCloseLoop``) and
optimises the graph, dropping the new closures if one ends up inconsistent. The keyframes,
the edge lists and the sequential matcher's grids are :class:`GraphSLAM`'s; see
:mod:`roverlab.slam.graph.slam` for the whole method.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order

from roverlab.slam.data.pose_solver import optimize
from roverlab.slam.data.posegraph import PoseGraph, edge_errors
from roverlab.slam.degeneracy import odometry_along
from roverlab.slam.graph.matcher import CorrelationGrid, MatchResult, build_grid, match_scan
from roverlab.slam.graph.params import GraphParams
from roverlab.slam.graph.poses import _information, _relative, _runs, _Scan

__all__ = ["LoopClosing"]

FloatArray = NDArray[np.float64]

#: Largest number of solver iterations after a loop closure (warm-started).
_OPT_ITERATIONS = 20


class LoopClosing:
    """Edges, near-chain links and loop closing of the keyframe graph; the subclass
    (:class:`~roverlab.slam.graph.slam.GraphSLAM`) provides the state below and the
    methods that raise :class:`NotImplementedError` here."""

    params: GraphParams
    _kf_pose: FloatArray
    _kf_scans: list[_Scan]
    _kf_weak: list[FloatArray | None]
    _e_from: list[int]
    _e_to: list[int]
    _e_meas: list[FloatArray]
    _e_info: list[FloatArray]
    _e_kind: list[str]
    _loop_block: int
    loop_closures: int
    rejected_loop_closures: int
    optimisations: int

    @property
    def num_keyframes(self) -> int:
        raise NotImplementedError

    def graph(self) -> PoseGraph:
        raise NotImplementedError

    def _seq_grid(
        self, frames: list[int], center: FloatArray, viewpoint: FloatArray
    ) -> CorrelationGrid:
        raise NotImplementedError

    def _world_points(self, frames: list[int], viewpoint: FloatArray) -> FloatArray:
        raise NotImplementedError

    def _match_sequential(
        self, grid: CorrelationGrid, pts: FloatArray, pred: FloatArray, *, penalise: bool, cov: bool
    ) -> MatchResult:
        raise NotImplementedError

    def _laser_position(self, k: int) -> FloatArray:
        raise NotImplementedError

    def _add_edge(self, i: int, j: int, mean_j: FloatArray, cov: FloatArray, kind: str) -> None:
        if i == j:
            return
        for e in range(len(self._e_from)):  # edges of j are few and at the end
            if self._e_to[-1 - e] != j:
                break
            if self._e_from[-1 - e] == i:
                return  # Karto keeps the first edge between two scans
        self._e_from.append(i)
        self._e_to.append(j)
        self._e_meas.append(_relative(self._kf_pose[i], mean_j))
        self._e_info.append(_information(cov, float(mean_j[2])))
        self._e_kind.append(kind)

    def _keep_odometry(
        self, weak: FloatArray | None, pose: FloatArray, pred: FloatArray, cov: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """A degenerate scan's match (``weak``: the robot-frame direction its scan cannot
        fix, None if it can) keeps ``pred``'s position along ``weak``, and its covariance
        grows by ``degenerate_variance`` along it."""
        if weak is None:
            return pose, cov
        fixed = odometry_along(pose, pred, weak)
        c, s = np.cos(fixed[2]), np.sin(fixed[2])
        w = np.array([c * weak[0] - s * weak[1], s * weak[0] + c * weak[1]])
        loose = np.array(cov, dtype=np.float64, copy=True)
        loose[:2, :2] += self.params.degenerate_variance * np.outer(w, w)
        return fixed, loose

    def _closest(self, frames: list[int] | NDArray[np.intp], pose: FloatArray) -> int:
        idx = np.asarray(frames, dtype=np.intp)
        d = np.hypot(self._kf_pose[idx, 0] - pose[0], self._kf_pose[idx, 1] - pose[1])
        return int(idx[int(np.argmin(d))])

    def _near_linked(self, k: int, distance: float) -> NDArray[np.bool_]:
        """Karto's ``FindNearLinkedScans``: keyframes reached from ``k`` through the graph,
        visiting only keyframes within ``distance`` of ``k``."""
        n = self.num_keyframes
        d = self._kf_pose[:, :2] - self._kf_pose[k, :2]
        within = np.einsum("ij,ij->i", d, d) < distance * distance + 1e-9
        out = np.zeros(n, dtype=bool)
        fr = np.asarray(self._e_from, dtype=np.intp)
        to = np.asarray(self._e_to, dtype=np.intp)
        ok = within[fr] & within[to]
        sub = np.flatnonzero(within)
        index = np.full(n, -1, dtype=np.intp)
        index[sub] = np.arange(sub.size)
        adj = coo_matrix(
            (np.ones(int(ok.sum())), (index[fr[ok]], index[to[ok]])), shape=(sub.size, sub.size)
        ).tocsr()
        reached = breadth_first_order(adj, int(index[k]), directed=False, return_predecessors=False)
        out[sub[np.asarray(reached, dtype=np.intp)]] = True
        return out

    def _chain_grid_match(
        self, k: int, chain: list[int], start: FloatArray, *, cov: bool
    ) -> MatchResult:
        grid = self._seq_grid(chain, start, self._laser_position(k))
        return self._match_sequential(
            grid, self._kf_scans[k].points, start, penalise=False, cov=cov
        )

    def _link_near_chains(self, k: int) -> list[tuple[FloatArray, FloatArray]]:
        """Karto's ``LinkNearChains``; returns the accepted matches (mean, covariance)."""
        p = self.params
        near = self._near_linked(k, p.link_scan_maximum_distance)
        d = self._kf_pose[:, :2] - self._kf_pose[k, :2]
        within = np.einsum("ij,ij->i", d, d) < p.link_scan_maximum_distance**2 + 1e-9
        within[k] = True
        out: list[tuple[FloatArray, FloatArray]] = []
        for a, b in _runs(within):
            if b > k:  # the chain holds the new keyframe itself: invalid
                continue
            if b - a < p.loop_match_minimum_chain_size or not near[a:b].any():
                continue
            chain = list(range(a, b))
            res = self._chain_grid_match(k, chain, self._kf_pose[k], cov=True)
            if res.response > p.link_match_minimum_response_fine - 1e-9:
                # a corridor scan matches its chain anywhere along the corridor
                mean, cov = self._keep_odometry(
                    self._kf_weak[k], res.pose, self._kf_pose[k], res.covariance
                )
                self._add_edge(self._closest(chain, mean), k, mean, cov, "near")
                out.append((mean, cov))
        return out

    def _loop_chains(self, k: int) -> list[list[int]]:
        """Karto's ``FindPossibleLoopClosure``, all chains at once."""
        p = self.params
        dist = p.loop_search_maximum_distance
        near = self._near_linked(k, dist)[:k]
        d = self._kf_pose[:k, :2] - self._kf_pose[k, :2]
        within = np.einsum("ij,ij->i", d, d) < dist * dist + 1e-9
        cand = within & ~near
        chains = []
        for a, b in _runs(cand):
            # a linked scan right after the run resets Karto's chain
            if b < k and near[b] and within[b]:
                continue
            if b - a >= p.loop_match_minimum_chain_size:
                chains.append(list(range(a, b)))
        return chains

    def _try_close_loop(self, k: int) -> None:
        """Karto's ``TryCloseLoop`` plus an optimisation and a consistency check; a
        degenerate scan (a bare corridor's) closes no loop: it would match anywhere along
        the corridor."""
        p = self.params
        if self._kf_weak[k] is not None:
            return
        added = 0
        backup = self._kf_pose.copy()
        n_edges = len(self._e_from)
        for chain in self._loop_chains(k):
            viewpoint = self._laser_position(k)
            coarse_grid = build_grid(
                self._world_points(chain, viewpoint),
                resolution=p.loop_search_space_resolution,
                smear_deviation=p.loop_search_space_smear_deviation,
                block=self._loop_block,
            )
            coarse = match_scan(
                coarse_grid,
                self._kf_scans[k].points,
                self._kf_pose[k],
                search_dimension=p.loop_search_space_dimension,
                coarse_angle_offset=p.coarse_search_angle_offset,
                coarse_angle_resolution=p.coarse_angle_resolution,
                fine_angle_offset=p.fine_search_angle_offset,
                penalty=None,
                refine_angle=False,
                subcell=False,
                covariance=True,
                response_expansion=False,
            )
            if not (
                coarse.response > p.loop_match_minimum_response_coarse
                and coarse.covariance[0, 0] < p.loop_match_maximum_variance_coarse
                and coarse.covariance[1, 1] < p.loop_match_maximum_variance_coarse
            ):
                continue
            fine = self._chain_grid_match(k, chain, coarse.pose, cov=True)
            if fine.response < p.loop_match_minimum_response_fine:
                continue
            self._kf_pose[k] = fine.pose
            self._add_edge(self._closest(chain, fine.pose), k, fine.pose, fine.covariance, "loop")
            added += 1
        if not added:
            return
        if self._optimise_checked(n_edges):
            self.loop_closures += added
        else:
            self.rejected_loop_closures += added
            del self._e_from[n_edges:], self._e_to[n_edges:], self._e_meas[n_edges:]
            del self._e_info[n_edges:], self._e_kind[n_edges:]
            self._kf_pose = backup

    def _optimise_checked(self, first_new: int) -> bool:
        """Optimise; False (poses untouched) if a closure edge ends up inconsistent."""
        graph = self.graph()
        poses, _ = optimize(graph, max_iterations=_OPT_ITERATIONS)
        self.optimisations += 1
        limit = self.params.loop_closure_max_residual
        if limit > 0.0:
            err = edge_errors(graph, poses)
            kinds = np.asarray(self._e_kind)
            check = kinds != "sequential"
            if np.any(np.hypot(err[check, 0], err[check, 1]) > limit):
                return False
        self._kf_pose = np.asarray(poses, dtype=np.float64).copy()
        return True
