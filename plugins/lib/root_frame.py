"""Root-relative body-part coordinates and the facing found from the nose and the knees.

Buchsbaum & Blumberg 2005, §5.1: the observer converts the world positions of
the target's visible parts to positions relative to the target's *root node*,
with the facing found from a forward marker (the nose, "always somewhat in front
of the body") against the line through the knees. Only visible parts are used.

:func:`root_relative` is the transform every perception and the clip repertoire use: the facing found from the
visible parts, smoothed over time (a running median while frames stream in, a centred one over a whole recording:
:class:`HeadingFilter`, :class:`RecordingFacing`), then root-relative coordinates. Over the same window the forward
marker's side is put to a vote (:func:`marker_behind`): a tracker's jitter moves a marker near the line across it
in a frame here and there, and a vote of the window's frames, not each frame on its own, turns the facing round.
All functions are vectorised over leading frame axes.

The line across the body is the paper's one pair (the knees; a profile's ``left`` and ``right``) or several pairs
(``[facing] left = ["left_hip", "left_shoulder"]``): :func:`across` combines their across vectors, each counting by
its own length, which weighs each pair's direction by the inverse of the variance a tracker's jitter gives it. Two
pairs turn less under jitter than one short pair: on the Bandai-Namco demos with 2 cm of jitter, the facing (over
the clip repertoire's one-second window) lies a median 2.1 degrees from the clean clip's with the hips alone (90th
percentile 5.3), 1.3 (3.2) with the hips and the shoulders. The origin stays the root node (§5.1).

The transform and the running median take quick paths in a watching loop (the rotation written out instead of an
einsum, the middle of each window read off its sorted estimates, no masking where nothing is hidden); each gives the
same bits as the formula it replaces (``tests/plugins/lib/test_root_frame_fast.py`` compares them byte for byte).
"""

from __future__ import annotations

import numpy as np

from typing import Protocol

from toolkit.body import Body
from toolkit.motion import world_to_local

__all__ = ["across", "facing_heading", "marker_behind", "to_root_relative", "root_relative", "FacingWindow", "HeadingFilter",
           "RecordingFacing", "smooth_heading"]

_UP = np.array([0.0, 1.0, 0.0])

MARKER_MARGIN = 0.25
"""How far behind the line through the facing parts (a share of their distance) the forward marker must lie to turn
the facing to the other side (:func:`facing_heading`). B&B §5.1's nose is "always somewhat in front of the body": a
mirrored recording puts it well behind; a marker the profile gives at the line (toes seen from toes) or a few
centimetres from it is within a tracker's jitter of both sides, and the body's left and right decide."""


def facing_heading(world: np.ndarray, visible: np.ndarray, body: Body, window: FacingWindow | None = None
                   ) -> np.ndarray:
    """Heading (radians about +y) of a body from its visible parts; NaN where it cannot be found.

    Parameters
    ----------
    world : array, shape (..., P, 3)
    visible : array of bool, shape (..., P)
    body : Body
    window : FacingWindow, optional
        The window the frames' flags (:func:`marker_behind`) are put to the vote of (:meth:`FacingWindow.votes`,
        once for these frames): the facing turns to the other side where more than half the window says the marker
        lies behind the line. ``None``: each frame's own marker decides (a window of one frame).

    Notes
    -----
    With both facing parts (knees) visible, the facing is the horizontal
    perpendicular of the line from right to left, on the side a body's left and
    right put its front; the forward marker (nose), when visible, turns it to the
    other side where it lies behind that line (as seen from the root, or from the
    middle of the knees when the root is hidden) by more than :data:`MARKER_MARGIN`
    of the knees' distance: a marker on the line, or one a tracker's jitter moves
    across it, does not flip the facing from frame to frame. With a knee hidden,
    the horizontal direction from the root to the forward marker is used.
    ``body.facing.behind``, when given, replaces the root as the point the
    forward marker is seen from (the toes seen from the ankle).
    """
    world = np.asarray(world, dtype=float)
    visible = np.asarray(visible, dtype=bool)
    perp, knees = _perpendicular(world, visible, body)  # +z when left is +x
    heading = np.full(world.shape[:-2], np.nan)
    if body.facing.forward is not None:
        fi, bi = body.index(body.facing.forward), _marker_base(body)
        if window is None:
            flip = _behind_line(world, visible, body, perp) & visible[..., fi]
        else:  # the frames' flags, from this perpendicular, put to the window's vote; NaN (no vote): not turned
            flip = window.votes(_flags(world, visible, body, perp, knees)) > 0.5
        perp = perp * np.where(flip, -1.0, 1.0)[..., None]
        fallback = world[..., fi, :] - world[..., bi, :]
        fallback[..., 1] = 0.0
        use_fb = ~knees & visible[..., fi] & visible[..., bi]
        perp = np.where(use_fb[..., None], fallback, perp)
        knees = knees | use_fb
    norm = np.linalg.norm(perp, axis=-1)
    ok = knees & (norm > 1e-9)
    heading[ok] = np.arctan2(perp[..., 0], perp[..., 2])[ok]
    return heading


