"""Matcher ``forward-model``: predicting the ongoing demonstration from the active node's edges (Kopp & Graeser 2006, §4.4, Fig. 3).

When a demonstration begins, every edge leaving the active node of the moving
subsystem's motor command graph predicts, in parallel, where the demonstrator's
part should be (its forward model, :meth:`GuidingStroke.position`). A candidate
whose prediction error exceeds ``threshold`` drops out. When exactly one
prevails (and enough of its path has been seen) it is executed at once, well
before the demonstration ends: *response facilitation*. While imitating, the
observation keeps being compared with the chosen edge; if they part by more
than ``deviation`` the imitation is stopped, the edge is excluded for this
segment, the subsystem returns to the last correct node (the start of the edge
the demonstration was on: the edges before it were right; §4.4: "the imitator
returns into the last node at which accordance with the demonstrated movement
was found") and Fig. 3's loop goes on from there: the edges leaving that node,
the excluded ones left out, predict what has been seen since the demonstration
passed it (:meth:`ForwardModel._repredict`). One that prevails explains the rest
(it is checked, and may deviate in turn); only what no edge explains is learned,
from the last correct node.

Speed (§4.4): with ``reparameterise`` (the default) the forward model is evaluated
not at the elapsed time but at the time at which the edge would have covered the
same length of path as has been observed, so a familiar movement performed faster
or slower still fits. How much faster is measured against the demonstration the
edge was learned from (``Edge.shown``: "the motor command (with the speed
demonstrated at first)"), played from the best start at the best speed factor
(:meth:`ForwardModel._speed`); the imitation is performed at that factor. A
commitment waits until the movement has been seen for three frames, so that its
speed can be told from when it began. Off, the paper's baseline: edges predict at
the elapsed time, and a familiar movement at another speed is learned as new.

Joining late: a segment often begins after its movement did (a hub threshold is
crossed once the body has left the hub; a take is cropped in motion). Each part
is then predicted from the point of its stroke, in the stroke's first half,
nearest to where it was first seen (the anchor), not from the stroke's start.
And a subsystem whose active node is not its hub begins at the hub instead when
the body is seen nearer to the hub's state than to the active node's (a
demonstrator who returned to rest without the matcher following him there).

*True imitation* (§4.3, Fig. 3 top): when no edge predicts the demonstration,
the motor command graph learns it (``learn_observed``): the working memory of the
segment is cut into strokes at the break points of the stroke analysis
(:mod:`plugins.lib.strokes`, with this matcher's ``drop`` and ``angle``), each
stroke becomes a guiding stroke by the inverse model, and the strokes become new
edges and nodes leading from the active node (ending in the hub when the
demonstration returns there).

Commitment is as in the paper (Fig. 3): when every living candidate stands for one movement (and ``min_progress``
of it has been seen).

Ranked candidates (B&B Fig. 13; K&G §4.4, Fig. 3's candidates): every answer of one followed subsystem carries
``Match.candidates``, the movements the forward models considered in the segment with their prediction errors,
the answer first and the others best first (:meth:`ForwardModel._ranked`): each movement's error is the mean over
the frames followed of its best path's error in each frame, a movement that dropped out held at the error it
dropped out with, so all are measured over the same frames. An unknown answer ranks them all (and still names,
in ``details``, the candidate predicted longest).

Working memory: the matcher reads the segment from the
:class:`~toolkit.watching.WorkingMemory` the watching loop gives it (root-relative,
in the observer's parts, hidden parts held) and keeps no frames of its own; what it
needs of the motor system is the :class:`CommandGraphs` protocol, checked when it
is attached. :meth:`ForwardModel.inspect` shows its candidates and prediction errors.

Subsystems moving at once (§4.2: "multiple graphs at once in order to account
for the possibly concurrent execution of submovements in different motor
subsystems within a complex hand-arm-motion"): every subsystem whose parts move
more than ``min_move`` during the demonstration is under consideration, each
followed by a :class:`Track` with its own candidates from its own active node.
One that starts later is followed from when it started. The commitment waits
until every moving subsystem has one prevailing command (and for a subsystem
that has begun to move but not yet far enough to be judged), then the commands
are imitated together (:meth:`MotorCommandGraph.add_together`). If one of them
has no candidate left, nothing is committed early: at the end its movement is
learned and imitated together with the others' recognised commands. With
``together = false`` only the first subsystem to move is followed.

Hands: a hand subsystem's edges are hand transitions over the fingers' joint
angles (:mod:`plugins.lib.hand_transition`); they predict the observed finger
configuration just as guiding strokes predict the wrist. Angles are compared
with the same thresholds through ``angle_scale`` (metres one radian counts as),
and a new hand movement is learned as one edge whose key postures are the
angular-velocity minima and direction changes (§4.3).
"""

from __future__ import annotations

import functools
import math
from collections import OrderedDict
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Protocol

import numpy as np

from plugins.lib.compiled import compiled
from plugins.lib.strokes import StrokeCriteria
from toolkit import Match, Matcher, Motion, Parameter, hookimpl
from toolkit.components import provides
from toolkit.watching import WorkingMemory, follow

__all__ = ["ForwardModel", "Track", "CommandGraphs"]


