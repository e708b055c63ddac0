"""The commands as the forward model reads them: every stroke on a fine grid of its own time (K&G §4.2, §4.4).

An edge's command is one stroke per part of its subsystem (a guiding stroke of a wrist, a hand's transition of
each finger; :mod:`plugins.lib.guiding_stroke`, :mod:`plugins.lib.hand_transition`). Each stroke is tabled once on
a fine grid (:attr:`Tables.GRID` points, uniform in its time): positions and cumulative path lengths, so that the
point of a stroke at a path length (the forward model's prediction at the length of the movement seen so far,
§4.4) and the time at which it is reached are interpolations in the table. :class:`StrokeRows` keeps every stroke
met as rows of one growing table, so a set of candidates is a list of row numbers and is predicted at once
(:meth:`StrokeRows.along`, a compiled loop where numba is installed: :func:`along_table`).
"""

from __future__ import annotations

import functools
from collections import OrderedDict
from dataclasses import dataclass
from typing import Any

import numpy as np

from plugins.lib.compiled import compiled_now
from plugins.matchers.forward_model.path_length import arc

__all__ = ["EdgeTable", "StrokeRows", "Tables", "along_table", "row_keys"]


@dataclass(frozen=True)
class EdgeTable:
    """A command's strokes, one per part, on a fine grid: positions (k, G, 3), cumulative path lengths (k, G), and
    the lead part (the one that moves farthest)."""

    commands: list
    positions: np.ndarray
    arcs: np.ndarray
    lead: int


def row_keys(arcs: np.ndarray, first: int = 0) -> np.ndarray | None:
    """``arcs`` (R, G) as one sorted complex array for :meth:`StrokeRows.along`: row r's values are ``first + r + 1j *
    arcs[r]``, and numpy orders complex numbers lexicographically (real part, then imaginary), so one
    ``searchsorted`` counts, for every row at once, the points of its own row at most a given length (the same
    count as comparing every point: exact comparisons of the same numbers). ``None`` when a row does not grow (NaN,
    or a decrease): then the count is taken by comparing every point."""
    if not arcs.size or not bool((arcs[:, 1:] >= arcs[:, :-1]).all()):
        return None
    keys = np.empty(arcs.shape, dtype=complex)
    keys.real = np.arange(first, first + len(arcs))[:, None]
    keys.imag = arcs
    return keys.ravel()


def along_table(arcs: np.ndarray, positions: np.ndarray, rows: np.ndarray, x: np.ndarray, ordered: bool,
                out: np.ndarray) -> None:
    """:meth:`StrokeRows.along` row by row: ``out[i]`` (3,) is the point of stroke ``rows[i]`` (``arcs`` (R, G),
    ``positions`` (R, G, 3)) at path length ``x[i]``, with numpy's steps and rules: the points at most ``x[i]`` counted
    (by a binary search when every row's lengths grow, ``ordered``; a NaN length is at most none), the segment
    before them (clipped to the stroke), the weight ``(x - a0) / step`` (0 where the step is not positive) clipped to
    [0, 1] as ``np.clip`` clips (NaN and -0 kept), then ``p0 + w * (p1 - p0)``. Plain Python as written (the
    reference); :func:`_kernel` compiles it."""
    g = arcs.shape[1]
    for i in range(rows.shape[0]):
        r, v = rows[i], x[i]
        count = 0
        if ordered:
            if v == v:
                lo, hi = 0, g  # the first point longer than v
                while lo < hi:
                    mid = (lo + hi) // 2
                    if arcs[r, mid] > v:
                        hi = mid
                    else:
                        lo = mid + 1
                count = lo
        else:
            for j in range(g):
                if arcs[r, j] <= v:
                    count += 1
        j = min(max(count - 1, 0), g - 2)
        a0 = arcs[r, j]
        step = arcs[r, j + 1] - a0
        w = (v - a0) / step if step > 0 else 0.0
        if w == w:  # np.clip: max, then min, NaN kept (and -0 too: numpy keeps w where w == 0)
            w = w if w >= 0.0 else 0.0
            w = w if w <= 1.0 else 1.0
        for c in range(3):
            p0 = positions[r, j, c]
            out[i, c] = p0 + w * (positions[r, j + 1, c] - p0)