def marker_behind(world: np.ndarray, visible: np.ndarray, body: Body) -> np.ndarray:
    """Whether the forward marker lies behind the line through the facing parts by more than
    :data:`MARKER_MARGIN` of their distance, frame by frame (...): 1.0 where it does, 0.0 where it does not, NaN where
    the marker or a facing part is not seen (or the body has no forward marker): the flags a window votes on
    (:meth:`FacingWindow.votes`; :func:`facing_heading` given a window)."""
    world = np.asarray(world, dtype=float)
    visible = np.asarray(visible, dtype=bool)
    if body.facing.forward is None:
        return np.full(world.shape[:-2], np.nan)
    return _flags(world, visible, body, *_perpendicular(world, visible, body))


def _perpendicular(world: np.ndarray, visible: np.ndarray, body: Body) -> tuple[np.ndarray, np.ndarray]:
    """The horizontal perpendicular of the line across the body from right to left (..., 3), as long as the facing
    parts are apart (:func:`across`), and where it was found (...)."""
    line, seen = across(world, visible, body)
    perp = _cross_up(line)
    perp[..., 1] = 0.0
    return perp, seen


def across(world: np.ndarray, visible: np.ndarray, body: Body) -> tuple[np.ndarray, np.ndarray]:
    """The line across the body, from its right to its left (..., 3), and where it was found (...): where at least
    one of the facing's left/right pairs is seen.

    One pair (the paper's knees): its left part minus its right part. Several (``body.facing.pairs``: the hips and
    the shoulders, say): each seen pair's horizontal across vector ``a_k`` counts by its own horizontal length,
    ``c = sum_k |a_k| a_k / sum_k |a_k|``.

    A tracker's jitter of ``s`` metres per coordinate turns a pair's direction by about ``sqrt(2) s / |a_k|``
    radians (variance ``2 s^2 / |a_k|^2``). The sum weighs each pair's direction by ``|a_k|^2``, the inverse of
    that variance, so the combined direction's variance is ``2 s^2 / sum_k |a_k|^2``: less than the longest pair's
    alone, and a short pair (the hips, 13 cm apart in the Bandai-Namco skeleton) counts for little beside a long one
    (the shoulders). A pair seen foreshortened (the shoulders of a body bent sideways) counts for less. ``c`` is as
    long as a length-weighted mean of the pairs' widths: the distance :data:`MARKER_MARGIN` is a share of.
    """
    pairs = body.facing.pairs
    if len(pairs) == 1:  # the paper's one pair: its difference as it is
        li, ri = body.index(body.facing.left), body.index(body.facing.right)
        return world[..., li, :] - world[..., ri, :], visible[..., li] & visible[..., ri]
    line = np.zeros(world.shape[:-2] + (3,))
    total = np.zeros(world.shape[:-2])
    seen = np.zeros(world.shape[:-2], dtype=bool)
    for left, right in pairs:  # a few pairs: each written out (an einsum over a pair axis costs more for a frame)
        li, ri = body.index(left), body.index(right)
        dx, dz = world[..., li, 0] - world[..., ri, 0], world[..., li, 2] - world[..., ri, 2]
        pair_seen = visible[..., li] & visible[..., ri]
        length = np.where(pair_seen, np.hypot(dx, dz), 0.0)
        line[..., 0] += length * dx
        line[..., 2] += length * dz
        total += length
        seen |= pair_seen
    line /= np.where(total > 0.0, total, 1.0)[..., None]
    return line, seen


def _middle(world: np.ndarray, visible: np.ndarray, body: Body) -> np.ndarray:
    """The middle of the facing parts (..., 3): of the one pair's, or the mean of the seen pairs' middles."""
    pairs = body.facing.pairs
    if len(pairs) == 1:
        return 0.5 * (world[..., body.index(body.facing.left), :] + world[..., body.index(body.facing.right), :])
    middle = np.zeros(world.shape[:-2] + (3,))
    count = np.zeros(world.shape[:-2])
    for left, right in pairs:
        li, ri = body.index(left), body.index(right)
        pair_seen = (visible[..., li] & visible[..., ri]).astype(float)
        middle += pair_seen[..., None] * 0.5 * (world[..., li, :] + world[..., ri, :])
        count += pair_seen
    return middle / np.where(count > 0, count, 1.0)[..., None]