def _distances(x: np.ndarray, y: np.ndarray, z: np.ndarray, first: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(positions - first[:, None], axis=-1)`` of points given as coordinate planes x, y, z (C, k, h)
    and ``first`` (k, 3): the same arithmetic in the same order (the squares summed x, y, z, then the root), so the
    same bits, without the (C, k, h, 3) temporaries of the stacked form."""
    dx, dy, dz = x - first[:, 0, None], y - first[:, 1, None], z - first[:, 2, None]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


class CommandGraphs(Protocol):
    """A motor system of motor command graphs, one per subsystem, whose edges are commands (K&G §4.2).

    What the forward model needs of it: ``plugins.motor.motor_command_graph`` provides it.
    """

    subsystems: Mapping[str, np.ndarray]
    """The parts (indices into the body) each subsystem moves."""

    def is_hand(self, subsystem: str) -> bool:
        """Whether a subsystem's states are a hand's finger joint angles (radians) rather than positions."""

    def active_node(self, subsystem: str) -> str:
        """The node a subsystem is in: where the last movement followed or performed ended."""

    def move_to(self, subsystem: str, node: str, *, posture: bool = True) -> None:
        """Put a subsystem in ``node`` (with ``posture``, the body's parts too)."""

    def state(self, subsystem: str, node: str) -> np.ndarray:
        """A node's motor state, (k, 3) for the subsystem's k parts."""

    def edges_from(self, subsystem: str, node: str) -> list[Any]:
        """The edges leaving ``node``: records with ``name``, ``source``, ``target`` and ``commands``."""

    def edge(self, movement: str) -> Any:
        """The edge record of a movement (edge) name."""

    def known_sequence(self, path: tuple[str, ...]) -> tuple[str, ...]:
        """The whole learned sequence of edges ``path`` begins, else ``path``."""

    def add_sequence(self, edges: list[str], *, name: str | None = None, label: str | None = None) -> str:
        """A path of edges named as one movement."""

    def add_together(self, movements: list[str]) -> str:
        """Movements of several subsystems named as one, performed at once."""

    def subsystem_of(self, movement: str) -> str:
        """The subsystem a movement moves."""

    def label(self, movement: str) -> str:
        """The movement a performable name is an example of."""

    def label_of_path(self, path: tuple[str, ...]) -> str | None:
        """The labelled movement a path of edges stands for, if one."""

    def learn_observed(self, subsystem: str, start: str, observed: np.ndarray, fps: float, *,
                       criteria: StrokeCriteria = StrokeCriteria()) -> list[str]:
        """Learn an observed movement as new edges from ``start`` (true imitation); their names."""

    def rest_pose(self) -> np.ndarray:
        """The body's rest pose, local frame (P, 3)."""


def _arc(points: np.ndarray) -> np.ndarray:
    """Cumulative path length along points (N, 3)."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


@dataclass
class Track:
    """One motor subsystem under consideration during a demonstration (K&G §4.1): its candidates, commitment, errors.

    ``onset`` is the row of the segment's working memory from which the subsystem is followed (0 for the first
    subsystem to move; a subsystem that starts later is followed from when it started). After a deviation,
    ``last_correct`` is the node where the demonstration last agreed with the committed path, ``right`` the
    edges before it that were followed correctly, ``excluded`` the edges that failed, and ``learn_from`` the row
    from which the rest is predicted again (Fig. 3's loop: the subsystem is then followed by a new track from
    ``last_correct``, ``onset`` = ``learn_from``) and, if no edge explains it, learned. ``trace`` holds, per
    frame, the prediction error of every candidate path evaluated (dropped ones at the frame they drop); while
    imitating, the committed path's error. ``committed_at`` and ``deviated_at`` count the segment's frames seen.
    """

    subsystem: str
    scale: float
    hand: bool
    start_node: str
    onset: int
    candidates: dict[tuple[str, ...], float]
    initial: list[str]
    excluded: set[str] = field(default_factory=set)
    committed: str | None = None
    committed_path: tuple[str, ...] = ()
    confidence: float = 0.0
    speed: float = 1.0
    progress: float = 0.0
    reported: bool = False
    deviated: bool = False
    last_correct: str | None = None
    right: tuple[str, ...] = ()
    learn_from: int = 0
    trace: list[tuple[int, dict[tuple[str, ...], float]]] = field(default_factory=list)
    committed_at: int | None = None
    deviated_at: int | None = None
    anchors: dict[str, np.ndarray] = field(default_factory=dict)
    first: np.ndarray | None = None
    """The subsystem's parts as seen at the onset (k, 3); ``None``: read from working memory."""
    stopped: bool = False
    """The imitation of a commitment was stopped at a deviation (once a segment; the body went back to ``home``)."""
    home: str | None = None
    """The node the subsystem's body is in, or goes back to, while it is followed: the start node (``None``), or
    the last correct node it returned to when its imitation was stopped."""
    at: int = 0
    """How many of the edges of ``right`` the body has performed (those up to ``home``)."""
    failed: list[tuple[str, tuple[str, ...]]] = field(default_factory=list)
    """The commitments (movement, path) that deviated in this segment, in order."""
    origin: int | None = None
    """After a deviation, predicted again from the last correct node (Fig. 3): the row from which the subsystem was
    followed first (``onset`` is then the row it passed the last correct node)."""
    begun: Track | None = None
    """After a deviation, predicted again: the segment's first track of the subsystem (what :meth:`ForwardModel.inspect`
    shows of the segment's start)."""
    placed: tuple[dict[str, int], np.ndarray] | None = None
    """The anchors placed at once when the track began (:meth:`ForwardModel._anchor`): each command's row in them and
    the array (C, k) whose rows are those of ``anchors``."""


@dataclass(frozen=True)
class _EdgeTable:
    """A command's strokes, one per part, on a fine grid: positions (k, G, 3), cumulative path lengths (k, G), and
    the lead part (the one that moves farthest)."""

    commands: list
    positions: np.ndarray
    arcs: np.ndarray
    lead: int


def _row_keys(arcs: np.ndarray, first: int = 0) -> np.ndarray | None:
    """``arcs`` (R, G) as one sorted complex array for :func:`_along_rows`: row r's values are ``first + r + 1j *
    arcs[r]``, and numpy orders complex numbers lexicographically (real part, then imaginary), so one
    ``searchsorted`` counts, for every row at once, the points of its own row at most a given length. ``None`` when
    a row does not grow (NaN, or a decrease): then the count is taken by comparing every point."""
    if not arcs.size or not bool((arcs[:, 1:] >= arcs[:, :-1]).all()):
        return None
    keys = np.empty(arcs.shape, dtype=complex)
    keys.real = np.arange(first, first + len(arcs))[:, None]
    keys.imag = arcs
    return keys.ravel()


class _StrokeRows:
    """Every command's strokes the forward model has met, one row per part, in one growing table: cumulative path
    lengths (R, G), positions (R, G, 3) and the lengths' search keys (:func:`_row_keys`, row numbers as real parts,
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

    def rows(self, name: str, table: _EdgeTable) -> int:
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
        keys = _row_keys(table.arcs, first)
        if keys is None:
            self.sorted = False
        else:
            self.keys[first * g : end * g] = keys
        self.n = end
        self.of[name] = (table, first)
        return first

    def along(self, rows: np.ndarray, x: np.ndarray) -> np.ndarray:
        """:func:`_along_rows` of the strokes in ``rows`` at path lengths ``x``: the same points, the same values (in a
        compiled loop, :func:`_along_table`, with numba; else numpy's steps)."""
        g = self.arcs.shape[1]
        kernels = _kernels()
        if kernels is not None and x.dtype == np.float64 and rows.dtype == np.int64:
            out = np.empty((len(x), 3))
            kernels[1](self.arcs, self.positions, rows, x, self.sorted, out)
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


def _along_rows(arcs: np.ndarray, positions: np.ndarray, x: np.ndarray, keys: np.ndarray | None = None) -> np.ndarray:
    """Per row r, the point of ``positions[r]`` (G, 3) at path length ``x[r]`` along ``arcs[r]`` (G,), linearly
    interpolated (``np.interp`` row by row); 0 <= x[r] <= arcs[r, -1].

    ``keys`` (:func:`_row_keys` of ``arcs``): the points at most ``x[r]`` along each row counted by one binary search
    instead of a comparison of every point (the same count: exact comparisons of the same numbers)."""
    if keys is None:
        count = (arcs <= x[:, None]).sum(axis=1)
    else:
        rows = np.arange(len(x))
        query = np.empty(len(x), dtype=complex)
        query.real, query.imag = rows, x
        count = np.searchsorted(keys, query, side="right") - rows * arcs.shape[1]
        count[np.isnan(x)] = 0  # a NaN length is at most no point
    j = np.clip(count - 1, 0, arcs.shape[1] - 2)
    rows = np.arange(len(x))
    a0, a1 = arcs[rows, j], arcs[rows, j + 1]
    step = a1 - a0
    w = np.divide(x - a0, step, out=np.zeros_like(x), where=step > 0)
    return positions[rows, j] + np.clip(w, 0.0, 1.0)[:, None] * (positions[rows, j + 1] - positions[rows, j])


def _lengths(observed: np.ndarray) -> np.ndarray:
    """The observed path length of each part of a working memory (n, k, 3), robust to observation noise.

    Noise adds length at every frame; the positions are averaged over three frames first.
    """
    from scipy.ndimage import uniform_filter1d

    if len(observed) >= 3:
        observed = uniform_filter1d(observed, size=3, axis=0, mode="nearest")
    return np.linalg.norm(np.diff(observed, axis=0), axis=-1).sum(axis=0) if len(observed) > 1 else \
        np.zeros(observed.shape[1])


class _Grown:
    """Rows computed once each and kept in a buffer that grows by doubling: :meth:`view` is the first ``n`` (a view).

    The forward model's per-frame work is incremental with it: a row of the working memory, once given, keeps its
    values while :attr:`WorkingMemory.revision <toolkit.watching.WorkingMemory.revision>` stays the same, so what
    is computed from it is computed once.
    """

    __slots__ = ("buffer", "n")

    def __init__(self, shape: tuple[int, ...], capacity: int = 64) -> None:
        self.buffer = np.empty((max(1, capacity), *shape))
        self.n = 0

    def extend(self, rows: np.ndarray) -> None:
        """Append ``rows`` (m, *shape)."""
        end = self.n + len(rows)
        if end > len(self.buffer):
            bigger = np.empty((max(end, 2 * len(self.buffer)), *self.buffer.shape[1:]))
            bigger[: self.n] = self.buffer[: self.n]
            self.buffer = bigger
        self.buffer[self.n : end] = rows
        self.n = end

    def view(self) -> np.ndarray:
        return self.buffer[: self.n]


def _norms(d: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(d, axis=-1)`` of real values, as numpy computes it (the square root of the summed squares
    along the last axis), without its argument handling: the same values."""
    return np.sqrt(np.add.reduce(d * d, axis=-1))


def _place_rows(x: np.ndarray, y: np.ndarray, z: np.ndarray, arcs: np.ndarray, parts: np.ndarray, first: np.ndarray,
                rows: np.ndarray, out: np.ndarray) -> None:
    """One group of :class:`_Halves` placed, stroke by stroke: ``out[rows[r]]`` is ``arcs[r, i]`` at the first ``i``
    where the distance from ``first[parts[r]]`` to the point (x, y, z)[r, i] is least (``np.argmin``'s rules: the
    first least, or the first NaN). Each distance is computed as :meth:`_Halves.place` computes it (the squares summed
    x, y, z, then the root: the same bits). The root is taken only where the summed squares fall below the least so
    far (the root does not decrease, so nowhere else can it be less): a point whose root equals the least one's keeps
    the earlier index, as ``argmin`` does. Plain Python as written (the reference); :func:`_kernels` compiles it."""
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


def _along_table(arcs: np.ndarray, positions: np.ndarray, rows: np.ndarray, x: np.ndarray, ordered: bool,
                 out: np.ndarray) -> None:
    """:meth:`_StrokeRows.along` row by row: ``out[i]`` (3,) is the point of stroke ``rows[i]`` (``arcs`` (R, G),
    ``positions`` (R, G, 3)) at path length ``x[i]``, with numpy's steps and rules: the points at most ``x[i]`` counted
    (by a binary search when every row's lengths grow, ``ordered``; a NaN length is at most none), the segment
    before them (clipped to the stroke), the weight ``(x - a0) / step`` (0 where the step is not positive) clipped to
    [0, 1] as ``np.clip`` clips (NaN and -0 kept), then ``p0 + w * (p1 - p0)``. Plain Python as written (the
    reference); :func:`_kernels` compiles it."""
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
def _kernels() -> tuple[Any, Any] | None:
    """:func:`_place_rows` and :func:`_along_table` compiled by numba (cached on disk; no ``fastmath``: no reordered
    sums, no fused multiply-adds), or ``None`` without numba (numpy's steps run then, with the same values).
    Compiled (or loaded) when a forward model is attached, not in its first demonstration."""
    kernels = compiled(_place_rows, _along_table)
    if kernels is None:
        return None
    place, along = kernels
    one, row = np.zeros((1, 2)), np.zeros(1, dtype=np.int64)
    place(one, one, one, one, row, np.zeros((1, 3)), row, np.zeros(1))  # compiled for the types they are called with
    along(one, np.zeros((1, 2, 3)), row, np.zeros(1), True, np.empty((1, 3)))
    return place, along


class _Walk:
    """:func:`_lengths` of a growing working memory, frame by frame, with exactly the same values.

    The three-frame mean (``uniform_filter1d``, ``mode="nearest"``) is scipy's running sum: ``tmp`` starts at the
    sum of the first window, then adds each entering row minus the leaving one, and each output is ``tmp / 3``. A
    new frame changes only the last smoothed row (its right neighbour was the edge's copy) and adds one: the running
    sum is kept up to the last row whose window lies wholly inside the frames seen, and so are the norms of the
    steps between the smoothed rows that are final, so a frame costs a few rows whatever the length of the segment.
    The total is summed by numpy over the kept norms as :func:`_lengths` sums them (same array layout, same order:
    the same bits). ``tests/test_forward_model_incremental.py`` compares it with :func:`_lengths` on random data.
    """

    __slots__ = ("tmp", "final", "smooth", "norms", "seen")

    def __init__(self, k: int) -> None:
        self.tmp: np.ndarray | None = None  # scipy's running window sum at row ``final - 1`` (k, 3)
        self.final = 0  # smoothed rows [0, final) are final: their windows lie inside the frames seen
        self.smooth = _Grown((k, 3))  # the final smoothed rows
        self.norms = _Grown((k,))  # the norms of the steps between final smoothed rows, then one slot more
        self.seen = 0

    def lengths(self, observed: np.ndarray) -> np.ndarray:
        """``_lengths(observed)`` for ``observed`` (n, k, 3), whose first rows are the ones given before."""
        n = len(observed)
        if n < self.seen:
            raise ValueError(f"the working memory shrank from {self.seen} to {n} rows")
        self.seen = n
        if n < 3:  # no filter below three frames (as _lengths)
            return _lengths(observed)
        if self.tmp is None:  # scipy: tmp = 0.0 + x[-1] + x[0] + x[1], the edge repeated
            self.tmp = (observed[0] + observed[0]) + observed[1]
            self.smooth.extend((self.tmp / 3)[None])
            self.final = 1
        if self.final == n - 2 and n >= 4:  # one more final row (the common case: one frame more)
            self.tmp = self.tmp + (observed[n - 1] - observed[n - 4])
            row = self.tmp / 3
            smooth = self.smooth
            if smooth.n == len(smooth.buffer):
                smooth.extend(row[None])
            else:
                smooth.buffer[smooth.n] = row
                smooth.n += 1
            self.final = n - 1
            self.norms.n = n - 3
            self.norms.extend(_norms(row - smooth.buffer[n - 3])[None])
        elif self.final < n - 1:  # rows final .. n-2: tmp[i] = tmp[i-1] + (x[i+1] - x[i-2])
            tmp, out = self.tmp, []
            for i in range(self.final, n - 1):
                tmp = tmp + (observed[i + 1] - observed[max(i - 2, 0)])
                out.append(tmp / 3)
            self.tmp, self.final = tmp, n - 1
            before = self.smooth.n
            self.smooth.extend(np.stack(out))
            rows = self.smooth.buffer[before - 1 : self.smooth.n]
            self.norms.n = before - 1  # drop the slot of the last edge row
            self.norms.extend(np.linalg.norm(np.diff(rows, axis=0), axis=-1))
        # the last row's window repeats its own frame (the edge): tmp[n-1] = tmp[n-2] + (x[n-1] - x[n-3])
        edge = (self.tmp + (observed[n - 1] - observed[n - 3])) / 3
        norms = self.norms
        norms.n = n - 2
        if norms.n == len(norms.buffer):
            norms.extend(_norms(edge - self.smooth.buffer[n - 2])[None])
        else:
            norms.buffer[norms.n] = _norms(edge - self.smooth.buffer[n - 2])
            norms.n += 1
        return np.add.reduce(norms.buffer[: norms.n], axis=0)


class _Halves:
    """The first halves of a set of commands' strokes, for :meth:`ForwardModel._anchor`: where along each stroke
    (path length) lies its first-half point nearest to where the part was seen.

    ``arcs`` (C, k, G) and ``positions`` (C, k, G, 3) are the strokes of C commands of k parts. A point lies in its
    stroke's first half while its path length is at most half the stroke's. A stroke that moves no part (every
    path length 0) is joined at 0 wherever the part is. The strokes that move are sorted by the length of their
    first halves and kept in :attr:`GROUPS` groups, each as contiguous coordinate planes x, y, z cut to its longest
    half, the points past a half given x = +inf (so their distance is +inf, as the plain computation's mask makes
    it; with a part never seen, NaN, both give the first point). :meth:`place` computes each distance as
    :func:`_distances` does (the squares summed x, y, z, then the root: the same bits) and takes each stroke's first
    nearest point (``np.argmin``), so the anchors are those of the masked argmin over whole strokes, with about a
    third less arithmetic. With numba the same arithmetic runs stroke by stroke in a compiled loop
    (:func:`_place_rows`), the root taken only where a point may be the nearest. ``tests/test_forward_model_fast.py``
    compares each way with the masked argmin."""

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
        kernels = _kernels()
        if kernels is not None and first.dtype == np.float64:  # compiled, stroke by stroke (the same anchors)
            first = np.ascontiguousarray(first)
            for rows, parts, x, y, z, arcs in self.groups:
                kernels[0](x, y, z, arcs, parts, first, rows, placed)
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


@dataclass
class _Tracked:
    """What the forward model keeps of one followed subsystem between frames: its rows of the working memory
    (:meth:`ForwardModel._observed`), their path lengths (:class:`_Walk`) and the rows it gave last."""

    track: Track
    rows: _Grown
    walk: _Walk
    last: np.ndarray | None = None
    stacked: tuple | None = None


class ForwardModel(Matcher):
    """Edges of the active node predict the demonstration in parallel; the last one left is imitated at once (K&G §4.4)."""

    name = "forward-model"
    motor_systems = ("motor-command-graph",)
    parameters = (
        Parameter("threshold", float, 0.05, "Prediction error (m) above which a candidate edge drops out.", minimum=0.0, length=True),
        Parameter("deviation", float, 0.05, "Error (m) between the imitated edge and the demonstration that stops the "
                  "imitation (also checked at the end: the demonstration must end where the edge does).", minimum=0.0, length=True),
        Parameter("min_progress", float, 0.2, "Share of the edge's path that must be seen before committing.", minimum=0.0, maximum=1.0),
        Parameter("min_move", float, 0.02, "Displacement (m) of a subsystem that makes it one under consideration.", minimum=0.0, length=True),
        Parameter("angle_scale", float, 0.25, "Metres one radian of finger joint angle counts as when a hand "
                  "subsystem's errors and movement are compared with threshold, deviation and min_move "
                  "(0.25: the 0.05 m threshold is 0.2 rad, 11 degrees).", minimum=1e-6, length=True),
        Parameter("max_candidates", int, 24, "Most candidate command paths followed at once (the best predictions).", minimum=1),
        Parameter("together", bool, True, "Follow every subsystem that moves during a demonstration, each with its "
                  "own candidates, and imitate them at once (a hand-arm movement, §4.2); off: only the first to move."),
        Parameter("learn", bool, True, "Learn new edges by the inverse model when no edge predicts the demonstration."),
        Parameter("reparameterise", bool, True, "Speed re-parameterisation (K&G §4.4): an edge predicts the "
                  "demonstration at the time its command covers the path length seen, so a familiar movement "
                  "performed faster or slower still fits, and is imitated at the speed measured. Off (the paper's "
                  "baseline): an edge predicts at the time elapsed, at the speed it was learned, so a familiar "
                  "movement at another speed is learned as new."),
        Parameter("drop", float, 0.5, "Speed-minimum criterion of the stroke segmentation used for learning.", minimum=0.0, maximum=1.0),
        Parameter("angle", float, 50.0, "Direction criterion (degrees) of the stroke segmentation used for learning.", minimum=1.0, maximum=180.0),
    )

    streaming = True
    report_details = ("candidates", "learned", "speed", "deviated")

    GRID = 200
    """Points of the fine grid each stroke is tabled on (:meth:`_table`)."""

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        motor = owner.motor
        provides(motor, CommandGraphs, needed_by="forward-model", what="a motor command graph",
                 expected=" or ".join(f'[motor] plugin = "{name}"' for name in self.motor_systems))
        self.motor = motor
        # observed root-relative positions are placed at the observer's own root height; finger angles stay as they are
        self._root_height = np.where(owner.body.angle_mask[:, None], 0.0, motor.rest_pose()[owner.body.root_index])
        self._criteria = StrokeCriteria(drop=self.params["drop"], angle=self.params["angle"])
        self._keys: dict[tuple[str, ...], str] = {}  # path -> movement (:meth:`_movement_key`)
        self._key_version: tuple | None = None
        _kernels()  # compiled (or loaded from numba's cache) now, not in the first demonstration
        self._tables: dict[int, tuple] = {}
        self._edges: dict[str, _EdgeTable] = {}
        self._half_tables: OrderedDict[tuple[str, ...], tuple[list, tuple]] = OrderedDict()
        self._stroke_tables: OrderedDict[tuple[str, ...], tuple[list, tuple]] = OrderedDict()
        self._stroke_rows = _StrokeRows(self.GRID)
        self._scales: dict[str, tuple[Any, float]] = {}
        self._placed: OrderedDict[tuple[tuple[str, ...], bytes], tuple[tuple, np.ndarray]] = OrderedDict()
        self._memory: WorkingMemory | None = None
        self._rows: _Grown | None = None  # the working memory in the motor frame, row by row
        self._last_local: np.ndarray | None = None
        self._tracked: dict[str, _Tracked] = {}
        self._revision = 0
        self.tracks: dict[str, Track] = {}
        self.reported = False
        every = getattr(motor, "edges", None)  # optional (not in CommandGraphs): every edge of a subsystem
        if callable(every):  # the repertoire's tables once, at composition; learned edges' when first met
            for subsystem in motor.subsystems:
                for edge in every(subsystem):
                    self._edge(edge.name)

    # -- streaming ------------------------------------------------------------------------------

    def begin(self, memory: WorkingMemory) -> None:
        self._memory = memory
        self._rows, self._last_local, self._tracked, self._revision = None, None, {}, memory.revision
        self.fps = memory.fps
        self.tracks = {}  # in the order the subsystems began to move
        self.reported = False  # a commitment to the tracks decided so far has been announced
        self._settled = False  # nothing more can happen in this segment (:meth:`_quiet`)
        self._settled_at: tuple[int, int] | None = None  # (frames, revision) when it settled (:meth:`settled`)

    @property
    def main(self) -> Track | None:
        """The first subsystem to move, as the views and single-subsystem users see it."""
        return next(iter(self.tracks.values()), None)

    def inspect(self) -> Mapping[str, Any]:
        """The segment followed last: for its first subsystem to move (and, under ``tracks``, for each) the start
        node, the candidate paths still alive, the initial candidates, the commitment and when it came, whether and
        when it deviated, the per-frame prediction errors (``trace``) and the anchors; read-only snapshots."""
        def view(track: Track | None) -> dict[str, Any]:
            if track is None:
                return {"subsystem": None, "start_node": None, "candidates": {}, "initial": [], "committed": None,
                        "committed_path": (), "deviated": False, "trace": (), "committed_at": None,
                        "deviated_at": None, "anchors": {}}
            # after a deviation predicted again without a new commitment: the commitment that deviated
            committed, path = (track.committed, track.committed_path) if track.committed is not None or \
                not track.failed else track.failed[-1]
            begun = track.begun or track
            return {"subsystem": track.subsystem, "start_node": begun.start_node,
                    "candidates": dict(track.candidates), "initial": list(track.initial), "committed": committed,
                    "committed_path": tuple(path), "deviated": track.deviated,
                    "trace": tuple(track.trace), "committed_at": track.committed_at, "deviated_at": track.deviated_at,
                    "anchors": {k: v.copy() for k, v in {**begun.anchors, **track.anchors}.items()}}
        return MappingProxyType({**view(self.main), "frames": 0 if self._memory is None else self._memory.n,
                                 "tracks": {name: view(track) for name, track in self.tracks.items()}})

    def _nearest(self) -> dict[str, Any]:
        """For an unknown answer: the candidate of the first subsystem to move that predicted the demonstration
        longest before it was dropped (``nearest``, its movement), and for how many frames (``predicted_frames``)."""
        track = self.main
        if track is None or not track.trace:
            return {}
        last: dict[tuple[str, ...], tuple[int, float]] = {}
        for frame, errors in track.trace:
            for path, error in errors.items():
                last[path] = (frame, error)
        path, (frame, error) = max(last.items(), key=lambda kv: (kv[1][0], -kv[1][1]))
        label = self._movement_key(tuple(path)) if path else None
        return {"nearest": label, "predicted_frames": int(frame), "error_when_dropped": float(error)}

    def _ranked(self, track: Track | None, answer: str | None = None,
                path: tuple[str, ...] = ()) -> tuple[tuple[str, float], ...]:
        """The movements a subsystem's forward models considered in this segment, with their prediction errors,
        best first (``Match.candidates``; B&B Fig. 13's ranked candidates, K&G §4.4's candidates of Fig. 3): each
        movement's error is the mean, over the frames the subsystem has been followed, of the error of its best
        candidate path in each frame; from the frame it dropped out on, the error it dropped out with (it is
        taken to be as far off from then as when it was last predicted), so every movement is measured over the
        same frames. ``answer`` (the movement of the committed ``path``) comes first, with its movement's error;
        the others follow by error. Empty when nothing was predicted."""
        if track is None or not track.trace:
            return ()
        keys: dict[tuple[str, ...], str] = {}
        sums: dict[str, float] = {}
        seen: dict[str, tuple[int, int, float, int]] = {}  # movement -> (first frame index, frames, last, last index)
        for i, (_, errors) in enumerate(track.trace):
            best: dict[str, float] = {}
            for candidate, error in errors.items():
                key = keys.get(candidate)
                if key is None:
                    key = keys[candidate] = self._movement_key(tuple(candidate)) if candidate else ""
                if error < best.get(key, np.inf):
                    best[key] = error
            for key, error in best.items():
                first, count, _, _ = seen.get(key, (i, 0, 0.0, i))
                seen[key] = (first, count + 1, error, i)
                sums[key] = sums.get(key, 0.0) + error
        n = len(track.trace)
        value = {key: (sums[key] + last * (n - 1 - at)) / (n - first) for key, (first, _, last, at) in seen.items()
                 if key and math.isfinite(sums[key])}
        own = self._movement_key(tuple(path)) if path else None
        ranked = sorted(((key, float(v)) for key, v in value.items() if key != own), key=lambda kv: (kv[1], kv[0]))
        if answer is None:
            return tuple(ranked)
        return ((answer, float(value.get(own, np.nan))), *ranked)

    def _local(self) -> np.ndarray:
        """The working memory in the observer's motor frame (n, P, 3): root-relative positions placed at its own
        root height (finger angles as seen); hidden parts held, never-seen parts NaN.

        Each row is placed once and kept (the same values: each row's own sum), all of them again when rows
        already given were rewritten (:attr:`WorkingMemory.revision <toolkit.watching.WorkingMemory.revision>`: a
        part seen for the first time)."""
        memory = self._memory
        rows, n = self._rows, memory.n
        if rows is None or rows.n > n or self._revision != memory.revision:
            rows = self._rows = _Grown(memory.positions.shape[1:], max(64, 2 * n))
            self._tracked, self._revision = {}, memory.revision
        if rows.n < n:
            rows.extend(memory.positions[rows.n : n] + self._root_height)
        self._last_local = rows.view()
        return self._last_local

    def _at(self, row: int) -> np.ndarray:
        """One row of the working memory in the motor frame (P, 3)."""
        return self._memory.positions[row] + self._root_height

    def observe(self, memory: WorkingMemory) -> Match | None:
        if memory is not self._memory:
            self.begin(memory)
        elif self._settled:  # every subsystem followed, none with a candidate or a commitment: as below, no work
            return None
        local = self._local()
        self._start_tracks(local)
        if not self.tracks:
            return None
        stop = None
        for track in self.tracks.values():
            stop = self._follow(track, local) or stop
        if stop is not None:
            return stop
        tracks = list(self.tracks.values())
        if self._quiet(tracks):
            self._settled = True
            self._settled_at = (memory.n, memory.revision)
            return None
        if self.reported or not all(t.committed is not None and not t.deviated for t in tracks) or self._joining(local):
            return None
        self.reported = True  # every subsystem under consideration has one prevailing command: imitate them at once
        for t in tracks:
            t.reported = True
        movement = self.motor.add_together([t.committed for t in tracks])
        labels = [self._path_label(t.committed_path) or self.motor.label(t.committed) for t in tracks]
        main = tracks[0]
        details = {"candidates": [c for t in tracks for c in t.initial], "speed": main.speed,
                   "progress": main.progress}
        if len(tracks) > 1:
            details["subsystems"] = {t.subsystem: {"candidates": t.initial, "path": list(t.committed_path),
                                                    "speed": t.speed, "progress": t.progress} for t in tracks}
        return Match(labels[0] if len(tracks) == 1 else movement, min(t.confidence for t in tracks), memory.n,
                     path=tuple(e for t in tracks for e in t.committed_path), details=details,
                     candidates=self._ranked(main, labels[0], main.committed_path) if len(tracks) == 1 else ())

    def replay(self, memory: WorkingMemory, stop: int) -> list[tuple[int, Match]]:
        """:meth:`Matcher.replay <toolkit.components.Matcher.replay>`: the rows up to ``stop`` given at once, with the
        answers and the state of :meth:`observe` after each. Two runs of rows are given without it, because after
        each of them it would return ``None`` and change nothing but the rows :meth:`_local` places, which it places
        when next called (each row by the same addition, alone or in a batch):

        - once the segment settled (:meth:`_quiet`), every row to ``stop``;
        - while no subsystem is followed, the rows before the first at which one has moved more than ``min_move``
          since the onset (:meth:`_unmoved`: :meth:`_start_tracks`' test for all those rows at once).

        The rows from the first that starts a track until the segment settles are observed one by one.
        ``tests/test_forward_model_replay_block.py`` compares it with the rows fed one at a time."""
        events: list[tuple[int, Match]] = []
        row = memory.start + memory.n
        if row < stop and memory is not self._memory:  # as observe's first row would
            self.begin(memory)
        while row < stop:
            if self._settled:
                break
            if not self.tracks:
                row = self._unmoved(memory, row, stop)
                if row >= stop:
                    break
            memory.feed(row + 1)
            match = self.observe(memory)
            if match is not None:
                events.append((row, match))
            row += 1
        memory.feed(stop)
        return events

    def _unmoved(self, memory: WorkingMemory, row: int, stop: int) -> int:
        """The first of rows ``row`` .. ``stop - 1`` after which :meth:`_start_tracks` would start a track while no
        subsystem is followed (one whose parts are farther than ``min_move`` from where they were at the onset, as
        :meth:`_moved` measures it, row by row: the same values), else ``stop``. Reads the rows up to ``stop``
        without giving them: ``memory`` is left as it was."""
        given = memory.start + memory.n
        memory.feed(stop)
        try:
            local = memory.positions + self._root_height  # what _local places, row by row (the same additions)
        finally:
            memory.feed(given)
        far = _norms(local[row - memory.start :] - local[0])  # (rows, P): _moved's distances for each row
        moved = np.zeros(len(far), dtype=bool)
        for name, idx in self.motor.subsystems.items():
            moved |= np.fmax.reduce(far[:, idx], axis=1) * self._scale_of(name) > self.params["min_move"]
        hits = np.flatnonzero(moved)
        return row + int(hits[0]) if len(hits) else stop

    def settled(self) -> int | None:
        """After how many frames of the segment followed nothing more changed, if it settled: every subsystem
        followed, none with a candidate or a commitment (:meth:`_quiet`), and the rows given not rewritten since
        (:attr:`WorkingMemory.revision <toolkit.watching.WorkingMemory.revision>` the same). Else ``None``.

        Following the same rows from the same start up to any frame from then on leaves the same state as now (every
        later frame returned at once; the rows not yet placed are placed when next needed, each by the same
        addition), so a watching loop that must match the first ``m`` rows of what it followed (the first stroke of
        a movement the segmenter split) may conclude this state for them, its working memory cut to ``m`` rows,
        when ``m`` is at least this; ``tests/test_watching_settled.py`` compares it with feeding them again."""
        kept = self._settled_at
        if not self._settled or kept is None or self._memory is None or kept[1] != self._memory.revision:
            return None
        return kept[0]

    def _quiet(self, tracks: list[Track]) -> bool:
        """Whether the rest of the segment can change nothing: no subsystem is left to start (:meth:`_start_tracks`
        starts none: every one is followed, or ``together`` is off) and no track has a candidate or a commitment
        (:meth:`_follow` returns at once). Every later frame would then return ``None`` without a change but the rows
        :meth:`_local` places, which it places when next called (each row by the same addition, alone or in a
        batch: the same values); :meth:`observe` skips them."""
        if self.params["together"] and len(self.tracks) < len(self.motor.subsystems):
            return False
        return all(t.committed is None and not t.candidates for t in tracks)

    def _start_tracks(self, memory: np.ndarray) -> None:
        """Follow every subsystem not yet followed that has moved more than ``min_move`` since the onset.

        The first follows from the onset; one that starts later (three-frame means, against observation noise)
        from the last frame it was still within a quarter of ``min_move`` of where it was at the onset.
        """
        if self.tracks and not self.params["together"]:
            return
        late = bool(self.tracks)
        waiting = [name for name in self.motor.subsystems if name not in self.tracks]
        if not waiting:  # every subsystem is followed
            return
        if late:
            first = memory[:3].mean(axis=0)
            moved = self._moved(waiting, first, memory[-3:].mean(axis=0))
        else:
            moved = self._moved(waiting, memory[0], memory[-1])
        moved = {name: d for name, d in moved.items() if d > self.params["min_move"]}
        for name in sorted(moved, key=moved.get, reverse=True):
            onset = 0
            if late:
                idx = self.motor.subsystems[name]
                away = np.linalg.norm(memory[:, idx] - first[idx], axis=-1).max(axis=1) * self._scale_of(name)
                still = np.flatnonzero(away <= 0.25 * self.params["min_move"])
                onset = int(still[-1]) if len(still) else 0
            self._track(name, onset)
            if not self.params["together"]:
                return

    def _moved(self, names: list[str], first: np.ndarray, last: np.ndarray) -> dict[str, float]:
        """How far (m; a hand's radians scaled) each subsystem's parts have moved at most from ``first`` to ``last``."""
        far = _norms(last - first)  # every part at once (the same values as part by part)
        return {name: float(np.fmax.reduce(far[idx])) * self._scale_of(name)  # np.nanmax without its warning
                for name, idx in self.motor.subsystems.items() if name in names}

    def _joining(self, memory: np.ndarray) -> bool:
        """Whether a subsystem not yet followed has begun to move (half of ``min_move``): the decision waits for it."""
        if not self.params["together"]:
            return False
        waiting = [n for n in self.motor.subsystems if n not in self.tracks]
        if not waiting:
            return False
        moved = self._moved(waiting, memory[:3].mean(axis=0), memory[-3:].mean(axis=0))
        return any(d > 0.5 * self.params["min_move"] for d in moved.values())

    def _track(self, name: str, onset: int) -> None:
        scale = self._scale_of(name)
        start = self._where(name, self._at(onset)[self.motor.subsystems[name]])
        # a command that moves no part farther than min_move (standing still) cannot be seen to begin
        candidates = {(edge.name,): 0.0 for edge in self.motor.edges_from(name, start)
                      if self._length(edge.name) * scale > self.params["min_move"]}
        self.tracks[name] = Track(name, scale, self.motor.is_hand(name), start, onset, candidates,
                                  sorted(p[0] for p in candidates), last_correct=start, learn_from=onset)

    def _where(self, name: str, seen: np.ndarray) -> str:
        """The node a subsystem's demonstration begins in: the active node or the hub, whichever state is nearer
        to where the parts were seen at the onset (``seen``, (k, 3)).

        The active node is where the last movement the matcher followed ended; a demonstrator who went back to
        the hub without being followed (a movement that was not recognised, a posture that differed from the
        observer's own at its end) begins his next movement there.
        """
        active = self.motor.active_node(name)
        if active == "hub" or not np.isfinite(seen).any():
            return active
        far = [self._distance_to(name, self.motor.state(name, n), seen) for n in (active, "hub")]
        return active if far[0] <= far[1] else "hub"

    def _distance_to(self, name: str, state: np.ndarray, seen: np.ndarray) -> float:
        """How far the parts seen (k, 3) are from a state of subsystem ``name``: the largest part's distance (parts
        never seen left out)."""
        return float(np.nanmax(np.linalg.norm(state - seen, axis=-1) * self._scale_of(name)))

    def _observed(self, track: Track, memory: np.ndarray) -> np.ndarray:
        """The working memory of a subsystem's parts since it is followed, (n, k, 3).

        Of the working memory :meth:`_local` gave last, or of its first rows (a replay after a deviation,
        :meth:`_repredict`, feeds them one more at a time), the rows are gathered once each and kept (a view)."""
        idx = self.motor.subsystems[track.subsystem]
        if memory is None or (memory is not self._last_local and not self._leading(memory)):
            return memory[track.onset:, idx]
        n = len(memory) - track.onset
        kept = self._tracked.get(track.subsystem)
        if kept is None or kept.track is not track:
            kept = self._tracked[track.subsystem] = _Tracked(track, _Grown((len(idx), 3)), _Walk(len(idx)))
        rows = kept.rows
        if rows.n > n:  # fewer rows than kept (not a replay's next row): gathered whole, not kept
            return memory[track.onset:, idx]
        if rows.n < n:
            rows.extend(memory[track.onset + rows.n :, idx])
        kept.last = rows.view()
        return kept.last

    def _leading(self, memory: np.ndarray) -> bool:
        """Whether ``memory`` is the first rows of the working memory :meth:`_local` gave last (a view of them, so
        the same values)."""
        local = self._last_local
        if local is None or memory.base is None or memory.base is not local.base or len(memory) > len(local):
            return False
        return memory.strides == local.strides and memory.shape[1:] == local.shape[1:] and \
            memory.__array_interface__["data"][0] == local.__array_interface__["data"][0]

    def _walked(self, track: Track, observed: np.ndarray) -> np.ndarray:
        """``_lengths(observed)`` of the rows :meth:`_observed` gave last for ``track``, frame by frame (:class:`_Walk`:
        the same values, a few rows' work a frame); of other rows, computed whole."""
        kept = self._tracked.get(track.subsystem)
        if kept is None or kept.track is not track or kept.last is not observed:
            return _lengths(observed)
        return kept.walk.lengths(observed)

    def _follow(self, track: Track, memory: np.ndarray) -> Match | None:
        """One frame of a subsystem's predictions (Fig. 3); a :class:`Match` with ``stop`` when its imitation deviates."""
        if track.committed is None and not track.candidates:  # nothing left to predict (as below, without the work)
            return None
        observed = self._observed(track, memory)
        lengths = self._walked(track, observed)  # once per frame (incremental)
        last = observed[-1]
        frame = self._memory.n - 1
        if track.committed is not None:
            error = self._error(track, track.committed_path,
                                self._clock(track, track.committed_path, lengths, len(observed)), last)
            track.trace.append((frame, {track.committed_path: error}))
            if error <= self.params["deviation"]:
                return None
            return self._deviate(track, lengths, memory)  # Fig. 3: stop, exclude the edge, predict again
        if not track.candidates:
            return None
        n = len(observed)
        paths = self._extended(track, lengths, n)
        if self.params["reparameterise"]:  # the clock is the path length observed: every candidate at once
            errors = self._errors(track, paths, lengths, last)
        else:
            errors = {path: self._error(track, path, self._clock(track, path, lengths, n), last) for path in paths}
        track.trace.append((frame, errors))
        alive = self._survivors(errors)
        if len(alive) > self.params["max_candidates"]:  # keep the best predictions
            alive = dict(sorted(alive.items(), key=lambda kv: kv[1])[: self.params["max_candidates"]])
        track.candidates = alive
        if alive and len({self._movement_key(p) for p in alive}) == 1:  # one first command (or movement) prevails
            path = min(alive, key=alive.get)
            along = self._along(track, path[0], self._clock(track, path, lengths, n))
            progress = self._progress(path[0], along)
            if (progress >= self.params["min_progress"] or len(path) > 1) and self._timed(track, observed):
                self._commit(track, path, along, progress, len(observed), alive[path])
        return None

    def _commit(self, track: Track, path: tuple[str, ...], along: np.ndarray, progress: float, n_observed: int,
                error: float) -> None:
        """Commit a subsystem to candidate ``path`` (the whole learned sequence it begins), at the speed seen."""
        track.committed_path = self._known_continuation(path)
        track.committed = self.motor.add_sequence(list(track.committed_path))
        track.committed_at = self._memory.n
        track.speed = self._speed(track, path, n_observed)
        track.progress = progress
        track.confidence = float(np.exp(-error / self.params["threshold"]))

    # -- drop-out (K&G §4.4, Fig. 3) ----------------------------------------------------------------

    def _survivors(self, errors: Mapping[tuple[str, ...], float]) -> dict[tuple[str, ...], float]:
        """The candidates (paths and their prediction errors this frame) that do not drop out: those whose
        prediction error is within ``threshold``."""
        threshold = self.params["threshold"]
        return {path: error for path, error in errors.items() if error <= threshold}

    def _last_correct(self, track: Track, lengths: np.ndarray, memory: np.ndarray) -> None:
        """The node at which the demonstration last agreed with the committed path: the start of the edge it was on.

        That edge is excluded from the segment's predictions (Fig. 3); the edges before it were followed correctly
        and join ``right``. Predicting again, and learning, start from the frame the demonstration passed the node
        (with ``reparameterise`` off, the frame the path reached it at its own speed).
        """
        from scipy.ndimage import uniform_filter1d

        path = track.committed_path
        lead = self._lead(path[0])
        observed = self._observed(track, memory)
        clock = self._clock(track, path, lengths, len(observed))
        arcs = np.cumsum([self._edge(e).arcs[lead, -1] for e in path])
        joined = self._anchor(track, path[0])[lead]
        on = int(np.searchsorted(arcs, clock[lead] + joined - 0.01 / track.scale))
        on = min(on, len(path) - 1)
        track.last_correct = self.motor.edge(path[on]).source
        track.excluded.add(path[on])
        if not on:
            return
        track.right = (*track.right, *path[:on])  # the part that was right
        if self.params["reparameterise"]:
            walked = _arc(uniform_filter1d(observed[:, lead], size=3, axis=0, mode="nearest"))
            row = int(np.searchsorted(walked, arcs[on - 1] - joined))
        else:  # when the commands, at their own speed, reached the node
            reached = sum(self.motor.edge(e).duration for e in path[:on])
            row = int(round((reached - self._mapped_time(self._strokes_of(path[0])[lead], joined)) * self.fps))
        track.learn_from = track.onset + min(max(row, 0), len(observed) - 1)

    def _scale_of(self, subsystem: str) -> float:
        """Metres one unit of the subsystem's values counts as: ``angle_scale`` for a hand's radians, else 1 (kept
        per subsystem while its parts are the same)."""
        parts = self.motor.subsystems.get(subsystem)
        kept = self._scales.get(subsystem)
        if kept is None or kept[0] is not parts:
            kept = self._scales[subsystem] = (parts, self.params["angle_scale"] if self.motor.is_hand(subsystem)
                                              else 1.0)
        return kept[1]

    def _length(self, name: str) -> float:
        """Path length (m, or radians for a hand) of a command's lead part."""
        edge = self._edge(name)
        return float(edge.arcs[edge.lead, -1])

    def _strokes_of(self, name: str) -> list[Any]:
        return self.motor.edge(name).commands

    def _lead(self, name: str) -> int:
        """The part of the subsystem that moves farthest along a command: progress and speed are measured on it."""
        return self._edge(name).lead

    def _edge(self, name: str) -> _EdgeTable:
        """Every part's stroke of command ``name`` on the fine grid, stacked (computed once per command)."""
        commands = self._strokes_of(name)
        table = self._edges.get(name)
        if table is None or table.commands is not commands:
            tables = [self._table(stroke) for stroke in commands]
            arcs = np.stack([arc for _, _, arc in tables])
            lead = int(np.argmax(arcs[:, -1]))
            table = _EdgeTable(commands, np.stack([positions for _, positions, _ in tables]), arcs, lead)
            self._edges[name] = table
        return table

    def _table(self, stroke: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(times, positions, cumulative path length) of a stroke on a fine grid, computed once per stroke."""
        table = self._tables.get(id(stroke))
        if table is None or table[0] is not stroke:
            grid = np.linspace(0.0, stroke.duration, self.GRID)
            positions = stroke.position(grid)
            table = (stroke, grid, positions, _arc(positions))
            self._tables[id(stroke)] = table
        return table[1], table[2], table[3]

    def _extended(self, track: Track, lengths: np.ndarray, n: int | None = None) -> list[tuple[str, ...]]:
        """Candidate paths whose commands have all been covered by the observation continue along every edge of
        their end node but those excluded for this segment (Fig. 3: an edge that failed predicts no more).

        ``lengths`` holds the observed path length of each part of the subsystem, ``n`` the frames observed
        (:meth:`_clock`; ``None``: as many as the path lengths say).
        """
        paths = list(track.candidates)
        if (n is None or self.params["reparameterise"]) and not track.hand and len(paths) > 1 and \
                all(len(path) == 1 for path in paths):
            return self._extended_at_once(track, paths, lengths)
        out = []
        for path in paths:
            lead = self._lead(path[0])
            seen = self._along(track, path[0], lengths if n is None else self._clock(track, path, lengths, n))[lead]
            total = sum(self._edge(e).arcs[lead, -1] for e in path)
            out.extend(self._next(track, path) if seen > total + 0.01 / track.scale else [path])
        return out

    def _extended_at_once(self, track: Track, paths: list[tuple[str, ...]],
                          lengths: np.ndarray) -> list[tuple[str, ...]]:
        """:meth:`_extended` of one-command paths (the common case) of a positional subsystem, at once, from the
        strokes stacked for :meth:`_errors`: each path's lead part's observed length plus its anchor, against the lead's
        stroke length (the same values, element by element, as path by path)."""
        names = tuple(path[0] for path in paths)
        _, totals, leads, anchors = self._stacked(track, names)
        rows = np.arange(len(names))
        passed = lengths[leads] + anchors[rows, leads] > totals[rows, leads] + 0.01 / track.scale
        if not passed.any():
            return paths
        out = []
        for path, past in zip(paths, passed.tolist()):
            out.extend(self._next(track, path) if past else [path])
        return out

    def _next(self, track: Track, path: tuple[str, ...]) -> list[tuple[str, ...]]:
        """A path whose commands have all been covered, continued along each edge of its end node that it does not
        hold and that is not excluded (itself when there is none)."""
        end = self.motor.edge(path[-1]).target
        nxt = [edge.name for edge in self.motor.edges_from(track.subsystem, end)]
        return [(*path, e) for e in nxt if e not in path and e not in track.excluded] or [path]

    def _path_label(self, path: tuple[str, ...]) -> str | None:
        """The labelled movement (clip repertoires) every sequence along ``path`` is an example of, else ``None``."""
        return self.motor.label_of_path(path)

    def _movement_key(self, path: tuple[str, ...]) -> str:
        """What a candidate stands for: the labelled movement its sequences are examples of, else its first command.

        Kept per path while the motor system's labels are the same table of the same size (only labelled sequences
        name a movement, and a labelled sequence is added with its label; :meth:`_ranked` asks for every path a
        segment predicted)."""
        labels = getattr(self.motor, "labels", None)
        if not isinstance(labels, dict):
            label = self._path_label(path)
            return label if label is not None else path[0]
        version = (id(labels), len(labels))
        if self._key_version != version:
            self._keys, self._key_version = {}, version
        key = self._keys.get(path)
        if key is None:
            label = self._path_label(path)
            key = self._keys[path] = label if label is not None else path[0]
        return key

    def _known_continuation(self, path: tuple[str, ...]) -> tuple[str, ...]:
        """The whole learned command sequence that ``path`` begins, else ``path`` itself."""
        return self.motor.known_sequence(path)

    def _mapped_time(self, stroke: Any, length: float) -> float:
        """The stroke time at which it has covered ``length`` metres of path (the speed-free forward model)."""
        grid, _, arc = self._table(stroke)
        return float(np.interp(min(length, arc[-1]), arc, grid))

    def _predict(self, track: Track, path: tuple[str, ...], lengths: np.ndarray) -> np.ndarray:
        """Where each part of the subsystem should be after as much path as it has been observed to cover.

        The fingers of a hand share their timing (one transition function, §4.2): they are all predicted at the
        time at which the lead finger has covered its observed path, so fingers that move in another order than
        the command's do not fit it.
        """
        if track.hand:
            lead = self._lead(path[0])
            left = lengths[lead]
            for i, name in enumerate(path):
                commands = self._strokes_of(name)
                arc = self._table(commands[lead])[2]
                if left <= arc[-1] or i == len(path) - 1:
                    t = self._mapped_time(commands[lead], left)
                    return np.array([c.position(t) for c in commands])
                left -= arc[-1]
        if len(path) == 1:  # one command: every part along its stroke (what the loop below does for one edge)
            edge = self._edge(path[0])
            return _along_rows(edge.arcs, edge.positions, np.minimum(lengths, edge.arcs[:, -1]))
        # each part along its own strokes: on the first edge whose stroke is longer than what is left to place
        out = np.empty((len(lengths), 3))
        left = np.array(lengths, dtype=float)
        open_ = np.ones(len(left), dtype=bool)
        for i, name in enumerate(path):
            edge = self._edge(name)
            total = edge.arcs[:, -1]
            here = open_ & ((left <= total) | (i == len(path) - 1))
            if here.all():  # every part on this edge: its strokes as they are (no copy)
                out[:] = _along_rows(edge.arcs, edge.positions, np.minimum(left, total))
                open_[:] = False
            elif here.any():
                out[here] = _along_rows(edge.arcs[here], edge.positions[here], np.minimum(left[here], total[here]))
                open_ &= ~here
            if not open_.any():
                break
            left = np.where(open_, left - total, left)
        return out

    def _error(self, track: Track, path: tuple[str, ...], lengths: np.ndarray, last: np.ndarray) -> float:
        """Distance between the path's prediction and the parts' last observed positions ``last`` (k, 3): the
        largest over the parts (:meth:`_distance`)."""
        return self._distance(track, self._predict(track, path, self._along(track, path[0], lengths)), last)

    def _errors(self, track: Track, paths: list[tuple[str, ...]], lengths: np.ndarray,
                last: np.ndarray) -> dict[tuple[str, ...], float]:
        """:meth:`_error` of every candidate path, in their order: the one-command paths of a positional subsystem
        predicted at once (their strokes stacked part by part, :meth:`_stacked`; the same arithmetic row by row, so
        the same values), the others one by one."""
        batch = [] if track.hand else [path for path in paths if len(path) == 1]
        errors: dict[tuple[str, ...], float] = {}
        if len(batch) > 1:
            rows, totals, _, anchors = self._stacked(track, tuple(path[0] for path in batch))
            k = len(lengths)
            along = np.minimum(lengths + anchors, totals)  # (C, k): _along, then _predict's minimum
            predicted = self._stroke_rows.along(rows, along.reshape(-1)).reshape(len(batch), k, 3)
            d = _norms(predicted - last) * track.scale
            errors = dict(zip(batch, d.max(axis=1).tolist()))  # the largest part error of each
        return {path: errors[path] if path in errors else self._error(track, path, lengths, last) for path in paths}

    def _stacked(self, track: Track, names: tuple[str, ...]) -> tuple[np.ndarray, ...]:
        """For commands ``names`` followed by ``track``: their strokes' rows in the table of every stroke
        (:class:`_StrokeRows`, C * k), stroke lengths (C, k), lead parts (C,) and anchors (C, k), stacked once per
        set of candidates (kept until the set changes; the rows, lengths and leads for the last sets of candidates
        of any track)."""
        kept = self._tracked.get(track.subsystem)
        cache = getattr(kept, "stacked", None) if kept is not None and kept.track is track else None
        if cache is not None and cache[0] == names:
            return cache[1]
        edges = [self._edge(name) for name in names]
        strokes = self._stroke_tables.get(names)
        if strokes is None or not all(a is b for a, b in zip(strokes[0], edges)):
            table = self._stroke_rows
            rows = np.concatenate([table.rows(n, e) + np.arange(len(e.arcs)) for n, e in zip(names, edges)])
            strokes = (edges, (rows, np.stack([e.arcs[:, -1] for e in edges]), np.array([e.lead for e in edges])))
            self._stroke_tables[names] = strokes
            if len(self._stroke_tables) > 64:
                self._stroke_tables.popitem(last=False)
        else:
            self._stroke_tables.move_to_end(names)
        stacked = (*strokes[1], self._anchors(track, names))
        if kept is not None and kept.track is track:
            kept.stacked = (names, stacked)
        return stacked

    def _along(self, track: Track, name: str, lengths: np.ndarray) -> np.ndarray:
        """How far along a path beginning with command ``name`` each part is: the observed path length plus
        where the demonstration joined the command (:meth:`_anchor`)."""
        return lengths + self._anchor(track, name)

    def _anchors(self, track: Track, names: tuple[str, ...]) -> np.ndarray:
        """:meth:`_anchor` of each of commands ``names``, stacked (C, k): taken from the anchors placed when the track
        began (their rows, gathered: the same values) when all of them were placed then, else stacked one by one."""
        self._anchor(track, names[0])  # places the track's candidates, if not yet
        placed = track.placed
        if placed is not None:
            rows = [placed[0].get(name, -1) for name in names]
            if min(rows) >= 0:
                return placed[1][rows]
        return np.stack([self._anchor(track, n) for n in names])

    def _anchor(self, track: Track, name: str) -> np.ndarray:
        """Where, along each part's stroke of command ``name`` (path length), the demonstration was first seen.

        A segment often begins a little after the movement did (a hub threshold is crossed once the body has
        left the hub; a stream starts in motion): each part is placed at the point of the first half of its
        stroke nearest to where it was seen at the track's onset, and predicted from there (0 when it was seen
        at the stroke's start). A hand's fingers share one clock: they are followed from the start (0).
        """
        anchor = track.anchors.get(name)
        if anchor is None:
            if track.hand:
                anchor = track.anchors[name] = np.zeros(len(self._edge(name).arcs))
                return anchor
            # this command's and those of the track's other candidates still without one, at once (all are placed
            # in the frame the track begins: the same onset posture)
            firsts = dict.fromkeys([name, *(path[0] for path in track.candidates)])
            names = [n for n in firsts if n not in track.anchors]
            halves = self._halves(tuple(names))
            first = self._first(track)
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

    def _halves(self, names: tuple[str, ...]) -> _Halves:
        """The first halves of commands ``names``' strokes, stacked for :meth:`_anchor` (:class:`_Halves`). Kept for
        the last sets of candidates (a node's edges are the candidates of every demonstration that starts there)."""
        tables = [self._edge(name) for name in names]
        kept = self._half_tables.get(names)
        if kept is not None and all(a is b for a, b in zip(kept[0], tables)):
            self._half_tables.move_to_end(names)
            return kept[1]
        halves = _Halves(np.stack([t.arcs for t in tables]), np.stack([t.positions for t in tables]))
        self._half_tables[names] = (tables, halves)
        if len(self._half_tables) > 32:
            self._half_tables.popitem(last=False)
        return halves

    def _first(self, track: Track) -> np.ndarray:
        """The subsystem's parts where they were seen at the track's onset (k, 3)."""
        if track.first is not None:
            return track.first
        return self._at(track.onset)[self.motor.subsystems[track.subsystem]]

    def _distance(self, track: Track, predicted: np.ndarray, observed: np.ndarray) -> float:
        """The prediction error: the largest of the per-part distances (k, 3 each; radians of a hand scaled), as K&G
        compare the wrist (§4.4)."""
        return float((_norms(predicted - observed) * track.scale).max())

    def _progress(self, name: str, along: np.ndarray) -> float:
        """The share of command ``name``'s time its lead part has covered, ``along`` its path."""
        lead = self._lead(name)
        stroke = self._strokes_of(name)[lead]
        return self._mapped_time(stroke, along[lead]) / stroke.duration

    def _speed(self, track: Track, path: tuple[str, ...], n_frames: int) -> float:
        """How much faster than the commands of ``path`` the demonstration goes (1: same speed), K&G §4.4: "map the
        length of the movement seen so far onto the trajectory predicted by a forward model, yielding the time
        parameter at which the corresponding motor command (with the speed demonstrated at first) would have
        produced a movement of the same length".

        The ``n_frames`` rows observed since the track's onset are matched with the path as it was first
        demonstrated (:meth:`_shown`) played from time ``c`` at ``s`` times its speed: the positions of the
        :attr:`SPEED_PARTS` parts that move farthest along its first command (a hand: its fingers, which share one
        clock), each taken relative to its mean over the frames (so a stance unlike one's own does not count), in
        the least squares sense. ``s`` is the speed factor: first the best of a grid on the part that moves farthest
        (``s`` from 0.25 to 4 in steps of 12%, ``c`` from half a second before the path's start to the end of its
        first edge, a frame apart), then refined on every part by three grids about the best, each five times
        finer (to 0.1% of speed). Positions, not path lengths
        walked, are compared: observation noise adds length at every frame, and smoothing it away would stretch
        the movement's onset by the same frames whatever its speed. 1 with ``reparameterise`` off (the paper's
        baseline: a command is predicted at the speed it was learned), or with fewer than three frames.
        """
        if not self.params["reparameterise"] or n_frames < 3:
            return 1.0
        arcs = self._edge(path[0]).arcs[:, -1]
        parts = np.argsort(-arcs)[: self.SPEED_PARTS]  # the parts that move farthest (a hand: every finger)
        idx = self.motor.subsystems[track.subsystem][parts]  # the rows in the motor frame, as _local places them
        seen = self._memory.positions[track.onset: track.onset + n_frames, idx] + self._root_height[idx]
        if not np.isfinite(seen).all():
            return 1.0
        times, points, first = self._shown(path, parts)
        seen = seen - seen.mean(axis=0)
        t = np.arange(n_frames) / self.fps
        flat = points.reshape(len(points), -1)

        def played(c: np.ndarray, s: np.ndarray, columns: int) -> np.ndarray:  # (G,) starts, speeds -> (G, n, m)
            q = (c[:, None] + s[:, None] * t).ravel()
            out = np.stack([np.interp(q, times, flat[:, d]) for d in range(columns)], axis=-1)
            out = out.reshape(len(c), len(t), columns)
            return out - out.mean(axis=1, keepdims=True)  # centred

        seen = seen.reshape(n_frames, -1)
        # the grid on the part that moves farthest, every 1/fps of start and 12% of speed; refined on every part
        speeds = np.geomspace(0.25, 4.0, 25)
        starts = np.arange(-0.5, first + 1.0 / self.fps, 1.0 / self.fps)
        c, s = (a.ravel() for a in np.meshgrid(starts, speeds))
        best = int(np.argmin(((played(c, s, 3) - seen[:, :3]) ** 2).sum(axis=(1, 2))))
        c0, s0, dc, ds = c[best], s[best], 1.0 / self.fps, np.log(speeds[1] / speeds[0])
        for _ in range(3):  # finer grids about the best, on every part: each a fifth of the step before
            cs, ls = np.meshgrid(c0 + dc * np.linspace(-1, 1, 11), np.log(s0) + ds * np.linspace(-1, 1, 11))
            cs, ss = cs.ravel(), np.clip(np.exp(ls.ravel()), 0.25, 4.0)
            best = int(np.argmin(((played(cs, ss, seen.shape[1]) - seen) ** 2).sum(axis=(1, 2))))
            c0, s0, dc, ds = cs[best], ss[best], dc / 5, ds / 5
        return float(s0)

    SPEED_PARTS = 5
    """The most parts a speed is measured on (those that move farthest)."""

    MIN_MOVING_FRAMES = 3
    """Frames of movement a speed is measured from (:meth:`_timed`)."""

    def _timed(self, track: Track, observed: np.ndarray) -> bool:
        """Whether enough of the movement has been seen to measure its speed (:meth:`_speed`): with
        ``reparameterise``, :attr:`MIN_MOVING_FRAMES` frames on which the subsystem's parts are away from where they
        were at the onset by more than a quarter of ``min_move`` (with one or two, how fast it goes and when it
        began cannot be told apart). A commitment waits for them: a frame or two, for a fast movement."""
        if not self.params["reparameterise"]:
            return True
        away = _norms(observed - observed[0]).max(axis=1) * track.scale
        return int((away > 0.25 * self.params["min_move"]).sum()) >= self.MIN_MOVING_FRAMES

    def _shown(self, path: tuple[str, ...], parts: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """The trajectories of ``parts`` (indices into the subsystem's parts) along ``path`` as it was first
        demonstrated: times (M,) and positions (M, p, 3), the edges laid end to end, and the time the first edge
        ends. An edge learned by watching keeps the piece of the demonstration it was learned from
        (``Edge.shown``); one without it (written by hand, or saved without) stands for its commands played at
        their own speed, each part holding its target once its command has ended."""
        times, points, t0, first = [], [], 0.0, 0.0
        for i, name in enumerate(path):
            edge = self.motor.edge(name)
            shown = getattr(edge, "shown", None)
            if shown is not None and getattr(edge, "shown_fps", 0.0) > 0:
                p, t = shown[:, parts], np.arange(len(shown)) / edge.shown_fps
            else:
                t = np.linspace(0.0, edge.duration, max(2, int(np.ceil(edge.duration * 120.0)) + 1))
                p = np.stack([edge.commands[j].position(np.minimum(t, edge.commands[j].duration)) for j in parts],
                             axis=1)
            times.append(t + t0)
            points.append(p)
            t0 += float(t[-1])
            if i == 0:
                first = t0
        times_all, points_all = np.concatenate(times), np.concatenate(points)
        keep = np.append(np.diff(times_all) > 1e-9, True)  # where two edges meet, the later's first frame
        return times_all[keep], points_all[keep], first

    # -- the end of the demonstration ------------------------------------------------------------

    def conclude(self, motion: Motion) -> Match | None:
        """The demonstration has ended: check each subsystem's commitment against where it ended, learn the rest.

        A subsystem whose committed path ended where the demonstration did is in the path's end node. One that
        deviated (now, or while imitating) goes back to its last correct node and the rest of its movement is
        learned by the inverse model (true imitation, §4.3), as is the movement of a subsystem no edge predicted.
        Whatever was not yet imitated is returned as one movement (several subsystems: performed together).
        """
        if self._memory is None:  # concluded without having followed the segment: follow it now, frame by frame
            return follow(self, motion)[1]
        try:
            return self._conclude()
        finally:
            self._memory = None  # the next segment begins anew

    def _conclude(self) -> Match | None:
        if not self.tracks:
            return Match.unknown("nothing moved", details={"reason": "nothing moved"})
        memory = self._local()
        perform, learned, paths, route = [], [], [], []  # route: every edge from the start node (the label's)
        first_from, first_to = None, None
        for name in list(self.tracks):
            track = self._settle(self.tracks[name], memory)
            if track.committed is not None and not track.deviated:  # its commitment held (or won the race)
                self.motor.move_to(track.subsystem, self.motor.edge(track.committed_path[-1]).target, posture=False)
                if not track.reported:  # recognised, but not imitated yet (recognised at the end, or another
                    # subsystem had to be learned): at the speed measured over the whole demonstration
                    track.speed = self._speed(track, track.committed_path, len(self._observed(track, memory)))
                    perform.append(track.committed)
                    paths.extend(track.committed_path)
                    route.extend(track.committed_path)
                continue
            # it deviated (now, or while followed) or was never committed: from where the body is, the start node or
            # the last correct node it went back to, it performs what was right and not performed yet, then the
            # rest: along the edge that explains it when one does (Fig. 3's loop), else what is learned
            self.motor.move_to(track.subsystem, track.home or track.start_node)
            before = list(track.right[track.at:])
            names: list[str] = []
            if track.committed is not None:  # another known edge explains the rest: nothing is learned
                track.speed = self._speed(track, track.committed_path, len(self._observed(track, memory)))
                rest = list(track.committed_path)
            else:
                names = self._learn(track, memory) if self.params["learn"] else []
                if not names:
                    continue
                rest = names
                if track.right:  # the part that was right, then the new one
                    self.motor.add_sequence([*track.right, *names])
            edges = [*before, *rest]
            end = self.motor.edge(edges[-1]).target
            self.motor.move_to(track.subsystem, end, posture=False)
            perform.append(self.motor.add_sequence(edges))
            paths.extend(edges)
            route.extend([*track.right, *rest])
            learned.extend(names)
            if first_from is None:
                first_from, first_to = track.last_correct, end
        if not perform:
            if self.reported:
                return None  # already reported when it committed
            details = {"reason": "no edge predicts the demonstration", **self._nearest()}
            return Match(None, 0.0, None, (), details, candidates=self._ranked(self.main), reason=details["reason"],
                         nearest=details.get("nearest"), score=details.get("error_when_dropped"),
                         measure="prediction error of the nearest when it was dropped")
        movement = self.motor.add_together(perform)
        main = self.main
        tracks = list(self.tracks.values())
        details: dict[str, Any] = {"candidates": [c for t in tracks for c in t.initial],
                                   "deviated": any(t.deviated for t in tracks)}
        if details["deviated"]:  # the edges that failed, excluded from the segment's predictions (Fig. 3)
            details["excluded"] = sorted(e for t in tracks for e in t.excluded)
        if learned:
            details.update({"learned": learned, "from": first_from, "to": first_to})
        else:  # recognised only at the end, or again from the last correct node after a deviation
            details.update({"speed": main.speed, "progress": main.progress})
            if first_from is not None:
                details.update({"from": first_from, "to": first_to})
        if len(perform) > 1:
            details["subsystems"] = {self.motor.subsystem_of(m): m for m in perform}
        label = movement if len(perform) > 1 else (self._path_label(tuple(route)) or self.motor.label(movement))
        ranked = self._ranked(main, label, main.committed_path) if len(tracks) == 1 and not learned and \
            main.committed is not None else ()
        return Match(label, 1.0 if learned else min(t.confidence for t in tracks if t.committed),
                     None, tuple(paths), details=details, candidates=ranked)

    def _learn(self, track: Track, memory: np.ndarray) -> list[str]:
        """Cut a subsystem's working memory since its last correct node into strokes, one edge each, chained from it.

        A subsystem followed from a later onset than the first is learned up to where it came to rest.
        """
        observed = memory[track.learn_from:, self.motor.subsystems[track.subsystem]]
        if (track.onset if track.origin is None else track.origin) > 0 and len(observed) > 3:
            # it may have stopped before the others did
            away = np.linalg.norm(observed - observed[-1], axis=-1).max(axis=1) * track.scale
            moving = np.flatnonzero(away > 0.25 * self.params["min_move"])
            observed = observed[: (int(moving[-1]) + 2 if len(moving) else len(observed))]
        if len(observed) < 3:
            return []
        return self.motor.learn_observed(track.subsystem, track.last_correct, observed, self.fps, criteria=self._criteria)

    def match(self, motion: Motion) -> Match:
        """Batch use: the whole segment at once (no facilitation): followed frame by frame, then concluded."""
        early, late = follow(self, motion)
        return late or early or Match.unknown()

    # -- Fig. 3's loop after a deviation, and the speed (K&G §4.4) -------------------------------------

    def _deviate(self, track: Track, lengths: np.ndarray, memory: np.ndarray) -> Match | None:
        """The demonstration deviates from the committed path (Fig. 3): the edge it was on is excluded from this
        segment's predictions, the imitation is stopped (the first time; the subsystem returns to the last correct
        node), and the rest is predicted again from the last correct node (:meth:`_repredict`).

        Returns a :class:`Match` with ``stop`` when an imitation under way was stopped.
        """
        track.deviated = True
        if track.deviated_at is None:
            track.deviated_at = len(memory)
        self._last_correct(track, lengths, memory)
        track.failed.append((track.committed, track.committed_path))
        stop = None
        if track.reported and not track.stopped:
            # stop the imitation; the others' commands were right and are completed by the motor system
            track.stopped, track.home, track.at = True, track.last_correct, len(track.right)
            self.motor.move_to(track.subsystem, track.last_correct)
            stop = Match(track.committed, 0.0, len(memory), stop=True, reason="deviation", details={
                "stop": True, "reason": "deviation", "subsystem": track.subsystem, "return_to": track.last_correct})
        self._repredict(track, memory)
        return stop

    def _repredict(self, track: Track, memory: np.ndarray) -> None:
        """Fig. 3's loop: "edges <- motor commands that can predict the observed movement", again, from the last
        correct node. A new :class:`Track` follows the subsystem from the row at which the demonstration passed
        that node, with the edges leaving it as candidates but those excluded; it keeps what the segment has
        established (the edges that were right, the excluded ones, whether the imitation was stopped, the trace).
        The rows seen since are followed again one by one, so a candidate drops out, or prevails and is committed
        to (and checked, and may deviate in turn), as if it had been followed from there. What no edge explains
        is learned at the end (:meth:`_conclude`), and only that.
        """
        node, name = track.last_correct, track.subsystem
        candidates = {(edge.name,): 0.0 for edge in self.motor.edges_from(name, node)
                      if edge.name not in track.excluded and self._length(edge.name) * track.scale > self.params["min_move"]}
        again = Track(name, track.scale, track.hand, node, track.learn_from, candidates, track.initial,
                      excluded=track.excluded, reported=track.reported, deviated=True, last_correct=node,
                      right=track.right, learn_from=track.learn_from, trace=track.trace,
                      committed_at=track.committed_at, deviated_at=track.deviated_at, stopped=track.stopped,
                      home=track.home or track.start_node, at=track.at, failed=track.failed,
                      begun=track.begun or track,
                      origin=track.onset if track.origin is None else track.origin)
        self.tracks[name] = again
        now = self._memory.n
        for row in range(again.onset + 1, len(memory)):  # what has been seen since the node, frame by frame
            current, seen = self.tracks[name], len(track.trace)
            self._follow(current, memory[: row + 1])
            for k in range(seen, len(track.trace)):  # the frame each replayed prediction belongs to
                frame, errors = track.trace[k]
                if frame == now - 1:
                    track.trace[k] = (row, errors)
            current = self.tracks[name]
            if current.committed is not None and current.committed_at == now:
                current.committed_at = row + 1

    def _settle(self, track: Track, memory: np.ndarray) -> Track:
        """At the end of the demonstration: a subsystem's commitment must end where the demonstration did; while
        it does not, it deviated (:meth:`_deviate`: the last correct node, the edge excluded, the rest predicted
        again). Returns the subsystem's track as it is then."""
        while track.committed is not None and not self._ended(track, memory):
            self._deviate(track, _lengths(self._observed(track, memory)), memory)
            track = self.tracks[track.subsystem]
        return track

    def _ended(self, track: Track, memory: np.ndarray) -> bool:
        """Whether the demonstration ended (the last row of ``memory``) where the committed path does."""
        end = self.motor.edge(track.committed_path[-1]).target
        expected = self.motor.state(track.subsystem, end)
        seen = memory[-1, self.motor.subsystems[track.subsystem]]
        return self._distance(track, expected, seen) <= self.params["deviation"]

    def _clock(self, track: Track, path: tuple[str, ...], lengths: np.ndarray, n: int) -> np.ndarray:
        """How far along ``path`` each part of the subsystem is predicted: with ``reparameterise`` (K&G §4.4) the
        path length observed (``lengths``, so the prediction does not depend on the speed); off, the path length
        the part's commands cover, at their own speed, in the time the ``n`` frames observed took (from where the
        demonstration joined the path, :meth:`_anchor`): the forward model of Fig. 3 without re-parameterisation,
        which a familiar movement at another speed does not fit."""
        if self.params["reparameterise"]:
            return lengths
        elapsed = (n - 1) / self.fps
        anchor = self._anchor(track, path[0])
        out = np.empty(len(lengths))
        for p in range(len(lengths)):
            t = self._mapped_time(self._strokes_of(path[0])[p], anchor[p]) + elapsed
            covered = 0.0
            for i, name in enumerate(path):
                edge = self.motor.edge(name)
                grid, _, arc = self._table(edge.commands[p])
                if t <= edge.duration or i == len(path) - 1:
                    covered += float(np.interp(t, grid, arc))
                    break
                t -= edge.duration
                covered += float(arc[-1])
            out[p] = covered - anchor[p]
        return out


@hookimpl
def likeme_register_matchers():
    return [ForwardModel]