@functools.lru_cache(maxsize=1)
def _kernel() -> Any:
    """:func:`along_table` compiled by numba (cached on disk; no ``fastmath``: no reordered sums, no fused
    multiply-adds), or ``None`` without numba (numpy's steps run then, with the same values). Compiled (or loaded)
    when a forward model is attached, not in its first demonstration."""
    one, row = np.zeros((1, 2)), np.zeros(1, dtype=np.int64)  # the types it is called with
    return compiled_now(along_table, one, np.zeros((1, 2, 3)), row, np.zeros(1), True, np.empty((1, 3)))


class StrokeRows:
    """Every command's strokes the forward model has met, one row per part, in one growing table: cumulative path
    lengths (R, G), positions (R, G, 3) and the lengths' search keys (:func:`row_keys`, row numbers as real parts,
    so the table's keys stay sorted as commands are added). A set of candidates is then a list of row numbers, and
    predicting them all (:meth:`along`) gathers only the two points about each one's path length, without copying
    their strokes. A command whose table changes gets new rows (:meth:`rows`)."""

    __slots__ = ("arcs", "positions", "keys", "n", "sorted", "of")

    def __init__(self, points: int) -> None:
        self.arcs = np.empty((64, points))
        self.positions = np.empty((64, points, 3))
        self.keys = np.empty(64 * points, dtype=complex)
        self.n = 0
        self.sorted = True  # every row's lengths grow: the keys can be searched
        self.of: dict[str, tuple[Any, int]] = {}  # command -> (its table, its first row)

    def rows(self, name: str, table: EdgeTable) -> int:
        """The first row of command ``name``'s strokes (``table``), added when new or changed."""
        kept = self.of.get(name)
        if kept is not None and kept[0] is table:
            return kept[1]
        k, g = table.arcs.shape
        first, end = self.n, self.n + k
        if end > len(self.arcs):
            size = max(end, 2 * len(self.arcs))
            for attr in ("arcs", "positions"):
                old = getattr(self, attr)
                new = np.empty((size, *old.shape[1:]))
                new[:first] = old[:first]
                setattr(self, attr, new)
            keys = np.empty(size * g, dtype=complex)
            keys[: first * g] = self.keys[: first * g]
            self.keys = keys
        self.arcs[first:end] = table.arcs
        self.positions[first:end] = table.positions
        keys = row_keys(table.arcs, first)
        if keys is None:
            self.sorted = False
        else:
            self.keys[first * g : end * g] = keys
        self.n = end
        self.of[name] = (table, first)
        return first

    def along(self, rows: np.ndarray, x: np.ndarray) -> np.ndarray:
        """The points (N, 3) of the strokes in ``rows`` (N,) at path lengths ``x`` (N,), linearly interpolated
        (``np.interp`` row by row), each length clipped to its stroke: the two points about each length gathered
        (in a compiled loop, :func:`along_table`, with numba; else numpy's steps, the same values)."""
        g = self.arcs.shape[1]
        kernel = _kernel()
        if kernel is not None and x.dtype == np.float64 and rows.dtype == np.int64:
            out = np.empty((len(x), 3))
            kernel(self.arcs, self.positions, rows, x, self.sorted, out)
            return out
        if self.sorted:
            query = np.empty(len(x), dtype=complex)
            query.real, query.imag = rows, x
            count = np.searchsorted(self.keys[: self.n * g], query, side="right") - rows * g
            count[np.isnan(x)] = 0  # a NaN length is at most no point
        else:
            count = (self.arcs[rows] <= x[:, None]).sum(axis=1)
        j = np.clip(count - 1, 0, g - 2)
        a0, a1 = self.arcs[rows, j], self.arcs[rows, j + 1]
        step = a1 - a0
        w = np.divide(x - a0, step, out=np.zeros_like(x), where=step > 0)
        p0 = self.positions[rows, j]
        return p0 + np.clip(w, 0.0, 1.0)[:, None] * (self.positions[rows, j + 1] - p0)