def _flags(world: np.ndarray, visible: np.ndarray, body: Body, perp: np.ndarray, knees: np.ndarray) -> np.ndarray:
    """:func:`marker_behind` from the facing parts' perpendicular ``perp``, found where ``knees``."""
    seen = knees & visible[..., body.index(body.facing.forward)]
    return np.where(seen, _behind_line(world, visible, body, perp), np.nan)


def _marker_base(body: Body) -> int:
    """The part the forward marker is seen from when it is seen: its own behind part (toes from the ankle), else the
    root."""
    return body.root_index if body.facing.behind is None else body.index(body.facing.behind)


def _behind_line(world: np.ndarray, visible: np.ndarray, body: Body, perp: np.ndarray) -> np.ndarray:
    """Each frame's forward marker behind the facing parts' line by more than :data:`MARKER_MARGIN` of their
    distance (``perp``: the line's horizontal perpendicular, as long as the parts are apart; with several pairs, of
    the first pair's distance).

    The side of the line the marker is on is measured from the root when it is seen (a sitting body has its knees in
    front of its nose), else from the middle of the facing parts; from the marker's own behind part where the profile
    gives one and it is seen (toes from the ankle). Nearer the line than the margin the marker says nothing a
    tracker's jitter cannot flip."""
    root, fi = body.root_index, body.index(body.facing.forward)
    mid = _middle(world, visible, body)
    base = np.where(visible[..., root, None], world[..., root, :], mid)
    if body.facing.behind is not None:
        bi = body.index(body.facing.behind)
        base = np.where(visible[..., bi, None], world[..., bi, :], base)
    ahead = world[..., fi, :] - base
    if not body.facing.also:
        return np.einsum("...i,...i->...", ahead, perp) < -MARKER_MARGIN * np.einsum("...i,...i->...", perp, perp)
    # several pairs: the combined line's direction, the margin a share of the first pair's width where it is seen
    # (of the combined line's length where not), as with that pair alone: a pair added beside the paper's knees
    # turns the line, not how far behind it the marker must lie
    length = np.sqrt(np.einsum("...i,...i->...", perp, perp))
    li, ri = body.index(body.facing.left), body.index(body.facing.right)
    first = world[..., li, :] - world[..., ri, :]
    width = np.where(visible[..., li] & visible[..., ri], np.hypot(first[..., 0], first[..., 2]), length)
    return np.einsum("...i,...i->...", ahead, perp) < -MARKER_MARGIN * width * length


def _cross_up(across: np.ndarray) -> np.ndarray:
    """``np.cross(across, _UP)`` of float vectors (..., 3), the same bits without its axis handling (most of its cost
    for a frame or a few): numpy computes each component as the same products and difference,
    ``a1 * 0 - a2 * 1``, ``a2 * 0 - a0 * 0`` and ``a0 * 1 - a1 * 0``."""
    a0, a1, a2 = across[..., 0], across[..., 1], across[..., 2]
    out = np.empty(across.shape)
    np.subtract(a1 * _UP[2], a2 * _UP[1], out=out[..., 0])
    np.subtract(a2 * _UP[0], a0 * _UP[2], out=out[..., 1])
    np.subtract(a0 * _UP[1], a1 * _UP[0], out=out[..., 2])
    return out


def _circular_median(windows: np.ndarray, rotations: np.ndarray | None = None) -> np.ndarray:
    """The median of each row of angles (n, w), NaN ignored, unwrapped around the row's own circular mean.

    Unwrapping around one estimate (the newest, say) splits the others at ±π when that estimate is flipped by half
    a turn; around the mean of the row, the majority stays together and outvotes the flipped few. Rows with no
    finite angle give NaN.

    ``rotations``: ``np.exp(1j * windows)`` where finite and 0 elsewhere, when the caller has them (the rows of a
    sliding window share their estimates: :func:`_windowed_median` computes each estimate's once).
    """
    ok = np.isfinite(windows)
    if ok.all():  # every row full (a stream's rows after its first window): no masking, no row split
        if rotations is None:
            rotations = np.exp(1j * windows)
        ref = np.angle(rotations.sum(axis=1))[:, None]
        return np.angle(np.exp(1j * _unwrapped_median(windows, ref)))
    angles = np.where(ok, windows, 0.0)
    if rotations is None:
        rotations = np.where(ok, np.exp(1j * angles), 0.0)
    ref = np.angle(rotations.sum(axis=1))[:, None]
    out = np.full(len(windows), np.nan)
    full, some = ok.all(axis=1), ok.any(axis=1)
    if full.any():  # most rows: without nanmedian's cost, and unwrapping only the elements near the middle
        out[full] = _unwrapped_median(angles[full], ref[full])
    partial = some & ~full  # a stream's first frames, a clip's ends, frames without an estimate
    if partial.any():
        a, r, seen = angles[partial], ref[partial], ok[partial]
        found = _partial_median(np.where(seen, a, np.nan), r)  # the same values, unwrapping only the middle
        out[partial] = found if found is not None else np.nanmedian(np.where(seen, _unwrapped(a, r), np.nan), axis=1)
    return np.angle(np.exp(1j * out))


