"""A spatial index for the k poses nearest to one pose by eq. 1 (Buchsbaum & Blumberg 2005, §5.2 step 2).

Path search starts from the k poses of the whole posegraph nearest to the observed middle frame (§5.2): a scan of
every node is linear in the graph (about 200-290 ms at 1,000,000 poses of 11 parts). :class:`PoseIndex` answers the
same question from a k-d tree (``scipy.spatial.cKDTree``) and gives *exactly* the scan's answer, ties included.

Features that eq. 1 bounds. Eq. 1 is the mean over the S visible parts of each part's Euclidean distance, which no
tree metric is, and a tree over the 3S coordinates themselves searches slowly: poses vary in every coordinate
(noise, performers), and a k-d tree in 33 dimensions visits a great many leaves. The index describes each pose by
M = :data:`FEATURES` numbers instead, each a mean over the visible parts of the part's position along one unit
direction of that part::

    f_j(x) = (1 / S) sum_i u_ji . x_i,   |u_ji| = 1 (or 0),

so that, by Cauchy-Schwarz part by part, ``|f_j(a) - f_j(b)| <= (1 / S) sum_i |a_i - b_i| = eq. 1(a, b)``: the
Chebyshev (L-infinity) distance between two poses' features is a lower bound of their eq. 1 distance. The
directions are the first principal axes of the poses' visible coordinates (an SVD of about :data:`SAMPLE` of the
poses), each part's share of an axis scaled to unit length: the features follow what varies between the poses (the
movement, its phase, the performer), while noise, independent from coordinate to coordinate, is averaged away.

Search: (1) the :data:`FIRST_BATCH` poses nearest by features are measured by eq. 1; the k-th smallest, ``U``, is an
upper bound of the k-th nearest pose's distance (k real poses are that near); (2) every pose whose features lie
within ``U`` of the query's (the tree's ``query_ball_point``, Chebyshev) is a candidate, and every pose outside is
farther than ``U`` by the bound, so the k best and every pose tied with the k-th are among the candidates; (3) the
candidates are measured (a quick eq. 1 in single precision over the tree's copy of the coordinates, kept in the
tree's order so that one query's candidates lie in few stretches of memory, with a bound of its rounding: see
:meth:`FeatureTree.sums`), and the few within that bound of the k-th are measured again
with :func:`plugins.lib.pose_distance.pose_distance` on the rows of the poses, the scan's arithmetic: the same
numbers. The answer is ordered by (eq. 1 distance, node index), the order of the scan's stable ``argsort``. Every
bound has a relative margin of :data:`_SLACK`, so rounding never drops a pose.

Hidden parts: one tree per visibility pattern (which parts are visible), built on the first query with that
pattern and cached; most observed frames see every part, so the one tree of all parts serves nearly every query.
At most :data:`MAX_TREES` trees are kept (the least recently used goes), since each holds a copy of the poses'
visible coordinates. Poses with a coordinate that is not finite cannot be put in a tree: :meth:`PoseIndex.nearest`
then scans, as it does when ``k`` reaches the number of poses, and when a query far from every pose leaves more
than :data:`MAX_SHARE` of the poses as candidates (a search that cannot gain on the scan).
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from plugins.lib.pose_distance import pose_distance

__all__ = ["FEATURES", "MAX_TREES", "PoseIndex", "nearest_by_scan"]

MAX_TREES = 4
"""Most visibility patterns whose tree is kept at once."""

FEATURES = 8
"""Features per pose (at most three per visible part): the tree's dimension."""

FIRST_BATCH = 32
"""Poses nearest by features measured by eq. 1 for the first upper bound (at least k)."""

LEAF_SIZE = 128
"""Poses per leaf of a tree (``cKDTree``'s ``leafsize``)."""

SAMPLE = 20_000
"""About this many poses (every ``n // SAMPLE``-th) give the principal axes."""

MAX_SHARE = 0.25
"""Share of the poses beyond which the candidates are not measured one by one: the scan is as fast and simpler."""

