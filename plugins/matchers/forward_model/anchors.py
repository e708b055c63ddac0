"""Joining a command late: where along its strokes the demonstration was first seen (K&G §4.4's forward models).

A segment often begins after its movement did (a hub threshold is crossed once the body has left the hub; a take is
cropped in motion). Each part is then predicted from the point of its stroke, in the stroke's first half, nearest to
where it was seen at the onset (the anchor), not from the stroke's start: the forward model's prediction is the point
of the stroke at the anchor plus the path length seen since (:meth:`Anchors.along`). A hand's fingers share one
clock (§4.2) and are followed from the start.

Every candidate of a subsystem is placed at once, when the first is asked for (:class:`Halves`: the candidates'
first halves in groups, the nearest points found by one argmin per group, or by a compiled loop where numba is
installed, :func:`place_rows`).
"""

from __future__ import annotations

import functools
from collections import OrderedDict
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from plugins.lib.compiled import compiled_now
from plugins.matchers.forward_model.tables import Tables

if TYPE_CHECKING:
    from plugins.matchers.forward_model.tracks import Track

__all__ = ["Anchors", "Halves", "place_rows"]


def place_rows(x: np.ndarray, y: np.ndarray, z: np.ndarray, arcs: np.ndarray, parts: np.ndarray, first: np.ndarray,
               rows: np.ndarray, out: np.ndarray) -> None:
    """One group of :class:`Halves` placed, stroke by stroke: ``out[rows[r]]`` is ``arcs[r, i]`` at the first ``i``
    where the distance from ``first[parts[r]]`` to the point (x, y, z)[r, i] is least (``np.argmin``'s rules: the
    first least, or the first NaN). Each distance is computed as :meth:`Halves.place` computes it (the squares summed
    x, y, z, then the root: the same bits). The root is taken only where the summed squares fall below the least so
    far (the root does not decrease, so nowhere else can it be less): a point whose root equals the least one's keeps
    the earlier index, as ``argmin`` does. Plain Python as written (the reference); :func:`_kernel` compiles it."""
    for r in range(x.shape[0]):
        p = parts[r]
        fx, fy, fz = first[p, 0], first[p, 1], first[p, 2]
        a = x[r, 0] - fx
        a = a * a
        b = y[r, 0] - fy
        a = a + b * b
        b = z[r, 0] - fz
        least_sum = a + b * b
        least = np.sqrt(least_sum)
        at = 0
        if least == least:  # a NaN first: argmin's answer
            for i in range(1, x.shape[1]):
                a = x[r, i] - fx
                a = a * a
                b = y[r, i] - fy
                a = a + b * b
                b = z[r, i] - fz
                a = a + b * b
                if a < least_sum:
                    d = np.sqrt(a)
                    if d < least:
                        least, at = d, i
                    least_sum = a
                elif a != a:  # the first NaN
                    at = i
                    break
        out[rows[r]] = arcs[r, at]


@functools.lru_cache(maxsize=1)
def _kernel() -> Any:
    """:func:`place_rows` compiled by numba (cached on disk; no ``fastmath``: no reordered sums, no fused
    multiply-adds), or ``None`` without numba (numpy's steps run then, with the same values). Compiled (or loaded)
    when a forward model is attached, not in its first demonstration."""
    one, row = np.zeros((1, 2)), np.zeros(1, dtype=np.int64)  # the types it is called with
    return compiled_now(place_rows, one, one, one, one, row, np.zeros((1, 3)), row, np.zeros(1))


class Halves:
    """The first halves of a set of commands' strokes, for :meth:`Anchors.anchor`: where along each stroke (path
    length) lies its first-half point nearest to where the part was seen.

    ``arcs`` (C, k, G) and ``positions`` (C, k, G, 3) are the strokes of C commands of k parts. A point lies in its
    stroke's first half while its path length is at most half the stroke's. A stroke that moves no part (every
    path length 0) is joined at 0 wherever the part is. The strokes that move are sorted by the length of their
    first halves and kept in :attr:`GROUPS` groups, each as contiguous coordinate planes x, y, z cut to its longest
    half, the points past a half given x = +inf (so their distance is +inf, as the plain computation's mask makes
    it; with a part never seen, NaN, both give the first point). :meth:`place` computes each distance as the plain
    ``np.linalg.norm`` of the stacked points does (the squares summed x, y, z, then the root: the same bits) and
    takes each stroke's first nearest point (``np.argmin``), so the anchors are those of the masked argmin over
    whole strokes, with about a third less arithmetic. With numba the same arithmetic runs stroke by stroke in a
    compiled loop (:func:`place_rows`), the root taken only where a point may be the nearest.
    ``tests/plugins/matchers/forward_model/test_anchors.py`` compares each way with the masked argmin."""

    GROUPS = 3

    __slots__ = ("shape", "groups")

    def __init__(self, arcs: np.ndarray, positions: np.ndarray) -> None:
        c, k, g = arcs.shape
        self.shape = (c, k)
        flat_arcs = arcs.reshape(c * k, g)
        later = flat_arcs > 0.5 * flat_arcs[:, -1:]
        halves = g - later.sum(axis=1)  # points in each first half (a prefix: the path lengths grow)
        moving = np.flatnonzero(flat_arcs[:, -1] > 0)
        order = moving[np.argsort(halves[moving], kind="stable")]
        flat = positions.reshape(c * k, g, 3)
        self.groups = []
        for rows in np.array_split(order, min(self.GROUPS, len(order))) if len(order) else []:
            h = int(halves[rows].max())
            x = np.where(later[rows, :h], np.inf, flat[rows, :h, 0])
            planes = tuple(np.ascontiguousarray(p) for p in (x, flat[rows, :h, 1], flat[rows, :h, 2]))
            self.groups.append((rows, rows % k, *planes, np.ascontiguousarray(flat_arcs[rows, :h])))

    def place(self, first: np.ndarray) -> np.ndarray:
        """The anchors (C, k): per command and part, the path length of the first-half point of its stroke nearest
        to ``first`` (k, 3), where the part was seen."""
        placed = np.zeros(self.shape[0] * self.shape[1])
        kernel = _kernel()
        if kernel is not None and first.dtype == np.float64:  # compiled, stroke by stroke (the same anchors)
            first = np.ascontiguousarray(first)
            for rows, parts, x, y, z, arcs in self.groups:
                kernel(x, y, z, arcs, parts, first, rows, placed)
            return placed.reshape(self.shape)
        for rows, parts, x, y, z, arcs in self.groups:
            f = first[parts]
            a = x - f[:, 0, None]
            a *= a
            b = y - f[:, 1, None]
            b *= b
            a += b
            np.subtract(z, f[:, 2, None], out=b)
            b *= b
            a += b
            np.sqrt(a, out=a)
            placed[rows] = arcs[np.arange(len(rows)), a.argmin(axis=1)]
        return placed.reshape(self.shape)