_CLOSE = 1e-9
"""A bound (rad) on how far :func:`_unwrapped_median`'s quick unwrapping lies from the exact one (which differs from
it by a few units in the last place, about 1e-15) away from the wrap; the wrap itself is within ``_WRAP``."""
_WRAP = 1e-6


def _unwrapped(angles: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``angles`` unwrapped around ``ref``: ``ref + np.angle(np.exp(1j * (angles - ref)))`` (element by element)."""
    return ref + np.angle(np.exp(1j * (angles - ref)))


def _unwrapped_median(angles: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``np.median(_unwrapped(angles, ref), axis=1)`` of rows of finite angles (n, w) and their refs (n, 1), the same
    values, with the exact unwrapping (a complex exponential and an angle) computed for a few elements per row only.

    The quick unwrapping ``ref + (d - 2π round(d / 2π))`` (``d = angles - ref``; the angles themselves when no ``d``
    reaches the wrap) lies within ``_CLOSE`` of the exact one wherever it is not within ``_WRAP`` of the wrap (those
    elements are unwrapped exactly at once). Order
    statistics move no more than the values do, so the exact middle values of a row lie within ``_CLOSE`` of the
    quick ones: every element whose quick value is more than twice that below (above) them is below (above) the
    middle, and the middle is found among the few left, unwrapped exactly and sorted.
    """
    n, w = angles.shape
    if not n:
        return np.zeros(0)
    ranks = [(w - 1) // 2, w // 2]  # the middle element, or the two middle ones (np.median: their mean)
    ordered = np.sort(angles, axis=1)
    if n == 1:  # one row (HeadingFilter.update, a frame at a time): the steps below on floats, without array calls
        found = _one_row_middle(ordered[0], float(ref[0, 0]), ranks)
        if found is not None:
            return found
    # the largest |angle - ref| of a row is at its smallest or largest angle (rounding keeps the order)
    spread = np.maximum(np.abs(ordered[:, -1:] - ref), np.abs(ordered[:, :1] - ref)).max()
    if not spread <= 64.0:  # angles of many turns: the quick unwrapping is not close enough
        return np.median(_unwrapped(angles, ref), axis=1)
    if spread < np.pi - _WRAP:  # no row wraps (most streams): the angles are their own quick unwrapping
        found = _sorted_middle(ordered, ref, np.full(n, ranks[0]), np.full(n, ranks[1]), np.full(n, w))
        if found is not None:
            return found
        quick, near = angles, np.zeros(angles.shape, dtype=bool)
        middle = ordered[:, ranks]
    else:
        d = angles - ref
        turns = np.round(d / (2 * np.pi))
        wrapped = d - 2 * np.pi * turns
        quick = ref + wrapped
        near = np.abs(np.abs(wrapped) - np.pi) < _WRAP
        if near.any():
            quick[near] = _unwrapped(angles[near], np.broadcast_to(ref, angles.shape)[near])
        middle = np.sort(quick, axis=1)[:, ranks]  # the same values as np.partition's at the ranks, sooner
    lo, hi = middle[:, :1] - 2 * _CLOSE, middle[:, 1:] + 2 * _CLOSE
    below = (quick < lo).sum(axis=1)  # certainly below the middle
    band = (quick >= lo) & (quick <= hi)
    rows, cols = np.nonzero(band)
    exact = quick[rows, cols]
    far = ~near[rows, cols]
    exact[far] = _unwrapped(angles[rows[far], cols[far]], ref[rows[far], 0])
    order = np.lexsort((exact, rows))  # by row, then by exact value
    exact = exact[order]
    first = np.concatenate([[0], np.cumsum(band.sum(axis=1))[:-1]])  # each row's first element in ``exact``
    a, b = exact[first + ranks[0] - below], exact[first + ranks[1] - below]
    return np.where(ranks[0] == ranks[1], a, (a + b) / 2)


def _sorted_middle(ordered: np.ndarray, ref: np.ndarray, low: np.ndarray, high: np.ndarray,
                   count: np.ndarray) -> np.ndarray | None:
    """The median of the exact unwrapping of rows that do not wrap (the angles are their own quick unwrapping, see
    :func:`_unwrapped_median`), read off the rows sorted: ``ordered`` (n, w), each row's ``count`` finite angles
    first (NaN sorts last), its middle at ranks ``low`` and ``high`` (equal for an odd count; else the mean of the
    two, as ``np.median`` and ``np.nanmedian`` take it).

    The elements below the band about the middle are a prefix of a sorted row and the band is the run after it,
    found from the middle outwards (the whole row is counted only where a neighbour of the middle lies in the band:
    ties). ``None`` where a band holds an exact zero: its sign could depend on the order of the elements, so the
    caller takes them in the row's own order, as before.
    """
    n = len(ordered)
    at = np.arange(n)
    first_middle, second_middle = ordered[at, low], ordered[at, high]
    lo, hi = first_middle - 2 * _CLOSE, second_middle + 2 * _CLOSE
    below = low.copy()  # elements < lo: the middle element is not, those before it are unless tied with it
    tied_below = np.flatnonzero(low > 0)
    tied_below = tied_below[ordered[tied_below, low[tied_below] - 1] >= lo[tied_below]]
    top = high + 1  # elements <= hi
    tied_above = np.flatnonzero(high + 1 < count)
    tied_above = tied_above[ordered[tied_above, high[tied_above] + 1] <= hi[tied_above]]
    if not (len(tied_below) or len(tied_above)):  # no ties (most rows): each band is the middle element or two
        a = _unwrapped(first_middle, ref[:, 0])
        b = _unwrapped(second_middle, ref[:, 0])
        if not (a.all() and b.all()):
            return None
        return np.where(low == high, a, (np.minimum(a, b) + np.maximum(a, b)) / 2)  # the two sorted, as below
    below[tied_below] = (ordered[tied_below] < lo[tied_below, None]).sum(axis=1)
    top[tied_above] = (ordered[tied_above] <= hi[tied_above, None]).sum(axis=1)
    counts = top - below
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])  # each row's first element in the band's list
    rows = np.repeat(at, counts)
    cols = below[rows] + np.arange(len(rows)) - first[rows]
    exact = _unwrapped(ordered[rows, cols], ref[rows, 0])
    if not exact.all():
        return None
    exact = exact[np.lexsort((exact, rows))]  # by row, then by exact value
    a, b = exact[first + low - below], exact[first + high - below]
    return np.where(low == high, a, (a + b) / 2)


