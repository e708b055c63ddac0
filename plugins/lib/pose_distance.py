"""The pose distance of Buchsbaum & Blumberg 2005, §5.1 eq. 1-2 and §5.2 eq. 3.

eq. 2: ``d(a, b)`` is the Euclidean distance between two 3-vectors.
eq. 1: ``dist(A, B)`` is the mean of ``d(A_i, B_i)`` over the N body parts
*currently visible*; hidden parts are left out, which is why it is a mean.
eq. 3: the distance of an observed path O from a graph path P is the sum of
eq. 1 over the poses considered so far.

All functions broadcast: poses are ``(..., P, 3)`` with masks ``(..., P)``.
A pose pair with no visible part has distance NaN (there is no evidence).
"""

from __future__ import annotations

import numpy as np

__all__ = ["PoseScan", "pose_distance", "path_distance"]


def pose_distance(a: np.ndarray, b: np.ndarray, visible: np.ndarray | None = None) -> np.ndarray:
    """eq. 1: mean distance over visible parts; NaN where nothing is visible.

    Parameters
    ----------
    a, b : array, shape (..., P, 3)
        Root-relative poses (broadcast against each other).
    visible : array of bool, shape (..., P), optional
        Parts that take part in the comparison (broadcast likewise); ``None``: every part (the caller has taken
        the visible parts already, as path search does in its beam).
    """
    diff = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    d = np.sqrt(np.einsum("...i,...i->...", diff, diff))  # eq. 2 per part
    if visible is None:
        return d.mean(axis=-1)
    visible = np.broadcast_to(np.asarray(visible, dtype=bool), d.shape)
    d = np.where(visible, d, 0.0)
    n = visible.sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, d.sum(axis=-1) / np.maximum(n, 1), np.nan)


def path_distance(observed: np.ndarray, path: np.ndarray, visible: np.ndarray) -> float:
    """eq. 3: the sum of eq. 1 over aligned poses ``observed[i]`` and ``path[i]`` (frames without evidence skipped).

    Parameters
    ----------
    observed, path : array, shape (N, P, 3)
        The observed samples and the poses of the graph path aligned with them.
    visible : array of bool, shape (N, P)
    """
    return float(np.nansum(pose_distance(observed, path, visible)))


