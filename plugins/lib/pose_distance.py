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

__all__ = ["pose_distance", "path_distance"]


def pose_distance(a: np.ndarray, b: np.ndarray, visible: np.ndarray | None = None,
                  weights: np.ndarray | None = None) -> np.ndarray:
    """eq. 1: mean distance over visible parts; NaN where nothing is visible.

    Parameters
    ----------
    a, b : array, shape (..., P, 3)
        Root-relative poses (broadcast against each other).
    visible : array of bool, shape (..., P), optional
        Parts that take part in the comparison (broadcast likewise); ``None``: every part (the caller has taken
        the visible parts already, as path search does in its beam).
    weights : array, shape (..., P), optional
        How much each part counts (attention, :mod:`plugins.lib.attention`): a weighted mean over the visible
        parts. ``None``: every part alike, the paper's eq. 1.
    """
    diff = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    d = np.sqrt(np.einsum("...i,...i->...", diff, diff))  # eq. 2 per part
    if weights is not None:
        w = np.broadcast_to(np.asarray(weights, dtype=float), d.shape)
        if visible is not None:
            w = np.where(np.broadcast_to(np.asarray(visible, dtype=bool), d.shape), w, 0.0)
        total = w.sum(axis=-1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(total > 0, (d * w).sum(axis=-1) / np.where(total > 0, total, 1.0), np.nan)
    if visible is None:
        return d.mean(axis=-1)
    visible = np.broadcast_to(np.asarray(visible, dtype=bool), d.shape)
    d = np.where(visible, d, 0.0)
    n = visible.sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, d.sum(axis=-1) / np.maximum(n, 1), np.nan)


def path_distance(observed: np.ndarray, path: np.ndarray, visible: np.ndarray,
                  weights: np.ndarray | None = None) -> float:
    """eq. 3: the sum of eq. 1 over aligned poses ``observed[i]`` and ``path[i]`` (frames without evidence skipped).

    Parameters
    ----------
    observed, path : array, shape (N, P, 3)
        The observed samples and the poses of the graph path aligned with them.
    visible : array of bool, shape (N, P)
    """
    return float(np.nansum(pose_distance(observed, path, visible, weights)))