class Tables:
    """The tables of a motor system's commands, each computed when first needed and kept while its command is the
    same: per stroke (:meth:`table`), per command (:meth:`edge`), and per set of candidates their rows in the table
    of every stroke (:meth:`stacked`)."""

    GRID = 200
    """Points of the fine grid each stroke is tabled on (:meth:`table`)."""

    def __init__(self, motor: Any) -> None:
        self.motor = motor
        self._strokes: dict[int, tuple] = {}
        self._edges: dict[str, EdgeTable] = {}
        self._stacks: OrderedDict[tuple[str, ...], tuple[list, tuple]] = OrderedDict()
        self.rows = StrokeRows(self.GRID)
        _kernel()  # compiled (or loaded from numba's cache) now, not in the first demonstration

    def strokes_of(self, name: str) -> list[Any]:
        """Command ``name``'s strokes, one per part of its subsystem."""
        return self.motor.edge(name).commands

    def table(self, stroke: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(times, positions, cumulative path length) of a stroke on a fine grid, computed once per stroke."""
        table = self._strokes.get(id(stroke))
        if table is None or table[0] is not stroke:
            grid = np.linspace(0.0, stroke.duration, self.GRID)
            positions = stroke.position(grid)
            table = (stroke, grid, positions, arc(positions))
            self._strokes[id(stroke)] = table
        return table[1], table[2], table[3]

    def edge(self, name: str) -> EdgeTable:
        """Every part's stroke of command ``name`` on the fine grid, stacked (computed once per command)."""
        commands = self.strokes_of(name)
        table = self._edges.get(name)
        if table is None or table.commands is not commands:
            tables = [self.table(stroke) for stroke in commands]
            arcs = np.stack([a for _, _, a in tables])
            lead = int(np.argmax(arcs[:, -1]))
            table = EdgeTable(commands, np.stack([positions for _, positions, _ in tables]), arcs, lead)
            self._edges[name] = table
        return table

    def length(self, name: str) -> float:
        """Path length (m, or radians for a hand) of a command's lead part."""
        edge = self.edge(name)
        return float(edge.arcs[edge.lead, -1])

    def lead(self, name: str) -> int:
        """The part of the subsystem that moves farthest along a command: progress and speed are measured on it."""
        return self.edge(name).lead

    def mapped_time(self, stroke: Any, length: float) -> float:
        """The stroke time at which it has covered ``length`` metres of path (the speed-free forward model)."""
        grid, _, a = self.table(stroke)
        return float(np.interp(min(length, a[-1]), a, grid))

    def progress(self, name: str, along: np.ndarray) -> float:
        """The share of command ``name``'s time its lead part has covered, ``along`` its path."""
        lead = self.lead(name)
        stroke = self.strokes_of(name)[lead]
        return self.mapped_time(stroke, along[lead]) / stroke.duration

    def stacked(self, names: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For commands ``names``: their strokes' rows in the table of every stroke (:attr:`rows`, C * k), their
        stroke lengths (C, k) and lead parts (C,); kept for the last sets of candidates (a node's edges are the
        candidates of every demonstration that starts there) while their commands are the same."""
        edges = [self.edge(name) for name in names]
        strokes = self._stacks.get(names)
        if strokes is None or not all(a is b for a, b in zip(strokes[0], edges)):
            table = self.rows
            rows = np.concatenate([table.rows(n, e) + np.arange(len(e.arcs)) for n, e in zip(names, edges)])
            strokes = (edges, (rows, np.stack([e.arcs[:, -1] for e in edges]), np.array([e.lead for e in edges])))
            self._stacks[names] = strokes
            if len(self._stacks) > 64:
                self._stacks.popitem(last=False)
        else:
            self._stacks.move_to_end(names)
        return strokes[1]
