"""Stroke analysis: where one movement's working memory is cut into guiding strokes (Kopp & Graeser 2006, §4.3).

"When the movement ends it is segmented in two ways": the working memory of one movement (positions of the chosen
parts, (N, 3k)) is cut

- at *speed* minima that fall below ``drop`` times the smaller of their neighbouring maxima (a minimum that stays
  high relative to its surroundings belongs to one curved stroke);
- where the *direction* of movement changes cluster: the normalised movement vectors are clustered divisively (one
  cluster; while some vector differs from its cluster's mean direction by more than ``angle`` degrees, it founds a
  new cluster and all vectors are redistributed to the nearest mean, until every cluster is tight); a break lies
  where two successive vectors fall into different clusters and the direction turns there by at least half of
  ``angle`` within a tenth of a second ("a significant change in movement direction compared to the overall
  curvature": a smooth C stroke crosses clusters gradually and is not cut), at a minimum of the speed below
  ``corner`` times its neighbouring maxima (an S stroke swings its direction at full speed and is not cut either).

Pieces shorter than ``min_stroke`` seconds are merged into their neighbour. These are pure functions: the
``velocity-direction`` segmenter cuts observed movements with them, the motor command graph cuts what it learns
into strokes with them before the inverse model turns each stroke into a command. A hand's fingers come in as
joint angles scaled to metres (``angle_scale``), so one rest speed and one direction clustering serve both.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from plugins.lib.compiled import compiled
from toolkit import Parameter

__all__ = ["STROKE_PARAMETERS", "StrokeCriteria", "StrokeAnalysis", "analyse", "breaks", "held", "speed_breaks", "direction_clusters",
           "direction_breaks"]


@dataclass(frozen=True)
class StrokeCriteria:
    """The criteria of the stroke analysis (the ``velocity-direction`` segmenter's parameters of the same names).

    ``rest_speed`` (m/s) below which the parts are at rest; ``drop`` and ``corner`` the shares of the neighbouring
    maxima a speed minimum must fall below to cut (by speed; to accompany a direction break); ``angle`` (degrees)
    between directions that makes a new cluster; ``min_stroke`` (s), the shortest stroke; ``smooth`` (s) of
    Savitzky-Golay smoothing of the working memory first (0: none).
    """

    rest_speed: float = 0.08
    drop: float = 0.5
    angle: float = 50.0
    corner: float = 0.9
    min_stroke: float = 0.15
    smooth: float = 0.2


STROKE_PARAMETERS = (
    Parameter("drop", float, StrokeCriteria.drop, "Speed-minimum criterion of the stroke segmentation.",
              minimum=0.0, maximum=1.0),
    Parameter("angle", float, StrokeCriteria.angle, "Direction criterion (degrees) of the stroke segmentation.",
              minimum=1.0, maximum=180.0),
)
"""The criteria a component cutting movements into strokes lets a user set, as its ``strokes`` table (the forward
model's learning by watching, the motor command graph's clips)."""


def speed_breaks(speed: np.ndarray, drop: float, moving: float = 0.0) -> list[int]:
    """Indices of speed minima below ``drop`` times the smaller of the highest speeds on either side.

    A minimum is no higher than the two samples on each side of it. A hold counts once, at its middle: a run
    of such samples, or minima with nothing faster than ``moving`` (the rest speed) between them (the ripples
    of a pause). A side reaches to the neighbouring minimum or to the end of the movement, so a movement that
    starts or ends at full speed still brackets its minima; both sides must rise above ``moving``, so a dip
    between two flickers of noise at rest separates no strokes.
    """
    minima, lowest, side = _minima(np.asarray(speed, dtype=float), moving)
    return minima[(lowest < drop * side) & (side > moving)].tolist()


def _minima(speed: np.ndarray, moving: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The holds of :func:`speed_breaks` (whatever the share): each hold's middle, its lowest speed and the smaller
    of its sides' highest speeds, as arrays (one element a hold). A minimum only compares speeds and takes maxima,
    so it is computed for every sample at once with the same values as sample by sample."""
    # Written out, not scipy.signal.find_peaks: K&G §4.3's criterion is a share of the neighbouring maxima (a ratio,
    # where find_peaks's prominence is a difference to the lower base of higher peaks) and a hold joins minima with
    # nothing faster than the rest speed between them, which no find_peaks option (plateau, distance, wlen) expresses.
    n = len(speed)
    none = np.zeros(0, dtype=int), np.zeros(0), np.zeros(0)
    if n < 5:
        return none
    # scipy.signal.argrelextrema(speed, np.less_equal, order=2), two samples on each side inside the movement
    middle = speed[2 : n - 2]
    low = np.flatnonzero((middle <= speed[1 : n - 3]) & (middle <= speed[: n - 4]) & (middle <= speed[3 : n - 1])
                         & (middle <= speed[4:])) + 2
    if not len(low):
        return none
    padded = np.append(speed, -np.inf)  # a range may end at the last sample
    # a minimum joins the hold before it when next to its last minimum or with nothing faster than `moving` between
    joined = np.zeros(0, dtype=bool)
    if len(low) > 1:
        between = np.maximum.reduceat(padded, np.stack([low[:-1], low[1:] + 1], axis=1).ravel())[::2]
        joined = (low[1:] == low[:-1] + 1) | (between <= moving)
    first = np.flatnonzero(np.concatenate([[True], ~joined]))  # the first minimum of each hold (index into low)
    last = np.append(first[1:] - 1, len(low) - 1)
    minima = (low[first] + low[last]) // 2
    left = np.append(0, low[last[:-1]])  # a side reaches to the neighbouring hold or to the end of the movement
    right = np.append(low[first[1:]], n - 1)
    highest = np.maximum.reduceat(padded, np.stack([left, low[first] + 1, low[last], right + 1], axis=1).ravel())
    lowest = np.minimum.reduceat(speed[low], first)
    return minima, lowest, np.minimum(highest[0::4], highest[2::4])


def direction_clusters(vectors: np.ndarray, angle: float, max_clusters: int = 12) -> np.ndarray:
    """Divisive clustering of unit movement vectors (N, D); returns a cluster label per vector.

    One cluster around the mean direction; while the vector least like its nearest mean is more than ``angle``
    degrees from it (and there are fewer than ``max_clusters``), it founds a new cluster and the vectors are
    redistributed to the nearest mean and the means re-averaged (:func:`_centres`) until they stay put (at most ten
    rounds). The means are one array (k, D); each similarity matrix ``vectors @ means.T`` is computed once for the
    means it belongs to, and a round whose labels are those of the round before ends the re-averaging at once (its
    means would be the same values, which the formula's test then finds close). The same labels as the formula
    written out cluster by cluster (``tests/plugins/lib/test_strokes_clusters.py`` holds it to that formula).

    With numba, each re-averaging round is two compiled calls (:func:`_relabel`, :func:`_renormed`) around the two
    products that stay numpy's (the similarity matrix and the means' dot products with themselves, BLAS's bits).
    """
    n = len(vectors)
    if n == 0:
        return np.zeros(0, dtype=int)
    kernels = _round_kernels() if vectors.dtype == np.float64 and vectors.ndim == 2 else None
    if kernels is not None:  # (what the analysis passes; other types keep numpy's own arithmetic)
        return _clusters_compiled(np.ascontiguousarray(vectors), angle, max_clusters, *kernels)
    cos_limit = np.cos(np.radians(angle))
    means = _unit(vectors.mean(axis=0))[None, :]
    sims = vectors @ means.T  # always the similarities to the current means
    rows = np.arange(n)
    for _ in range(4 * max_clusters):
        labels = sims.argmax(axis=1)
        best = sims[rows, labels]
        worst = int(best.argmin())
        if best[worst] >= cos_limit or len(means) >= max_clusters:
            break
        means = np.concatenate([means, vectors[worst][None, :]])  # a new cluster around the most different element
        labels = None
        for _ in range(10):  # redistribute and re-average until stable
            sims = vectors @ means.T
            again = sims.argmax(axis=1)
            if labels is not None and _and(again == labels, axis=None):
                break  # the same clusters: the same means again
            labels = again
            new = _centres(vectors, labels, means)
            if _allclose(new, means):
                break
            means = new
        else:
            sims = vectors @ means.T
    return sims.argmax(axis=1)


def _clusters_compiled(vectors: np.ndarray, angle: float, max_clusters: int, relabel, renormed) -> np.ndarray:
    """:func:`direction_clusters` with each re-averaging round's small steps compiled: the same steps in the same
    order (the similarity matrix and the dot products stay numpy's), so the same labels."""
    n, d = vectors.shape
    cos_limit = np.cos(np.radians(angle))
    means = _unit(vectors.mean(axis=0))[None, :]
    sims = vectors @ means.T
    rows = np.arange(n)
    labels = np.empty(n, dtype=np.intp)
    for _ in range(4 * max_clusters):
        best = sims[rows, sims.argmax(axis=1)]
        worst = int(best.argmin())
        if best[worst] >= cos_limit or len(means) >= max_clusters:
            break
        means = np.concatenate([means, vectors[worst][None, :]])
        k = len(means)
        centre, counts, new = np.empty((k, d)), np.empty(k, dtype=np.intp), np.empty((k, d))
        for first in (True, False, False, False, False, False, False, False, False, False):
            sims = vectors @ means.T
            if relabel(sims, labels, first, vectors, centre, counts):
                break  # the same clusters: the same means again
            if renormed(centre, np.sqrt(_dots(centre, centre)), counts, means, new):
                break
            means, new = new, means
        else:
            sims = vectors @ means.T
    return sims.argmax(axis=1)


def _relabel(sims: np.ndarray, labels: np.ndarray, first: bool, vectors: np.ndarray, centre: np.ndarray,
             counts: np.ndarray) -> bool:
    """One round's redistribution: each row's nearest mean (``sims.argmax(axis=1)``: the first highest, the first
    NaN if any) into ``labels``; true (and nothing else done) when not ``first`` and the labels are those already
    there. Otherwise each cluster's rows summed in their order from 0.0 into ``centre`` (k, D), as numpy's
    ``add.reduce`` starts from its identity (a column of -0.0 sums to 0.0: the sums of :func:`_centres`), their
    numbers into ``counts``, and each sum divided by its count (an empty cluster's by 1). Plain Python as written
    (the reference); :func:`_round_kernels` compiles it (no ``fastmath``: no reordered sums, no fused multiply-adds).
    """
    n, k = sims.shape
    same = not first
    for i in range(n):
        b = 0
        top = sims[i, 0]
        if top == top:
            for j in range(1, k):
                x = sims[i, j]
                if x != x:
                    b = j
                    break
                if x > top:
                    top = x
                    b = j
        if labels[i] != b:
            same = False
            labels[i] = b
    if same:
        return True
    d = vectors.shape[1]
    for c in range(k):
        counts[c] = 0
        for j in range(d):
            centre[c, j] = 0.0
    for i in range(n):
        c = labels[i]
        counts[c] += 1
        for j in range(d):
            centre[c, j] += vectors[i, j]
    for c in range(k):
        m = float(counts[c]) if counts[c] > 0 else 1.0
        for j in range(d):
            centre[c, j] /= m
    return False


def _renormed(centre: np.ndarray, norm: np.ndarray, counts: np.ndarray, means: np.ndarray, new: np.ndarray) -> bool:
    """The end of a round: ``new`` (k, D) the unit means of :func:`_centres` (``centre`` divided by its ``norm``
    where that exceeds 1e-12, as it is otherwise, the old mean for an empty cluster) and whether they are
    :func:`_allclose` to ``means``. Plain Python as written (the reference); compiled by :func:`_round_kernels`."""
    k, d = centre.shape
    close = True
    for c in range(k):
        for j in range(d):
            if counts[c] == 0:
                v = means[c, j]
            elif norm[c] > 1e-12:
                v = centre[c, j] / norm[c]
            else:
                v = centre[c, j]
            new[c, j] = v
            m = means[c, j]
            if not abs(v - m) <= 1e-08 + 1e-05 * abs(m):
                close = False
    return close


@functools.lru_cache(maxsize=1)
def _round_kernels():
    """:func:`_relabel` and :func:`_renormed` compiled by numba (cached on disk), or ``None`` without numba (the
    numpy steps of :func:`direction_clusters` run then, with the same labels). Compiled (or loaded) at the first
    call: the ``velocity-direction`` segmenter calls it when it is attached, not at the end of the first movement."""
    kernels = compiled(_relabel, _renormed)
    if kernels is None:
        return None
    relabel, renormed = kernels
    _clusters_compiled(np.eye(2), 10.0, 12, relabel, renormed)  # compiled for the types it is called with
    return relabel, renormed


def direction_breaks(labels: np.ndarray) -> list[int]:
    """Indices where two successive vectors fall into different clusters."""
    return [int(i) for i in np.flatnonzero(np.diff(labels) != 0) + 1]


@dataclass(frozen=True)
class StrokeAnalysis:
    """How one movement's working memory was cut into strokes (indices are frames into the movement).

    ``window``: the (smoothed) positions (N, 3k); ``speed``: the speed of the fastest chosen part between
    successive frames (N - 1,); ``clusters``: the direction cluster of each movement vector (-1: none, at rest);
    ``speed_breaks`` and ``direction_breaks``: the candidates each criterion found; ``breaks``: the ones kept.
    """

    window: np.ndarray
    speed: np.ndarray
    clusters: np.ndarray
    speed_breaks: list[int]
    direction_breaks: list[int]
    breaks: list[int]


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.sqrt(v.dot(v))  # np.linalg.norm(v) of a vector, without its generality's cost
    return v / n if n > 1e-12 else v


def _cluster_means(vectors: np.ndarray, labels: np.ndarray, means: list[np.ndarray]) -> list[np.ndarray]:
    """Each cluster's mean direction, ``_unit(vectors[labels == k].mean(axis=0))``, or its old one ``means[k]`` if
    it has no vector: the same values (each cluster's rows summed in their order, divided by their count, and
    divided by the square root of the mean's dot product with itself, as ``mean`` and ``np.linalg.norm`` do), from
    one sort of the labels instead of a mask per cluster."""
    order = np.argsort(labels, kind="stable")
    grouped = vectors[order]
    bounds = np.searchsorted(labels[order], np.arange(len(means) + 1)).tolist()
    new = []
    for k, mean in enumerate(means):
        a, b = bounds[k], bounds[k + 1]
        if a == b:
            new.append(mean)
            continue
        centre = np.add.reduce(grouped[a:b], axis=0) / (b - a)
        norm = np.sqrt(centre.dot(centre))
        new.append(centre / norm if norm > 1e-12 else centre)
    return new


def _centres(vectors: np.ndarray, labels: np.ndarray, means: np.ndarray) -> np.ndarray:
    """Each cluster's mean direction (k, D) as one array: the values of :func:`_cluster_means` (a cluster's rows
    summed in their order, divided by their count, divided by the square root of the mean's dot product with itself;
    its old mean ``means[k]`` if it has no vector).

    The rows are laid out per cluster in a (longest, k, D) array padded with -0.0, which leaves any sum as it is
    (x + -0.0 is x, for x = +0.0 too), and summed along its first axis at once: numpy adds the (k, D) layers one
    after the other, as it sums one cluster's rows one after the other.
    """
    k, d = means.shape
    run = (labels[:, None] == np.arange(k)).cumsum(axis=0)  # rows of each cluster so far
    counts = run[-1]
    padded = np.empty((int(counts.max()), k, d))
    padded.fill(-0.0)
    padded[run[np.arange(len(labels)), labels] - 1, labels] = vectors
    centre = np.add.reduce(padded, axis=0)
    full = bool(_and(counts, axis=None))
    centre /= counts[:, None] if full else np.maximum(counts, 1)[:, None]
    norm = np.sqrt(_dots(centre, centre))
    long = norm > 1e-12
    if full and _and(long, axis=None):
        return centre / norm[:, None]
    centre = np.where(long[:, None], centre / np.where(long, norm, 1.0)[:, None], centre)
    return centre if full else np.where((counts > 0)[:, None], centre, means)


def _units(vectors: np.ndarray) -> np.ndarray:
    """:func:`_unit` of each row of ``vectors`` (N, D), the same values: ``np.linalg.norm`` of a vector is the
    square root of its dot product with itself, taken here row by row, and the rows divided at once."""
    if not len(vectors):
        return np.array([_unit(v) for v in vectors])
    n = np.sqrt(_dots(vectors, vectors))
    long = n > 1e-12
    return np.where(long[:, None], vectors / np.where(long, n, 1.0)[:, None], vectors)


def _dots(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``[u.dot(v) for u, v in zip(a, b)]`` of two (N, D) arrays as one array: a stack of (1, D) @ (D, 1) products,
    which numpy's matmul hands to the same BLAS dot product a vector's ``dot`` calls (``np.linalg.norm`` of a vector
    too), so the same bits (``tests/plugins/lib/test_strokes_clusters.py``); not ``einsum``, which sums in another
    order."""
    return np.matmul(a[:, None, :], b[:, :, None])[:, 0, 0]


_and = np.logical_and.reduce  # _and(x, axis=None) is x.all(), without ndarray.all's Python wrapper


def _allclose(a: np.ndarray, b: np.ndarray) -> bool:
    """``np.allclose(a, b)`` of finite or NaN values (its default tolerances), without its generality's cost."""
    return bool(_and(abs(a - b) <= 1e-08 + 1e-05 * abs(b), axis=None))


def _smoothed(window: np.ndarray, length: int) -> np.ndarray:
    """``scipy.signal.savgol_filter(window, length, 2, axis=0, mode="interp")`` of a finite window (N, D), N > length:
    the same steps with what depends on ``length`` and D only computed once (:func:`_savgol_plan`): the filter's
    coefficients convolved over the window, and at each end a quadratic fitted to the ``length`` end rows (the
    scaled Vandermonde matrix, LAPACK's gelsd with the workspace scipy.linalg.lstsq asks for) and evaluated by
    Horner's rule. ``tests/plugins/lib/test_strokes_clusters.py`` holds it to savgol_filter bit for bit."""
    from scipy.ndimage import convolve1d

    coeffs, lhs, scale, gelsd, lwork, iwork, rcond, at = _savgol_plan(length, window.shape[1])
    n, half = len(window), length // 2
    y = convolve1d(window, coeffs, axis=0, mode="constant")
    for start, rows in ((0, slice(0, half)), (n - length, slice(n - half, n))):
        fit, _, _, info = gelsd(lhs, window[start : start + length], lwork, iwork, rcond, False, False)
        if info != 0:  # as scipy.linalg.lstsq would say
            from scipy.signal import savgol_filter

            return savgol_filter(window, length, 2, axis=0, mode="interp")
        p = (fit[:3].T / scale).T
        values = np.zeros_like(at[start > 0])
        for j in range(3):
            values = values * at[start > 0] + p[j, ...]
        y[rows] = values / 1.0
    return y


@functools.lru_cache(maxsize=16)
def _savgol_plan(length: int, width: int) -> tuple:
    """What :func:`_smoothed` needs for windows ``length`` long of ``width`` columns, as savgol_filter computes it."""
    from scipy.linalg import get_lapack_funcs
    from scipy.signal import savgol_coeffs

    coeffs = savgol_coeffs(length, 2)
    x = np.arange(0, length, dtype=np.float64)
    rcond = length * np.finfo(np.float64).eps
    powers = np.flip(np.arange(3, dtype=np.float64))
    lhs = x[:, None] ** powers[None, :]
    scale = np.sqrt(np.sum(lhs * lhs, axis=0))
    lhs /= scale
    gelsd, gelsd_lwork = get_lapack_funcs(("gelsd", "gelsd_lwork"), (lhs, np.zeros((length, width))))
    work, iwork, info = gelsd_lwork(length, 3, width, rcond)
    half = length // 2
    at = (np.arange(0, half, dtype=np.float64).reshape(-1, 1),  # the rows each end's fit gives, from its first
          np.arange(length - half, length, dtype=np.float64).reshape(-1, 1))
    for a in (coeffs, lhs, scale, *at):
        a.flags.writeable = False
    return coeffs, lhs, scale, gelsd, int(work.real), int(iwork.real), rcond, at


def held(window: np.ndarray) -> np.ndarray:
    """``window`` (N, D) with its non-finite values (a part hidden and not held, or not seen yet) as not visible:
    each column holds its last finite value, takes its first finite value before that (a part not seen yet does not
    move) and is 0 where it has none (a part never seen in the movement). The window itself (the same values) when
    every value is finite.

    Hidden parts do not move (``docs/conventions.md``): filled so, they add no speed and no direction to the
    analysis, and the smoothing filter (which refuses NaN) sees only numbers.
    """
    window = np.asarray(window, dtype=float)
    finite = np.isfinite(window)
    if finite.all():
        return window
    n = len(window)
    rows = np.where(finite, np.arange(n)[:, None], -1)
    last = np.maximum.accumulate(rows, axis=0)  # the last finite row of each column so far (-1: none yet)
    first = np.where(finite.any(axis=0), np.argmax(finite, axis=0), 0)  # the first finite row of each column
    source = np.where(last >= 0, last, first[None, :])
    filled = np.take_along_axis(window, source, axis=0)
    filled[:, ~finite.any(axis=0)] = 0.0
    return filled


def breaks(window: np.ndarray, fps: float, criteria: StrokeCriteria = StrokeCriteria()) -> list[int]:
    """Break points (indices into ``window``, positions (N, 3k) of the chosen parts) by speed and direction.

    ``analyse(window, fps, criteria).breaks``, without what cannot change them: no analysis of a movement too short
    for two strokes, and no direction clustering where no speed dip could accompany a direction break.
    """
    return _analyse(window, fps, criteria, clusters=False).breaks


def analyse(window: np.ndarray, fps: float, criteria: StrokeCriteria = StrokeCriteria()) -> StrokeAnalysis:
    """The working memory of one movement (positions (N, 3k) of the chosen parts, sampled at ``fps``) analysed for
    break points.

    Speed minima below ``drop`` of their neighbouring maxima cut; direction-cluster changes cut where the
    direction turns sharply at a dip of the speed (see the module). Pieces shorter than ``min_stroke`` merge.
    """
    return _analyse(window, fps, criteria)


def _analyse(window: np.ndarray, fps: float, c: StrokeCriteria, clusters: bool = True) -> StrokeAnalysis:
    """:func:`analyse`; with ``clusters`` false only its ``breaks`` are meant (:func:`breaks`): a movement too short
    for two strokes is not analysed, and the direction clusters are left out (-1) where there is no speed dip."""

    window = held(window)
    n = len(window)
    empty = np.zeros(max(0, n - 1))
    shortest = max(1, int(round(c.min_stroke * fps)))
    if n < 4 or (not clusters and n < 2 * shortest):  # no piece could be kept on both sides of a break
        return StrokeAnalysis(np.asarray(window, dtype=float), empty, np.full(len(empty), -1), [], [], [])
    smooth = int(round(c.smooth * fps)) | 1
    if smooth >= 5 and n > smooth:
        window = _smoothed(window, smooth)
    vectors = np.diff(window, axis=0)
    speed = np.linalg.norm(vectors.reshape(len(vectors), -1, 3), axis=2).max(axis=1) * fps
    moving = speed > c.rest_speed
    minima, lowest, side = _minima(speed, c.rest_speed)
    by_speed = sorted((minima[(lowest < c.drop * side) & (side > c.rest_speed)] + 1).tolist())
    cuts = set(by_speed)
    by_direction: list[int] = []
    labels = np.full(len(vectors), -1)
    k = max(2, int(round(0.1 * fps)))
    dips = minima[(lowest < c.corner * side) & (side > c.rest_speed)] + 1
    if moving.any() and (clusters or dips.size):
        labels[moving] = direction_clusters(_units(vectors[moving]), c.angle)
        # slow vectors take the cluster of the one before (none before the first moving one: -1)
        last = np.maximum.accumulate(np.where(moving, np.arange(len(labels)), -1))
        labels = np.where(last >= 0, labels[np.maximum(last, 0)], -1)
        changes = np.flatnonzero(labels[1:] != labels[:-1]) + 1  # direction_breaks(labels)
        if changes.size and dips.size:
            # a cluster change inside one stroke is no break: the direction must turn sharply there, at a dip
            # of the speed (a C stroke turns gradually, an S stroke swings its direction at full speed)
            distance = np.abs(dips[None, :] - changes[:, None])
            near = (distance <= k).any(axis=1)
            changes, distance = changes[near], distance[near]
            if changes.size:
                # the k vectors before and after each change (-0.0 beyond the movement: no term), summed one after
                # the other, made unit and compared as each change's own would be
                rows = changes[:, None] + np.arange(-k, k)
                rows = np.where((rows >= 0) & (rows < len(vectors)), rows, len(vectors))
                sums = np.append(vectors, np.full((1, vectors.shape[1]), -0.0), axis=0)[rows]
                before, after = _units(sums[:, :k].sum(axis=1)), _units(sums[:, k:].sum(axis=1))
                cos = _dots(before, after)
                sharp = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))) >= 0.5 * c.angle
                nearest = np.where(distance <= k, distance, k + 1).argmin(axis=1)
                by_direction.extend(dips[nearest[sharp]].tolist())
    cuts.update(by_direction)
    kept: list[int] = []
    for cut in sorted(cuts):
        if cut - (kept[-1] if kept else 0) >= shortest and n - cut >= shortest:
            kept.append(cut)
    return StrokeAnalysis(window, speed, labels, by_speed, sorted(set(by_direction)), kept)
