"""A spatial index for the k poses nearest to one pose by eq. 1 (Buchsbaum & Blumberg 2005, §5.2 step 2).

Path search starts from the k poses of the whole posegraph nearest to the observed middle frame (§5.2): a scan of
every node is linear in the graph (about 290 ms at 1,000,000 poses of 11 parts). :class:`PoseIndex` answers the
same question from a k-d tree (``scipy.spatial.cKDTree``) and gives *exactly* the scan's answer, ties included.

Bound and verify. Eq. 1 is the mean over the P visible parts of each part's Euclidean distance, which no tree
metric is. The tree holds each node's visible parts as one vector of 3P coordinates and measures the Manhattan
(L1) distance ``L`` between vectors. Per part, ``|x|_1 / sqrt(3) <= |x|_2 <= |x|_1``, so summed over the parts

    L / (P sqrt(3))  <=  eq. 1  <=  L / P,

a lower bound within a factor sqrt(3) of eq. 1 whatever P (the Euclidean norm of the whole vector would give
``D / P <= eq. 1 <= D / sqrt(P)``, a factor sqrt(P) = 3.3 at 11 parts, and so many more candidates to verify).
The tree returns candidates in growing batches by ``L``; each batch is verified with
:func:`plugins.lib.pose_distance.pose_distance` (the scan's arithmetic, the same numbers), and the search stops
once the lower bound of the last candidate returned exceeds the k-th best verified eq. 1 distance: every node not
returned is then farther than the k-th, so the k best (and every node tied with the k-th) are among those verified.
The answer is ordered by (eq. 1 distance, node index): the order of the scan's stable ``argsort``.

Hidden parts: one tree per visibility pattern (which parts are visible), built on the first query with that
pattern and cached; most observed frames see every part, so the one tree of all parts serves nearly every query.
At most :data:`MAX_TREES` trees are kept (the least recently used goes), since each holds a copy of the poses'
visible coordinates. Poses with a coordinate that is not finite cannot be put in a tree: :meth:`PoseIndex.nearest`
then scans (as it does when ``k`` reaches the number of poses).
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
from scipy.spatial import cKDTree

from plugins.lib.pose_distance import pose_distance

__all__ = ["MAX_TREES", "PoseIndex", "nearest_by_scan"]

MAX_TREES = 4
"""Most visibility patterns whose tree is kept at once (each a copy of the poses' visible coordinates)."""

FIRST_BATCH = 64
"""Candidates asked of the tree in the first batch (at least 4 k); each further batch is four times larger."""

LEAF_SIZE = 64
"""Poses per leaf of a tree (``cKDTree``'s ``leafsize``)."""

_SLACK = 1e-9
"""Relative margin on the lower bound, so floating-point rounding in the tree's L1 sum never stops a search early."""


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
        self._trees: OrderedDict[bytes, cKDTree] = OrderedDict()

    def __len__(self) -> int:
        return len(self.poses)

    def tree(self, visible: np.ndarray) -> cKDTree:
        """The tree of the poses' ``visible`` parts (built on first use, cached)."""
        key = np.packbits(visible).tobytes()
        tree = self._trees.get(key)
        if tree is None:
            data = np.ascontiguousarray(self.poses[:, visible].reshape(len(self.poses), -1))
            # the faster build (no median split, no shrunk boxes): queries measured as fast
            tree = cKDTree(data, leafsize=LEAF_SIZE, balanced_tree=False, compact_nodes=False)
            self._trees[key] = tree
            while len(self._trees) > MAX_TREES:
                self._trees.popitem(last=False)
        else:
            self._trees.move_to_end(key)
        return tree

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
        if k >= n or seen == 0 or not self.finite or not np.isfinite(query[visible]).all():
            return nearest_by_scan(self.poses, query, visible, k)
        tree = self.tree(visible)
        point = query[visible].reshape(-1)
        factor = 1.0 / (seen * np.sqrt(3.0)) * (1.0 - _SLACK)
        batch = max(FIRST_BATCH, 4 * k)
        while True:
            if batch >= n:  # the tree would return every pose: the scan is simpler and as exact
                return nearest_by_scan(self.poses, query, visible, k)
            l1, idx = tree.query(point, k=batch, p=1)
            d = pose_distance(self.poses[idx], query, visible)  # verify: eq. 1 as the scan computes it
            kth = np.partition(d, k - 1)[k - 1]
            if l1[-1] * factor > kth:  # every pose not returned is farther than the k-th: the k best are here
                order = np.lexsort((idx, d))[:k]
                return idx[order], d[order]
            batch *= 4