_SLACK = 1e-9
"""Relative margin on every bound, so floating-point rounding never drops a pose."""


def nearest_by_scan(poses: np.ndarray, query: np.ndarray, visible: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """The exhaustive scan: the ``k`` poses nearest to ``query`` by eq. 1 over the ``visible`` parts.

    Returns
    -------
    indices, distances : array (min(k, N),)
        Ordered by distance, ties by index (a stable sort), as path search orders its start poses.
    """
    d = pose_distance(poses, query, visible)
    order = np.argsort(d, kind="stable")[:k]
    return order, d[order]


@dataclass
class FeatureTree:
    """The tree of one visibility pattern: the features' directions, the tree of every pose's features, and the
    poses' visible coordinates in the tree's order (the candidates of one query lie in few stretches of memory)."""

    weights: np.ndarray
    """(M, 3S) over the S visible parts' coordinates: ``features = coordinates @ weights.T``."""
    tree: cKDTree
    """The poses' features (N, M), in the order of :attr:`order`: the tree answers positions in that order."""
    order: np.ndarray
    """(N,) the node index of each position."""
    coordinates: np.ndarray
    """(N, 3S) the poses' visible coordinates in single precision (half the memory read per query), in the order of
    :attr:`order`."""
    margin: float
    """Absolute margin on a feature distance (rounding in the features' sums)."""
    scale: float
    """The largest magnitude of a coordinate (the rounding of :meth:`sums` is bounded by it)."""

    @classmethod
    def build(cls, coordinates: np.ndarray, parts: int) -> "FeatureTree":
        """The tree of poses given by their visible ``coordinates`` (N, 3S) of ``parts`` = S parts."""
        weights = directions(coordinates, parts, min(FEATURES, 3 * parts))
        features = coordinates @ weights.T
        # shrunk boxes (compact_nodes) and large leaves: the fastest searches measured; no median split (a slower
        # build, searched no faster)
        options = {"leafsize": LEAF_SIZE, "balanced_tree": False, "compact_nodes": True}
        order = cKDTree(features, **options).indices  # the tree's order of the poses, then the tree in that order
        tree = cKDTree(features[order], **options)
        scale = float(np.abs(coordinates).max(initial=0.0))
        return cls(weights, tree, order, coordinates[order].astype(np.float32), _SLACK * (1.0 + scale), scale)

    def sums(self, positions: np.ndarray, point: np.ndarray) -> tuple[np.ndarray, float]:
        """The sum over the visible parts of each part's distance from the poses at ``positions`` to ``point``
        (3S,), eq. 1 times S, computed in single precision; and a bound of its error.

        The error: each coordinate and the point rounded to single precision (relative 2**-24 = u), their difference
        rounded, each part's norm (squares, two sums, a square root) and the sum of the S norms each within a few u,
        so with R the largest magnitude of a coordinate of the poses or the point the error is at most
        ``u (R + |point|) (16 S + 4 S**2)``; twice that is returned."""
        d = self.coordinates.take(positions, axis=0)
        d -= point.astype(np.float32)
        d *= d
        d = d.reshape(len(positions), -1, 3)
        squares = d[:, :, 0] + d[:, :, 1]
        squares += d[:, :, 2]
        parts = squares.shape[1]
        error = 2.0 * 2.0**-24 * (self.scale + float(np.abs(point).max(initial=0.0))) * (16 * parts + 4 * parts**2)
        return np.sqrt(squares, out=squares).sum(axis=1, dtype=np.float64), error


def directions(coordinates: np.ndarray, parts: int, m: int) -> np.ndarray:
    """The weights of ``m`` features of poses given as their visible ``coordinates`` (N, 3S) of ``parts`` = S parts:
    the principal axes of (a sample of) the coordinates, each part's share of an axis scaled to unit length (a part
    an axis does not move keeps zero), divided by S. (M, 3S)."""
    sample = coordinates[:: max(1, len(coordinates) // SAMPLE)]
    _, _, axes = np.linalg.svd(sample - sample.mean(axis=0), full_matrices=False)
    axes = axes[:m].reshape(-1, parts, 3)
    norms = np.linalg.norm(axes, axis=2, keepdims=True)
    unit = np.divide(axes, norms, out=np.zeros_like(axes), where=norms > 0)
    return unit.reshape(len(unit), -1) / parts


class PoseIndex:
    """The k nearest poses by eq. 1, the same as :func:`nearest_by_scan`, from one k-d tree per visibility pattern.

    Parameters
    ----------
    poses : array, shape (N, P, 3)
        Root-relative poses (path search: ``nodes_compared``). Not copied: the caller must not change them while the
        index is in use (path search builds a new index when its posegraph learns).
    """

    def __init__(self, poses: np.ndarray):
        self.poses = np.asarray(poses, dtype=float)
        if self.poses.ndim != 3 or self.poses.shape[2] != 3:
            raise ValueError(f"PoseIndex needs poses shaped (N, P, 3), not {self.poses.shape}")
        self.finite = bool(np.isfinite(self.poses).all())
        self._trees: OrderedDict[bytes, FeatureTree] = OrderedDict()
        self.scanned = 0
        """Queries answered by the scan (see the module's notes)."""

    def __len__(self) -> int:
        return len(self.poses)

    def tree(self, visible: np.ndarray) -> FeatureTree:
        """The feature tree of the poses' ``visible`` parts (built on first use, cached)."""
        visible = np.asarray(visible, dtype=bool)
        key = np.packbits(visible).tobytes()
        found = self._trees.get(key)
        if found is None:
            found = FeatureTree.build(self.poses[:, visible].reshape(len(self.poses), -1), int(visible.sum()))
            self._trees[key] = found
            while len(self._trees) > MAX_TREES:
                self._trees.popitem(last=False)
        else:
            self._trees.move_to_end(key)
        return found

    def nearest(self, query: np.ndarray, visible: np.ndarray | None, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The ``k`` poses nearest to ``query`` (P, 3) by eq. 1 over the ``visible`` parts (P,) (``None``: all).

        Returns
        -------
        indices, distances : array (min(k, N),)
            Exactly :func:`nearest_by_scan`'s: ordered by eq. 1 distance, ties by node index.
        """
        n, parts = self.poses.shape[:2]
        visible = np.ones(parts, dtype=bool) if visible is None else np.asarray(visible, dtype=bool)
        seen = int(visible.sum())
        query = np.asarray(query, dtype=float)
        first = max(FIRST_BATCH, k)
        if first >= n or seen == 0 or not self.finite or not np.isfinite(query[visible]).all():
            self.scanned += 1
            return nearest_by_scan(self.poses, query, visible, k)
        index = self.tree(visible)
        point = query[visible].reshape(-1)
        at = point @ index.weights.T
        # (1) an upper bound of the k-th distance: the k-th nearest of the first poses by features
        at_first = np.atleast_1d(index.tree.query(at, k=first, p=np.inf)[1])
        sums, error = index.sums(at_first, point)
        bound = (np.partition(sums, k - 1)[k - 1] + error) * (1.0 + _SLACK) / seen
        # (2) every pose whose features are within the bound: the rest are farther than the k-th
        found = np.asarray(index.tree.query_ball_point(at, bound * (1.0 + _SLACK) + index.margin, p=np.inf),
                           dtype=np.intp)
        if len(found) > MAX_SHARE * n:
            self.scanned += 1
            return nearest_by_scan(self.poses, query, visible, k)
        found.sort()  # in memory order
        # (3) measure the candidates; those within a hair of the k-th again, with the scan's arithmetic
        sums, error = index.sums(found, point)
        ids = index.order[found[sums <= (np.partition(sums, k - 1)[k - 1] + 2 * error) * (1.0 + 4 * _SLACK)]]
        d = pose_distance(self.poses[ids], query, visible)
        order = np.lexsort((ids, d))[:k]
        return ids[order], d[order]