def _one_row_middle(row: np.ndarray, ref: float, ranks: list[int]) -> np.ndarray | None:
    """:func:`_sorted_middle` of one sorted row of finite angles, the same numbers: the spread, the band and the
    mean of the two middle elements as Python floats (the same double arithmetic), the exact unwrapping by the same
    numpy functions. ``None`` where the row wraps, a neighbour of the middle is tied with it or a middle element
    unwraps to an exact zero (the caller's general path)."""
    low, high = ranks
    first, second = float(row[low]), float(row[high])
    if not max(abs(float(row[-1]) - ref), abs(float(row[0]) - ref)) < np.pi - _WRAP:
        return None
    lo, hi = first - 2 * _CLOSE, second + 2 * _CLOSE
    if (low > 0 and row[low - 1] >= lo) or (high + 1 < len(row) and row[high + 1] <= hi):
        return None
    a, b = (float(v) for v in _unwrapped(np.array([first, second]), ref))
    if a == 0.0 or b == 0.0:
        return None
    return np.array([a if low == high else (min(a, b) + max(a, b)) / 2])


def _partial_median(values: np.ndarray, ref: np.ndarray) -> np.ndarray | None:
    """``np.nanmedian`` (by row) of the exact unwrapping of ``values`` (n, w) around ``ref`` (n, 1) (NaN where a row has
    no angle, at least one finite angle a row), by :func:`_sorted_middle` (the same values) when no row wraps;
    ``None`` otherwise."""
    ordered = np.sort(values, axis=1)
    count = np.isfinite(values).sum(axis=1)
    last = ordered[np.arange(len(values)), count - 1]
    spread = np.maximum(np.abs(last - ref[:, 0]), np.abs(ordered[:, 0] - ref[:, 0])).max()
    if not spread < np.pi - _WRAP:
        return None
    high = count // 2
    return _sorted_middle(ordered, ref, np.where(count % 2 == 1, high, high - 1), high, count)


_WINDOW_BUDGET = 1 << 20
"""Numbers of windows gathered at a time by :func:`_windowed_median` (a window is as long as seconds x fps)."""