class PoseScan:
    """eq. 1 over every part from one query pose to each of many fixed poses: path search's scan of the whole
    posegraph (§5.2 step 2), the same numbers as ``np.sqrt(np.einsum("cpi,cpi->cp", d, d)).mean(axis=1)`` with
    ``d = poses - query``, in about half the time.

    The poses are kept as three coordinate planes (N, P), so each step is one pass of a ufunc over contiguous memory
    into buffers kept between queries. NumPy's einsum sums the three squares of a part as ``(x² + z²) + y²`` (its
    vector loop puts x, y, z and a zero in lanes and adds the halves); the planes are summed in that order, and the
    mean over the parts is the same ``mean(axis=1)`` of a C-ordered (N, P) array. A few poses (``rows``) are taken
    with their three coordinates together and summed in the same order (einsum, which loops over every part with
    three numbers, is slowest there: 20 us for 110 poses, 0.5 ms for 1,000). Whether einsum sums so is checked
    when the scan is built, on up to :data:`SCAN_CHECK` of the poses (another NumPy or machine could sum otherwise):
    if any number differs the scan calls einsum itself (:attr:`planes` is False).

    Parameters
    ----------
    poses : array, shape (N, P, 3)
        The poses (not changed; the planes are a copy).
    """

    def __init__(self, poses: np.ndarray):
        poses = np.asarray(poses, dtype=float)
        self.poses = poses
        self._x, self._y, self._z = (np.ascontiguousarray(poses[..., i]) for i in range(3))
        self._buffers = np.empty((2, *poses.shape[:2]))
        self.finite = bool(np.isfinite(poses).all())
        self._scale = float(np.abs(poses).max(initial=0.0)) if self.finite else np.inf
        self._single = None  # the planes in single precision and their buffers, made by the first approximate()
        self.planes = True
        if len(poses):  # the check: a query that is none of the poses (their mean, moved), on the first poses
            few = poses[:SCAN_CHECK]
            query = poses.mean(axis=0) + np.linspace(0.01, 0.02, poses.shape[1])[:, None]
            if not np.isfinite(query).all():
                query = np.zeros(poses.shape[1:])
            planes = PoseScan.__new__(PoseScan)
            planes.poses, planes.planes = few, True
            planes._x, planes._y, planes._z = self._x[:SCAN_CHECK], self._y[:SCAN_CHECK], self._z[:SCAN_CHECK]
            planes._buffers = np.empty((2, *few.shape[:2]))
            d = few - query
            einsum = np.sqrt(np.einsum("cpi,cpi->cp", d, d)).mean(axis=1)
            rows = np.arange(len(few))
            self.planes = bool(np.array_equal(planes(query), einsum, equal_nan=True)
                               and np.array_equal(planes(query, rows), einsum, equal_nan=True))

    def __call__(self, query: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """eq. 1 over every part from ``query`` (P, 3) to each pose, (N,); with ``rows`` (indices), to those poses
        only, (len(rows),) (path search's beam: the candidates of one step)."""
        query = np.asarray(query, dtype=float)
        if rows is not None:
            d = self.poses.take(rows, axis=0)
            np.subtract(d, query, out=d)
            if not self.planes:
                return np.sqrt(np.einsum("cpi,cpi->cp", d, d)).mean(axis=1)
            np.multiply(d, d, out=d)
            s = np.add(d[..., 0], d[..., 2])
            np.add(s, d[..., 1], out=s)
            np.sqrt(s, out=s)
            return _mean(s)
        if not self.planes:
            d = self.poses - query
            return np.sqrt(np.einsum("cpi,cpi->cp", d, d)).mean(axis=1)
        s, b = self._buffers
        np.subtract(self._x, query[:, 0], out=s)
        np.multiply(s, s, out=s)
        np.subtract(self._z, query[:, 2], out=b)
        np.multiply(b, b, out=b)
        np.add(s, b, out=s)
        np.subtract(self._y, query[:, 1], out=b)
        np.multiply(b, b, out=b)
        np.add(s, b, out=s)
        np.sqrt(s, out=s)
        return _mean(s)

    def approximate(self, query: np.ndarray) -> tuple[np.ndarray, float] | None:
        """eq. 1 over every part from ``query`` (P, 3) to each pose computed in single precision, (N,), and a bound
        of its error: every pose's exact distance (:meth:`__call__`) lies within the bound of its approximation.
        ``None`` when a pose or the query has a coordinate that is not finite (no bound holds).

        The bound: with u = 2**-24 and M the largest magnitude of a coordinate of the poses plus that of the query,
        each coordinate rounded to single precision and the difference rounded are within 3uM of the exact
        difference, each part's norm (a length of at most 2·3**0.5·M: the squares, two sums and a square root)
        within 15uM of the exact norm, and the sum of the P norms (any order) within (P - 1)u times their total, so
        the sum is within uM(15P + 3.5P²) of the exact sum; the mean (times 1/P, both rounded) within uM(22 + 3.5P).
        Twice uM(22 + 4P), plus 1e-9 of the largest distance (the exact distance's own rounding), is returned: the
        caller compares an approximation against another plus twice the bound. The single-precision planes are laid
        out (3, P, N), so each ufunc's inner loop runs over the poses, and are made by the first call."""
        query = np.asarray(query, dtype=float)
        if not self.finite or not np.isfinite(query).all() or not self.poses.shape[1]:
            return None
        if self._single is None:  # the coordinates as (3, P, N) planes: each ufunc's inner loop runs over the N poses
            single = np.ascontiguousarray(self.poses.transpose(2, 1, 0), dtype=np.float32)
            self._single = (single, np.empty_like(single),
                            np.full(self.poses.shape[1], 1.0 / self.poses.shape[1], dtype=np.float32))
        single, d, share = self._single
        np.subtract(single, query.T.astype(np.float32)[:, :, None], out=d)
        np.multiply(d, d, out=d)
        s = np.add(d[0], d[1], out=d[0])
        np.add(s, d[2], out=s)
        np.sqrt(s, out=s)
        mean = (share @ s).astype(float)  # the sum of the norms over P, any order (the bound allows it)
        parts = self.poses.shape[1]
        top = self._scale + float(np.abs(query).max())
        return mean, 2.0 * 2.0**-24 * top * (22 + 4 * parts) + 1e-9 * float(mean.max(initial=0.0))


def _mean(s: np.ndarray) -> np.ndarray:
    """``s.mean(axis=1)`` of a 2-D float array as NumPy computes it (``np.add.reduce`` over the axis, then a true
    division by the count), without its set-up."""
    out = np.add.reduce(s, axis=1)
    out /= s.shape[1]
    return out


SCAN_CHECK = 256
"""Poses on which :class:`PoseScan` checks, when built, that its arithmetic gives einsum's numbers."""