class Anchors:
    """Each track's anchors, placed when first asked for, and the first halves and placements of the last sets of
    candidates (a node's edges are the candidates of every demonstration that starts there; a replay of the same
    frames places them from the same posture).

    ``first(track)``: where the track's parts were seen at its onset (k, 3)."""

    def __init__(self, tables: Tables, first: Callable[[Track], np.ndarray]) -> None:
        self.tables = tables
        self.first = first
        self._halves: OrderedDict[tuple[str, ...], tuple[list, Halves]] = OrderedDict()
        self._placed: OrderedDict[tuple[tuple[str, ...], bytes], tuple[Halves, np.ndarray]] = OrderedDict()
        _kernel()  # compiled (or loaded from numba's cache) now, not in the first demonstration

    def along(self, track: Track, name: str, lengths: np.ndarray) -> np.ndarray:
        """How far along a path beginning with command ``name`` each part is: the observed path length plus
        where the demonstration joined the command (:meth:`anchor`)."""
        return lengths + self.anchor(track, name)

    def anchors(self, track: Track, names: tuple[str, ...]) -> np.ndarray:
        """:meth:`anchor` of each of commands ``names``, stacked (C, k): taken from the anchors placed when the track
        began (their rows, gathered: the same values) when all of them were placed then, else stacked one by one."""
        self.anchor(track, names[0])  # places the track's candidates, if not yet
        placed = track.placed
        if placed is not None:
            rows = [placed[0].get(name, -1) for name in names]
            if min(rows) >= 0:
                return placed[1][rows]
        return np.stack([self.anchor(track, n) for n in names])

    def anchor(self, track: Track, name: str) -> np.ndarray:
        """Where, along each part's stroke of command ``name`` (path length), the demonstration was first seen.

        A segment often begins a little after the movement did (a hub threshold is crossed once the body has
        left the hub; a stream starts in motion): each part is placed at the point of the first half of its
        stroke nearest to where it was seen at the track's onset, and predicted from there (0 when it was seen
        at the stroke's start). A hand's fingers share one clock: they are followed from the start (0).
        """
        anchor = track.anchors.get(name)
        if anchor is None:
            if track.hand:
                anchor = track.anchors[name] = np.zeros(len(self.tables.edge(name).arcs))
                return anchor
            # this command's and those of the track's other candidates still without one, at once (all are placed
            # in the frame the track begins: the same onset posture)
            firsts = dict.fromkeys([name, *(path[0] for path in track.candidates)])
            names = [n for n in firsts if n not in track.anchors]
            halves = self.halves(tuple(names))
            first = self.first(track)
            key = (tuple(names), first.tobytes())  # a replay of the same frames places them from the same posture
            kept = self._placed.get(key)
            if kept is not None and kept[0] is halves:
                self._placed.move_to_end(key)
                placed = kept[1]
            else:
                placed = halves.place(first)
                self._placed[key] = (halves, placed)
                if len(self._placed) > 32:
                    self._placed.popitem(last=False)
            track.anchors.update(zip(names, placed))
            if track.placed is None:
                track.placed = ({n: i for i, n in enumerate(names)}, placed)
            anchor = track.anchors[name]
        return anchor

    def halves(self, names: tuple[str, ...]) -> Halves:
        """The first halves of commands ``names``' strokes, stacked for :meth:`anchor` (:class:`Halves`). Kept for
        the last sets of candidates."""
        tables = [self.tables.edge(name) for name in names]
        kept = self._halves.get(names)
        if kept is not None and all(a is b for a, b in zip(kept[0], tables)):
            self._halves.move_to_end(names)
            return kept[1]
        halves = Halves(np.stack([t.arcs for t in tables]), np.stack([t.positions for t in tables]))
        self._halves[names] = (tables, halves)
        if len(self._halves) > 32:
            self._halves.popitem(last=False)
        return halves