def _windowed_median(padded: np.ndarray, window: int, rows: np.ndarray) -> np.ndarray:
    """:func:`_circular_median` of the rows ``rows`` of the sliding windows of ``window`` estimates over ``padded``,
    a bounded number of rows at a time.

    Gathering every row at once would copy frames x window numbers (a whole recording times seconds x fps);
    each row's median depends only on that row, so the result is the same bit for bit. Each estimate's complex
    exponential is computed once, not once per window it falls in. The rows whose windows hold an estimate in every
    place (all but a stream's first ``window - 1`` frames, say) are taken apart from the others, so that most rows
    skip the masking that the others need.
    """
    finite = np.isfinite(padded)
    rotations = np.where(finite, np.exp(1j * np.where(finite, padded, 0.0)), 0.0)
    view = np.lib.stride_tricks.sliding_window_view(padded, window)  # views: nothing copied yet
    turned = np.lib.stride_tricks.sliding_window_view(rotations, window)
    step = max(1, _WINDOW_BUDGET // max(1, window))
    rows = np.asarray(rows)
    out = np.empty(len(rows))
    if finite.all():
        groups = [np.arange(len(rows))]
    else:  # rows with every estimate of their window take the quick path of _circular_median together
        seen = np.concatenate([[0], np.cumsum(finite)])
        full = seen[rows + window] - seen[rows] == window
        groups = [np.flatnonzero(full), np.flatnonzero(~full)]
    for group in groups:
        for i in range(0, len(group), step):
            at = group[i : i + step]
            out[at] = _circular_median(view[rows[at]], turned[rows[at]])
    return out


class HeadingFilter:
    """A running median of recent facing estimates, for a stream of frames.

    The facing found from the knees swings when one knee lifts (a kick, a stomp)
    and the nose swings when the head turns, while a body standing in place turns
    slowly. The median over the last ``window`` frames (circular: angles are
    unwrapped around their circular mean, :func:`_circular_median`) keeps the facing steady through such
    limb movements and still follows a real turn after half a window.
    A window of 1 returns each estimate unchanged.
    """

    def __init__(self, window: int) -> None:
        self.window = max(1, int(window))
        self._recent: list[float] = []
        self._flags: list[float] = []  # the forward marker's recent sides (:meth:`votes`)

    def reset(self) -> None:
        self._recent.clear()
        self._flags.clear()

    def headings(self, found: np.ndarray) -> np.ndarray:
        """:class:`FacingWindow`: the filtered facing after each estimate of ``found`` (a frame's, shape (), or a
        block's, (n,)), by :meth:`update` for one frame and :meth:`update_many` for more."""
        found = np.asarray(found, dtype=float)
        if found.ndim == 0:
            return np.asarray(self.update(float(found)))
        if len(found) == 1:
            return np.array([self.update(float(found[0]))])
        return self.update_many(found)

    def votes(self, flags: np.ndarray) -> np.ndarray:
        """:class:`FacingWindow`: after each frame's flag (:func:`marker_behind`; a frame's, shape (), or a
        block's), the flags of 1.0 among the last ``window`` flags there were (NaN ones skipped) over ``window``:
        a stream's first frames, with fewer flags, are not turned round before half a window says so (as the
        median follows a turn after half a window). NaN before the first flag."""
        flags = np.asarray(flags, dtype=float)
        block = flags.reshape(-1)
        if len(block) == 1:  # one frame (a world's step): the same numbers on floats (flags are 0 and 1: sums exact)
            flag = float(block[0])
            if np.isfinite(flag):
                self._flags.append(flag)
                if len(self._flags) > self.window:
                    del self._flags[0]
            return np.full(flags.shape, sum(self._flags) / self.window if self._flags else np.nan)
        given = block[np.isfinite(block)]
        history = np.concatenate([np.asarray(self._flags, dtype=float), given])
        ends = len(self._flags) + np.cumsum(np.isfinite(block))  # flags there were after each frame
        self._flags = history[-self.window :].tolist()
        sums = np.concatenate([[0.0], np.cumsum(history)])
        starts = np.maximum(ends - self.window, 0)
        out = np.where(ends > 0, (sums[ends] - sums[starts]) / self.window, np.nan)
        return out.reshape(flags.shape)

    def update(self, heading: float) -> float:
        """Add one estimate (NaN when there was none) and return the filtered facing (NaN if none yet).

        The same as :meth:`update_many` of one estimate, without its block machinery (a perception calls it every
        frame): the circular median of the last ``window`` estimates.
        """
        if np.isfinite(heading):
            self._recent.append(float(heading))
            if len(self._recent) > self.window:
                del self._recent[0]
        if not self._recent:
            return float("nan")
        return float(_circular_median(np.asarray(self._recent)[None])[0])

    def update_many(self, headings: np.ndarray) -> np.ndarray:
        """Add estimates (n,) one after another; the filtered facing after each, as :meth:`update` gives it.

        Each output is the circular median of the last ``window`` finite estimates up to its frame
        (:func:`_circular_median`); vectorised over the block.
        """
        h = np.asarray(headings, dtype=float)
        finite = np.isfinite(h)
        estimates = np.concatenate([np.asarray(self._recent, dtype=float), h[finite]])
        ends = len(self._recent) + np.cumsum(finite)  # estimates available after each frame
        self._recent = estimates[-self.window :].tolist()
        out = np.full(len(h), np.nan)
        have = ends > 0
        if not have.any():
            return out
        padded = np.concatenate([np.full(self.window - 1, np.nan), estimates])
        out[have] = _windowed_median(padded, self.window, ends[have] - 1)  # the last w estimates to each frame
        return out


def smooth_heading(heading: np.ndarray, window: int) -> np.ndarray:
    """A centred running circular median of headings (F,) over ``window`` frames, for whole recordings.

    The batch counterpart of :class:`HeadingFilter` (which, streaming, can only look back). Each window's estimates
    are unwrapped around that window's own circular mean before the median is taken, so a run of estimates that
    crosses ±π, or a few estimates flipped by half a turn, never pulls the median round (unwrapping the whole clip
    at once would let one flip carry every later frame with it). Near the clip's ends the window is cut short rather
    than slid inside the clip: a window that stops sliding turns the facing in one jump when it starts again (a
    kick, whose knees swing the estimate, turned half way through).
    NaN estimates are ignored; frames with no estimate in their window stay NaN.
    """
    heading = np.asarray(heading, dtype=float)
    n, half = len(heading), max(1, int(window)) // 2
    if n == 0 or window <= 1 or not np.isfinite(heading).any():
        return heading.copy()
    padded = np.pad(heading, half, constant_values=np.nan)  # near the ends the window shrinks: the facing stays
    return _windowed_median(padded, 2 * half + 1, np.arange(n))  # continuous from frame to frame


class FacingWindow(Protocol):
    """How a facing is found over a window of frames (:func:`root_relative`): :class:`HeadingFilter` while frames
    stream in (it can only look back), :class:`RecordingFacing` over a whole recording (centred)."""

    def votes(self, flags: np.ndarray) -> np.ndarray:
        """The share of the window's frames in which the forward marker lay behind the line (:func:`marker_behind`;
        NaN flags skipped, NaN where the window has none), frame by frame."""

    def headings(self, found: np.ndarray) -> np.ndarray:
        """The facing from the frames' estimates (:func:`facing_heading`) over the window, frame by frame."""


class RecordingFacing:
    """The facing of a whole recording (:class:`FacingWindow`): the centred running circular median of the estimates
    over ``window`` frames (:func:`smooth_heading`), the forward marker's side put to the vote of the same centred
    window (cut short near the ends, as the median's is): its flags of 1.0 over the window's length, so that the
    facing turns round where more than half a window's frames say so (all of a window cut short at the ends)."""

    def __init__(self, window: int) -> None:
        self.window = max(1, int(window))

    def votes(self, flags: np.ndarray) -> np.ndarray:
        flags = np.asarray(flags, dtype=float)
        n, half = len(flags), self.window // 2  # smooth_heading's window: 2 half + 1 frames
        given = np.isfinite(flags)
        sums = np.concatenate([[0.0], np.cumsum(np.where(given, flags, 0.0))])
        counts = np.concatenate([[0], np.cumsum(given)])
        frames = np.arange(n)
        lo, hi = np.maximum(frames - half, 0), np.minimum(frames + half + 1, n)
        return np.where(counts[hi] > counts[lo], (sums[hi] - sums[lo]) / (2 * half + 1), np.nan)

    def headings(self, found: np.ndarray) -> np.ndarray:
        return smooth_heading(found, self.window)


def to_root_relative(
    world: np.ndarray, visible: np.ndarray, body: Body, heading: np.ndarray | float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """World positions to root-relative positions in the body's own frame.

    ``heading`` replaces the facing found from the parts (a filtered value, say).

    Returns
    -------
    pose : array, shape (..., P, 3)
        Root-relative positions, rotated so the body faces +z; the joint angles of
        fingers (angle parts) unchanged, seen only when their wrist is.
    visible : array of bool, shape (..., P)
        The input mask, cleared where root or heading were not found.
    root : array, shape (..., 3)
        The root's world position.
    heading : array, shape (...)
    """
    world = np.asarray(world, dtype=float)
    visible = np.asarray(visible, dtype=bool) & _finite_points(world)
    safe_world = _zero_hidden(world, visible)
    if heading is None:
        heading = facing_heading(safe_world, visible, body)
    return _to_root_relative(world, visible, safe_world, body, np.asarray(heading, dtype=float))


def _finite_points(world: np.ndarray) -> np.ndarray:
    """``np.isfinite(world).all(axis=-1)`` of points (..., 3), sooner: a reduction over an axis of 3 is slow, so
    the whole array is checked first (most recordings are finite everywhere) and the coordinates are and-ed."""
    finite = np.isfinite(world)
    if world.shape[-1] != 3 or not world.size:
        return finite.all(axis=-1)
    if finite.all():
        return np.ones(world.shape[:-1], dtype=bool)
    return finite[..., 0] & finite[..., 1] & finite[..., 2]


def _zero_hidden(world: np.ndarray, visible: np.ndarray) -> np.ndarray:
    """``np.where(visible[..., None], world, 0.0)``: ``world`` itself (not copied; only read) when every part is
    seen."""
    return world if visible.all() else np.where(visible[..., None], world, 0.0)


def _to_local(points: np.ndarray, origin: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """``toolkit.motion.world_to_local(points, origin, heading)`` of frames (n, P, 3), origins (n, 3) and headings
    (n,), the same bits, without its einsum (which costs most of the transform).

    The einsum ``"fji,fpj->fpi"`` over the heading matrix ``[[c, 0, s], [0, 1, 0], [-s, 0, c]]`` sums the products
    from a zero, in the order of ``j``: ``((0 + c x) + 0 y) + (-s) z``, and so on. For finite coordinates and
    headings that is ``(c x - s z) + 0`` (the zero terms change no sum but a signed zero's sign, which the leading
    ``0 +``, like the trailing ``+ 0``, makes positive), ``y + 0`` and ``(s x + c z) + 0``; ``c`` and ``s`` are the
    same ``np.cos``/``np.sin`` of the same array of headings. Non-finite inputs (an overflowing difference too) go
    through ``world_to_local``.
    """
    d = points - origin.reshape(-1, 1, 3)
    if not (np.isfinite(d).all() and np.isfinite(heading).all()):
        return world_to_local(points, origin, heading)
    c, s = np.cos(heading)[:, None], np.sin(heading)[:, None]
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    out = np.empty_like(d)
    np.subtract(c * x, s * z, out=out[..., 0])
    np.add(y, 0.0, out=out[..., 1])
    np.add(s * x, c * z, out=out[..., 2])
    out[..., 0] += 0.0
    out[..., 2] += 0.0
    return out


def _to_root_relative(world: np.ndarray, visible: np.ndarray, safe_world: np.ndarray, body: Body,
                      heading: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`to_root_relative` once its inputs are checked: ``visible`` already false where ``world`` is not
    finite, ``safe_world`` is ``world`` with hidden parts at 0, ``heading`` a float array."""
    root = world[..., body.root_index, :]
    ok = visible[..., body.root_index] & np.isfinite(heading)
    safe_root = np.where(ok[..., None], root, 0.0)
    safe_heading = np.where(ok, heading, 0.0)
    if world.ndim == 2:
        pose = world_to_local(safe_world, safe_root, float(safe_heading))
    else:
        flat = safe_world.reshape(-1, *world.shape[-2:])
        pose = _to_local(flat, safe_root.reshape(-1, 3), safe_heading.reshape(-1)).reshape(world.shape)
    mask = visible & ok[..., None]
    angles = body.angle_mask
    if angles.any():  # finger joint angles are not positions: kept as they are, seen when their wrist is seen
        pose[..., angles, :] = world[..., angles, :]
        mask = mask & mask[..., body.carriers]
    if not mask.all():
        pose[~mask] = np.nan
    return pose, mask, np.where(ok[..., None], root, np.nan), heading


def root_relative(world: np.ndarray, visible: np.ndarray | None, body: Body, smooth: FacingWindow | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """§5.1 in one place: world positions of frames (n, P, 3) to root-relative positions in the body's own frame.

    The facing is found from the visible parts of each frame (:func:`facing_heading`) over the window ``smooth``
    (:class:`FacingWindow`): the forward marker's side put to the window's vote (:func:`marker_behind`), the
    estimates then smoothed; a :class:`HeadingFilter` while frames stream in, a :class:`RecordingFacing` over a
    whole recording, ``None`` for neither (each frame on its own). Non-finite coordinates are never visible.

    Returns what :func:`to_root_relative` returns: poses (n, P, 3) (NaN where hidden), visibility (n, P), the root's
    world position (n, 3) and the heading (n,).
    """
    world = np.asarray(world, dtype=float)
    seen = _finite_points(world)
    visible = seen if visible is None else seen & np.asarray(visible, dtype=bool)
    safe_world = _zero_hidden(world, visible)  # computed once: the facing and the transform share it
    found = facing_heading(safe_world, visible, body, smooth)
    heading = found if smooth is None else np.asarray(smooth.headings(found), dtype=float)
    return _to_root_relative(world, visible, safe_world, body, heading)
