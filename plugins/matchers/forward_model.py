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

Drop-out relative to the other candidates (issue 18; not in the paper, which leaves the correspondence problem
open, §6): the paper's drop-out (``dropout = "absolute"``, the default) compares each candidate's prediction
error with one fixed ``threshold``, set for the wrist of a body like one's own. Another person's stance and style
put every prediction off by about as much from the first frame (a styled bow is 10-15 cm from every candidate at its
onset on a 1.5 m body), so on real clips every candidate drops out and nothing is committed. With
``dropout = "relative"`` the candidates race: a candidate drops out when its error exceeds ``ratio`` times the best
living candidate's. What all candidates share (the stance, the body) cancels in the ratio; what tells them apart (the
movement) does not. The ratio has no unit, so it holds for any body and skeleton; 1.5 means "half again as far off
as the best", a clear lead and not a matter of noise. Two refinements follow from what the quantities mean:

- errors under ``min_move`` count as ``min_move``: predictions that differ by less than the smallest displacement
  that counts as a movement cannot be told apart, so a near-perfect best does not drop every other candidate;
- ``ceiling``: a candidate whose error exceeds it drops out whatever the others do, so a demonstration that no edge
  fits is still "unknown", not the least bad edge (0.15 m at Max's scale, three times the paper's 0.05 m: a part
  predicted three wrists' thresholds away is somewhere else).

With ``stillness`` a candidate also drops out when it predicts worse, by more than ``min_move``, than predicting
no movement at all (every part staying where it was seen at the onset): it explains nothing of what is seen. This
needs no length of its own and holds for any body; it is meant with ``relative = true``, where candidates and
stillness alike compare displacements since the onset (with positions, a stance unlike one's own puts every
candidate behind stillness from the first frame).

Commitment is as in the paper (Fig. 3): when every living candidate stands for one movement (and ``min_progress``
of it has been seen). With ``race`` the ratio compares each candidate's mean error since the onset rather than this
frame's, so one frame does not decide. A demonstration that ends with several candidates still alive is answered
with the best of them (the race's finish, :meth:`ForwardModel._leader`); every one of them is within the ceiling.

Spread between takes (issue 18): a movement learned from several clips (``MotorCommandGraph.takes``) says how much
its performances differ. With ``spread`` > 0 each such movement's candidates drop out beyond ``spread`` times its
spread between takes (:meth:`ForwardModel.spreads`: the median over its takes of the take's mean prediction error
under the nearest other take's commands), in place of ``threshold`` or ``ceiling``, as ``path-search``'s ``spread``
does for its ``max_distance``. A movement people perform alike is held tight, one they perform in many ways loosely.

Across styles (issue 18; K&G §4.1, §4.4, §6), three more settings, each off by default (the paper):

- ``error = "moving"``: K&G follow the subsystems that move (§4.1). A whole-body subsystem (a repertoire of
  clips) has many parts that take no part in a movement, and their errors (a head held otherwise, another stance)
  outweigh those of the few that do. Each part's error is weighted by the path it has been seen to cover since the
  onset, over the parts' sum (:func:`moving_weights`): the weights have no unit and sum to 1, a still part weighs
  nothing, and the error stays in metres.
- ``clock = "lead"``: one motor command has one time (§4.4 re-parameterises it by the path its movement covers,
  and a hand's fingers share one clock, §4.2). Every part is predicted at the time at which the command's lead part
  has covered the lead's observed path (:func:`lead_clock`), rather than each part at its own observed path length,
  so a command that moves parts the demonstrator keeps still (or keeps still parts that move) predicts them where
  they are not. With ``relative``, displacements are then taken from where the lead joined the command.
- ``unexplained`` (a share, unit-free; with ``dropout = "relative"``): "unknown" without metres. A candidate is
  committed to, or wins the race at the end, only while its mean prediction error since the onset is at most
  ``unexplained`` times the demonstration's own mean extent, the error of predicting that nothing moves
  (:func:`explained`); the ceiling in metres is then not used. 1 means "predicts better than standing still":
  the ratio is unchanged when the demonstration and the prediction are scaled or moved together, so it holds for
  any body and skeleton.

Travel (issue 18; B&B §7.1, K&G §6): the commands move parts relative to the root (B&B §5.1's root-relative
coordinates), so a walk to the left, to the right, backwards and forwards, whose leg swings are alike, are alike to
them. With ``travel`` = τ > 0 where the body goes is one more part, as ``path-search``'s ``travel``: the root's
displacement over τ seconds in the body's own frame (:mod:`plugins.lib.travel`). It is *observed* from the working
memory's world positions, at each frame from the frames up to it (the mean velocity over the last quarter second,
not known before the segment has lasted that long); *predicted* from where the body went while the
command was shown (``Edge.travel``, kept by the motor command graph for clips and for what it learns by watching),
read at the point of the command where its lead part is predicted (K&G §4.1: the forward model predicts from the
command); and *compared* as one more part of ``error``: the largest, one more in the mean, or weighted by how far
it has been seen to go (the root's path in the world since the onset) with ``moving``. It is compared as it is,
also with ``relative``: travel is a velocity, which another person's stance does not offset. Where the world
positions are not known the travel part is left out; a command without travel is performed on the spot. The
drop-out, ``stillness`` (the body on the spot) and ``unexplained`` (the extent includes the travel) see it; the
end check (:meth:`ForwardModel._ended`), the start node and the spreads between takes compare the parts alone.

The styled comparison (issue 18; K&G §4.4, §6; B&B §7.1), path search's ``posture`` and the posegraph's
``tempo`` estimated online (:mod:`plugins.lib.online_style`): the forward model commits early, so it
cannot measure a style over the whole segment; each candidate is fitted to the frames seen so far, from running sums
(the same work a frame at any length of segment), each setting off by default (the paper):

- ``posture = "removed"``: each candidate's prediction and the observation are compared each about its own mean
  over the frames seen so far, so a part held otherwise through the movement (a stance, a hand held higher) cancels
  on both sides alike, rather than only the onset's posture as ``relative`` removes it; ``unexplained`` and
  ``stillness`` then compare with predicting that nothing moves in the same way (each part about its own mean);
- ``tempo`` = a factor (2, the posegraph's): the command is predicted at the time it reaches at a pace (command
  seconds per second seen) among paces at most 12% apart within the factor either way, the pace whose prediction
  leaves the least squared residual over the frames seen (with the posture above); K&G §4.4 re-parameterise each
  part by the path length it has covered, which lets a command that moves a part the demonstrator keeps still
  predict it where it is seen, and a movement made larger run ahead along its command. A candidate path goes on
  along the next edges once its pace's time passes the path's end; the end check compares the fitted prediction.

Amplitude (the observation scaled by its extent over the command's over the same progress, within a factor 2) was
built and measured too, and lowered the accuracy on the Bandai-Namco clips in every combination: not kept
(docs/benchmarks.md, "The forward model's styled comparison (issue 18, fmstyled)").

The spreads between takes (``spread``; :meth:`ForwardModel.take_errors`) use the styled comparison too when it is on
(issue 18, fmstyled2): each take is followed by another take's commands as a demonstration is, about each side's own
mean and at the pace fitted to the frames seen so far (the running sums as cumulative sums over the take,
:func:`plugins.lib.online_style.distances_all`), so the limit ``spread`` times the spread and the candidates' errors it
bounds compare like with like: two takes that differ only by a held stance, or by their pace, have no spread.

Cost (K&G §4.4 predict every candidate in parallel): with ``tempo`` every candidate's prediction at every pace is one
gather over the commands stacked once per subsystem (:meth:`ForwardModel._at_times_all`), the running sums and best
paces of all candidates at once (:func:`plugins.lib.online_style.residuals_all`), and their travel parts at once; the
same values as candidate by candidate (``tests/test_forward_model_styled_batch.py``). Without ``tempo`` (``posture``
alone) the same batch runs with one pace, every one-command candidate placed along its strokes at once on the
path-length clock (:meth:`ForwardModel._styled_clock_all`); :meth:`ForwardModel._styled_predict`, path by path, is the
tests' reference (and what runs when the commands cannot be stacked).

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

from plugins.lib import online_style
from plugins.lib.compiled import compiled
from plugins.lib.strokes import StrokeCriteria
from toolkit import Match, Matcher, Motion, Parameter, hookimpl
from toolkit.components import provides
from toolkit.watching import WorkingMemory, follow

__all__ = ["ForwardModel", "Track", "CommandGraphs", "moving_weights", "explained", "lead_clock"]


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
                       criteria: StrokeCriteria = StrokeCriteria(), travel: np.ndarray | None = None) -> list[str]:
        """Learn an observed movement as new edges from ``start`` (true imitation); their names. ``travel`` (n, 3):
        where the body went at each frame (the root's velocity in the body's frame), kept with the edges."""

    def rest_pose(self) -> np.ndarray:
        """The body's rest pose, local frame (P, 3)."""


def moving_weights(lengths: np.ndarray) -> np.ndarray:
    """Each part's share of the path the parts have been seen to cover (k,): ``lengths / lengths.sum()``, the
    parts alike (``1 / k``) when none has moved (or a length is not finite). The weights sum to 1 and have no unit,
    so a weighted error is in the units of the distances, and a still part weighs nothing."""
    lengths = np.asarray(lengths, dtype=float)
    total = float(lengths.sum())
    if not np.isfinite(total) or total <= 0.0:
        return np.full(len(lengths), 1.0 / max(len(lengths), 1))
    return lengths / total


def explained(error: float, extent: float, unexplained: float, floor: float = 0.0) -> bool:
    """Whether a prediction whose mean error is ``error`` explains the demonstration: ``error <= unexplained *
    max(extent, floor)``, where ``extent`` is the mean error of predicting that nothing moves (the demonstration's
    own extent of movement, in the same units) and ``floor`` the smallest extent that counts as a movement. The
    ratio ``error / extent`` has no unit: it is unchanged when the demonstration and the prediction are scaled
    together (another body size) or moved together (another place), so the same ``unexplained`` holds for a mouse
    and a person."""
    return bool(error <= unexplained * max(extent, floor))


def lead_clock(arcs: np.ndarray, lead: int, length: float) -> np.ndarray:
    """Every part's path length (k,) at the time at which part ``lead`` has covered ``length`` of its stroke.

    ``arcs`` (k, G) are the cumulative path lengths of one command's strokes on a grid uniform in time (the parts of
    one command share its duration), so the time is a fractional grid index: where ``arcs[lead]`` reaches
    ``length`` (its first point there when the lead pauses), clipped to the stroke; each part is read there. A
    lead that does not move (every length 0) holds every part at its start."""
    arcs = np.asarray(arcs, dtype=float)
    g = arcs.shape[1]
    row = arcs[lead]
    if not np.isfinite(length) or row[-1] <= 0.0:
        return arcs[:, 0].copy()
    length = min(max(length, 0.0), float(row[-1]))
    j = int(np.clip(np.searchsorted(row, length, side="left") - 1, 0, g - 2))
    step = row[j + 1] - row[j]
    w = 0.0 if step <= 0 else min(max((length - row[j]) / step, 0.0), 1.0)
    return arcs[:, j] + w * (arcs[:, j + 1] - arcs[:, j])


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
    sums: dict[tuple[str, ...], tuple[float, int]] = field(default_factory=dict)
    """Per candidate path, its summed prediction errors and the frames summed (a path extended from another
    inherits its sums): the race of ``race``."""
    weights: np.ndarray | None = None
    """With ``error = "moving"``: the parts' weights (k,) at the frame followed last (:func:`moving_weights`)."""
    extent: tuple[float, int] = (0.0, 0)
    """With ``unexplained``: the summed error of predicting no movement (the demonstration's extent) and the frames
    summed."""
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
    travel_seen: np.ndarray | None = None
    """With ``travel``: the travel part seen at the frame followed last (3,), the root's displacement over ``travel``
    seconds in the body's frame; ``None`` when not known (no world positions, fewer than two frames)."""
    travel_weights: np.ndarray | None = None
    """With ``travel`` and ``error = "moving"``: the weights (k + 1,) of the parts and of the travel part at the frame
    followed last (:func:`moving_weights` of the parts' path lengths and the root's path in the world)."""
    styled: dict[tuple[str, ...], Any] = field(default_factory=dict)
    """With the styled comparison (``posture``, ``tempo``): per candidate path, its running fit
    (:class:`plugins.lib.online_style.Fit`; its ``extra`` holds the last frame's ``along``, ``pace``,
    whether the best pace has passed the path's end (``past``), and the ``error``)."""
    seen: Any = None
    """With the styled comparison: the running sums of the observation (:class:`plugins.lib.online_style.Observed`)."""
    fitted: int = 0
    """With the styled comparison: the rows since the onset added to the fits."""
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
    travel: np.ndarray | None = None
    """With ``travel``: where the body went (m/s, body frame) at each point of the lead part's grid (G, 3)."""


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


class _TimedTables:
    """Every command of one subsystem the styled comparison has predicted, stacked for
    :meth:`ForwardModel._at_times_all`: each command's strokes on the fine grid, positions (T, k, G, 3) and
    cumulative path lengths (T, k, G), with each part's stroke duration (T, k), the command's duration (T,) and, with
    ``travel``, its travel grid (T, G, 3). A command met for the first time, or whose table changed, is added (the
    stack is rebuilt then, once per new command; every command is uniform in its own time)."""

    __slots__ = ("index", "tables", "positions", "arcs", "durations", "edge_durations", "totals", "travel")

    def __init__(self) -> None:
        self.index: dict[str, tuple[Any, int]] = {}
        self.tables: list[tuple[np.ndarray, np.ndarray, np.ndarray, float, np.ndarray | None]] = []
        self.positions = self.arcs = self.durations = self.edge_durations = self.totals = self.travel = None

    def rows(self, names: list[str], model: ForwardModel) -> np.ndarray | None:
        """The row of each command in the stack (added when new or changed); ``None`` when they cannot be stacked
        (grids of other sizes)."""
        out, grew = [], False
        for name in names:
            table = model._edge(name)
            kept = self.index.get(name)
            if kept is None or kept[0] is not table:
                edge = model.motor.edge(name)
                duration = np.array([c.duration for c in edge.commands])
                if self.tables and table.positions.shape != self.tables[0][0].shape:
                    return None
                self.index[name] = kept = (table, len(self.tables))
                self.tables.append((table.positions, table.arcs, duration, edge.duration, table.travel))
                grew = True
            out.append(kept[1])
        if grew or self.positions is None:
            self.positions = np.stack([t[0] for t in self.tables])
            self.arcs = np.stack([t[1] for t in self.tables])
            self.durations = np.stack([t[2] for t in self.tables])
            self.edge_durations = np.array([t[3] for t in self.tables], dtype=float)
            self.totals = self.arcs[:, :, -1]
            travel = [t[4] for t in self.tables]
            self.travel = np.stack(travel) if all(t is not None for t in travel) else None  # (T, G, 3)
        return np.array(out, dtype=np.intp)


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
        Parameter("dropout", str, "absolute", "How a candidate drops out (K&G §4.4): 'absolute', the paper's, when "
                  "its prediction error exceeds threshold; 'relative', when it exceeds ratio times the best living "
                  "candidate's, or the absolute ceiling (see the module).", choices=("absolute", "relative")),
        Parameter("ratio", float, 1.5, "With dropout = relative: a candidate drops out when its prediction error "
                  "exceeds this many times the best living candidate's (errors under min_move count as min_move).",
                  minimum=1.0),
        Parameter("race", bool, False, "With dropout = relative: compare each candidate's mean prediction error "
                  "since the onset, not this frame's, with the best's (evidence accumulates; one frame does not "
                  "decide); the ceiling still applies to this frame's."),
        Parameter("ceiling", float, 0.15, "With dropout = relative: prediction error (m) above which a candidate "
                  "drops out whatever the others do, so a demonstration no edge fits is unknown.", minimum=0.0,
                  length=True),
        Parameter("stillness", bool, False, "Also drop a candidate whose prediction error exceeds, by more than "
                  "min_move, that of predicting no movement at all (every part staying where it was at the onset): "
                  "it explains nothing of what is seen. Meant with relative = true (both then compare displacements)."),
        Parameter("unexplained", float, 0.0, "With dropout = relative: a unit-free limit in place of the ceiling. "
                  "A candidate is committed to, or wins the race at the end, only while its mean prediction error "
                  "since the onset is at most this many times the demonstration's own mean extent (the error of "
                  "predicting that nothing moves, combined over the parts as error says); else the answer is "
                  "unknown. 0: not used (the ceiling in metres decides).", minimum=0.0),
        Parameter("spread", float, 0.0, "A movement with several takes: its candidates drop out beyond this many "
                  "times its spread between takes (each take's mean prediction error under the nearest other take's "
                  "commands) instead of threshold (absolute) or ceiling (relative); 0: not used (the paper).",
                  minimum=0.0),
        Parameter("max_candidates", int, 24, "Most candidate command paths followed at once (the best predictions).", minimum=1),
        Parameter("error", str, "max", "How the prediction errors of a subsystem's parts combine: the largest "
                  "(a wrist subsystem, §4.4), the mean (eq. 1 of B&B 2005, for whole-body subsystems), or 'moving': "
                  "the mean weighted by the path length each part has been seen to cover since the onset, so the "
                  "parts that move carry the error and a still body does not (K&G §4.1 follow the moving "
                  "subsystems; see the module).", choices=("max", "mean", "moving")),
        Parameter("relative", bool, False, "Compare displacements since the onset instead of positions, so that a "
                  "demonstrator whose posture differs from the observer's own (another style's stance) still fits."),
        Parameter("clock", str, "parts", "Where along a command each part is predicted: 'parts', each at the path "
                  "length it has been seen to cover (the default); 'lead', every part at the time at which the "
                  "command's lead part has covered the lead's observed path (one motor command, one time, as a "
                  "hand's fingers share one; §4.4's re-parameterisation), so a command that moves parts the "
                  "demonstrator keeps still, or keeps still parts that move, predicts them where they are not. "
                  "With relative, displacements are then taken from where the lead joined the command.",
                  choices=("parts", "lead")),
        Parameter("travel", float, 0.0, "Seconds over which where the body goes counts as one more part: the root's "
                  "displacement over this time in the body's own frame (plugins.lib.travel), observed from the world "
                  "positions and predicted from the travel each command was shown with (Edge.travel), at the point of "
                  "the command the parts are predicted at. 0: root-relative parts only (the paper).", minimum=0.0),
        Parameter("posture", str, "kept", "Styled comparison (issue 18; K&G §6, B&B §7.1): 'removed' compares each "
                  "candidate's prediction and the observation each about its own mean over the frames seen so far "
                  "(plugins.lib.online_style), so a stance or a hand held otherwise through the movement cancels; "
                  "'kept': as relative says (the paper).", choices=("kept", "removed")),
        Parameter("tempo", float, 0.0, "Styled comparison: each candidate is predicted at the time its command "
                  "reaches at a pace (command seconds per second seen) fitted to the frames seen so far, among "
                  "paces at most 12% apart within this factor either way (posegraph's tempo), so predictions follow "
                  "the demonstrator's own pace. 0: the path-length clock of reparameterise (the paper, §4.4).",
                  minimum=0.0, check=lambda v: None if v == 0 or v >= 1 else "0 (off) or a factor of at least 1"),
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
        self._root = owner.body.root_index
        self._keys: dict[tuple[str, ...], str] = {}  # path -> movement (:meth:`_movement_key`)
        self._key_version: tuple | None = None
        self._travel_stacks: OrderedDict[tuple[str, ...], tuple[list, tuple]] = OrderedDict()
        if self.params["travel"] > 0:
            import scipy.ndimage  # noqa: F401  (travel's filter: imported at set-up, not in the first match)
        _kernels()  # compiled (or loaded from numba's cache) now, not in the first demonstration
        self._tables: dict[int, tuple] = {}
        self._edges: dict[str, _EdgeTable] = {}
        self._half_tables: OrderedDict[tuple[str, ...], tuple[list, tuple]] = OrderedDict()
        self._stroke_tables: OrderedDict[tuple[str, ...], tuple[list, tuple]] = OrderedDict()
        self._stroke_rows = _StrokeRows(self.GRID)
        self._time_tables: dict[str, _TimedTables] = {}  # subsystem -> the commands the styled comparison predicted
        self._scales: dict[str, tuple[Any, float]] = {}
        self._placed: OrderedDict[tuple[tuple[str, ...], bytes], tuple[tuple, np.ndarray]] = OrderedDict()
        self._memory: WorkingMemory | None = None
        self._rows: _Grown | None = None  # the working memory in the motor frame, row by row
        self._last_local: np.ndarray | None = None
        self._tracked: dict[str, _Tracked] = {}
        self._revision = 0
        self._spreads: dict[str, float] | None = None
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
        observer's own at its end) begins his next movement there. With ``relative`` too (issue 18): another
        stance is off one's own states by centimetres, while a movement's end is off the hub by the movement; keeping
        the active node whatever is seen (as this did before) let one unrecognised movement's end node start every
        later segment of a stream from the wrong node (the generated streams' error 0.778 against 0.333).
        """
        active = self.motor.active_node(name)
        if active == "hub" or not np.isfinite(seen).any():
            return active
        far = [self._distance_to(name, self.motor.state(name, n), seen) for n in (active, "hub")]
        return active if far[0] <= far[1] else "hub"

    def _distance_to(self, name: str, state: np.ndarray, seen: np.ndarray) -> float:
        """How far the parts seen (k, 3) are from a state of subsystem ``name``, combined as ``error`` says."""
        d = np.linalg.norm(state - seen, axis=-1) * self._scale_of(name)
        # "moving" is the plain mean here: a state is compared at the onset, before any part has moved
        return float(np.nanmax(d) if self.params["error"] == "max" else np.nanmean(d))

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
        if self.params["travel"] > 0 and not track.hand:
            self._travel_seen(track, len(memory), lengths)
        styled = self._styled(track)
        if track.committed is not None:
            error = self._styled_errors(track, [track.committed_path], observed, lengths)[track.committed_path] \
                if styled else self._error(track, track.committed_path,
                                           self._clock(track, track.committed_path, lengths, len(observed)), last)
            track.trace.append((frame, {track.committed_path: error}))
            if error <= self.params["deviation"]:
                return None
            return self._deviate(track, lengths, memory)  # Fig. 3: stop, exclude the edge, predict again
        if not track.candidates:
            return None
        n = len(observed)
        paths = self._styled_extended(track) if styled else self._extended(track, lengths, n)
        if styled:
            errors = self._styled_errors(track, paths, observed, lengths)
        elif self.params["reparameterise"]:  # the clock is the path length observed: every candidate at once
            errors = self._errors(track, paths, lengths, last)
        else:
            errors = {path: self._error(track, path, self._clock(track, path, lengths, n), last) for path in paths}
        track.trace.append((frame, errors))
        unexplained = self.params["unexplained"] > 0 and self.params["dropout"] == "relative"
        still = None
        if (self.params["stillness"] or unexplained) and styled and self.params["posture"] == "removed":
            still = self._styled_still(track, observed, lengths)
        elif self.params["stillness"] or unexplained:  # predicting no movement: every part still, the body on the spot
            still = self._distance(track, observed[0], last) if not self._traveling(track) else float(
                self._with_travel(track, (_norms(observed[0] - last) * track.scale)[None],
                                  np.array([_norms(track.travel_seen)]))[0])
        evidence = self._evidence(track, errors)
        if unexplained:
            total, frames = track.extent
            track.extent = (total + still, frames + 1)
        alive = self._survivors(errors, evidence, still if self.params["stillness"] else None)
        if len(alive) > self.params["max_candidates"]:  # keep the best predictions
            alive = dict(sorted(alive.items(), key=lambda kv: kv[1])[: self.params["max_candidates"]])
        track.candidates = alive
        if alive and len({self._movement_key(p) for p in alive}) == 1:  # one first command (or movement) prevails
            path = min(alive, key=alive.get)
            along = track.styled[path].extra["along"] if styled else \
                self._along(track, path[0], self._clock(track, path, lengths, n))
            progress = self._progress(path[0], along)
            if (progress >= self.params["min_progress"] or len(path) > 1) and self._timed(track, observed) and \
                    self._explained(track, path):
                self._commit(track, path, along, progress, len(observed), alive[path])
        return None

    def _commit(self, track: Track, path: tuple[str, ...], along: np.ndarray, progress: float, n_observed: int,
                error: float) -> None:
        """Commit a subsystem to candidate ``path`` (the whole learned sequence it begins), at the speed seen."""
        track.committed_path = self._known_continuation(path)
        if path in track.styled:  # the whole sequence predicts the frames seen as its beginning did
            track.styled[track.committed_path] = track.styled[path]
        track.committed = self.motor.add_sequence(list(track.committed_path))
        track.committed_at = self._memory.n
        track.speed = self._speed(track, path, n_observed)
        track.progress = progress
        track.confidence = float(np.exp(-error / self._limit(path)))

    def _leader(self, track: Track, memory: np.ndarray) -> bool:
        """With ``dropout = relative``, at the end of a demonstration no candidate prevailed in alone: commit the
        subsystem to the best of those still alive (the lowest error, or with ``race`` the lowest mean error), as
        the race's finish. Every one of them is within its ceiling: what is unknown is decided by the ceiling, not
        here. Returns whether it committed."""
        if self.params["dropout"] != "relative" or track.committed is not None or not track.candidates:
            return False
        score = ({p: t / n for p, (t, n) in track.sums.items() if p in track.candidates} if self.params["race"]
                 else {}) or track.candidates
        path = min(score, key=score.get)
        if not self._explained(track, path):  # even the best explains too little of the movement: unknown
            return False
        observed = self._observed(track, memory)
        along = self._along(track, path[0], _lengths(observed))
        self._commit(track, path, along, self._progress(path[0], along), len(observed), track.candidates[path])
        return True

    # -- the styled comparison (issue 18; K&G §6, B&B §7.1) ------------------------------------------

    def _styled(self, track: Track) -> bool:
        """Whether ``track`` is compared in the demonstrator's own style (``posture``, ``tempo``;
        :mod:`plugins.lib.online_style`): any of them on, for a positional subsystem (a hand's fingers share one
        clock and keep the paper's comparison)."""
        p = self.params
        return not track.hand and (p["posture"] == "removed" or p["tempo"] > 0)

    def _styled_extended(self, track: Track) -> list[tuple[str, ...]]:
        """:meth:`_extended` for the styled comparison: a candidate path continues along the edges of its end node
        once, at the last frame, its fitted prediction passed the path's end (the best pace's time past the path's
        duration; with the path-length clock, the lead part's length past its stroke)."""
        out = []
        for path in track.candidates:
            fit = track.styled.get(path)
            out.extend(self._next(track, path) if fit is not None and fit.extra.get("past") else [path])
        return out

    def _styled_errors(self, track: Track, paths: list[tuple[str, ...]], observed: np.ndarray,
                       lengths: np.ndarray) -> dict[tuple[str, ...], float]:
        """This frame's prediction error of each candidate path in the demonstrator's own style
        (:mod:`plugins.lib.online_style`): the rows seen since the last call added to the observation's running
        sums and to each path's (a path extended this frame goes on from its parent's sums: its predictions of
        the frames before are the same), each path's prediction at the pace that fits the frames seen best,
        compared about each side's own mean (``posture``), the parts (and the travel part) combined as ``error``
        says. With ``relative`` both sides
        are displacements since the onset."""
        n, start = len(observed), track.fitted
        k = observed.shape[1]
        rel = self.params["relative"]
        o = observed[start:n] - observed[0] if rel else observed[start:n]
        if track.seen is None:
            track.seen = online_style.Observed.empty(k)
        if n > start:
            track.seen.add(o)
        paces = online_style.paces(self.params["tempo"])
        centred = self.params["posture"] == "removed"
        fits = {}
        errors = {}
        batch = self._styled_predict_all(track, paths, observed, start, n, paces) if n > start else None
        for path in paths:
            fit = track.styled.get(path)
            if fit is None:
                parent = track.styled.get(path[:-1])
                fit = parent.copy() if parent is not None else online_style.Fit.empty(len(paces), k)
            fits[path] = fit
        travel = None
        together = batch is not None and len(fits) == len(paths)  # every candidate's sums at once
        if together:
            ds, bests = online_style.residuals_all(track.seen, list(fits.values()), o, batch[0], centred)
            if self._traveling(track) and self.params["tempo"] > 0:  # from the commands stacked for the paces
                travel = self._travel_all(track.subsystem, paths, batch[1][np.arange(len(paths)), bests])
        for c, path in enumerate(paths):
            fit = fits[path]
            if n > start:
                if together:
                    p, along, past = batch[0][c], batch[1][c], batch[2][c]
                    d, best = ds[c], int(bests[c])
                else:
                    p, along, past = (batch[0][c], batch[1][c], batch[2][c]) if batch is not None else \
                        self._styled_predict(track, path, observed, start, n, paces)
                    fit.add(o, p)
                    d, best = online_style.residuals(track.seen, fit, o[-1], p[:, -1], centred)
                d = d * track.scale
                if self._traveling(track):
                    dt = _norms((self._travel_predicted(path, along[best]) if travel is None else travel[c])
                                - track.travel_seen)
                    error = float(self._with_travel(track, d[None], np.array([dt]))[0])
                else:
                    error = float(self._combine(track, d[None], lengths)[0])
                fit.extra.update(along=along[best], pace=float(paces[best]), past=bool(past[best]), error=error)
            errors[path] = fit.extra.get("error", np.inf)
        if track.committed is None:
            track.styled = fits
        else:
            track.styled.update(fits)
        track.fitted = n
        return errors

    def _styled_still(self, track: Track, observed: np.ndarray, lengths: np.ndarray) -> float:
        """With ``posture = "removed"``: the error of predicting that nothing moves, compared as the candidates are
        (``stillness``, ``unexplained``): a prediction that holds every part still is its own mean, so each part's
        distance is the observation's from its mean over the frames seen (:meth:`_styled_errors` has added this
        frame); the body on the spot for the travel part."""
        seen = track.seen
        o = observed[-1] - observed[0] if self.params["relative"] else observed[-1]
        d = _norms(o - seen.so / max(seen.n, 1)) * track.scale
        if self._traveling(track):
            return float(self._with_travel(track, d[None], np.array([_norms(track.travel_seen)]))[0])
        return float(self._combine(track, d[None], lengths)[0])

    def _onset_time(self, track: Track, path: tuple[str, ...]) -> float:
        """With ``tempo``: the command time of path ``path`` at the onset, where its lead part joined its first
        command (:meth:`_anchor`; 0 with ``relative``)."""
        lead = self._lead(path[0])
        return self._mapped_time(self._strokes_of(path[0])[lead], float(self._anchor(track, path[0])[lead]))

    def _styled_predict(self, track: Track, path: tuple[str, ...], observed: np.ndarray, start: int, n: int,
                        paces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Path ``path``'s predictions of rows ``start .. n - 1`` since the onset, (S, m, k, 3) at each of the S
        ``paces`` (displacements from the path's point at the onset with ``relative``), with each pace's place
        along the path at the last row (S, k) and whether it has passed the path's end (S,).

        With ``tempo``: at command time ``t0 + pace * i / fps`` for row ``i``, ``t0`` where the lead part joined the
        command (:meth:`_anchor`; 0 with ``relative``). Without: the path-length clock (:meth:`_clock`), one pace."""
        anchor = self._anchor(track, path[0])
        rows = np.arange(start, n)
        if self.params["tempo"] > 0:
            times = self._onset_time(track, path) + paces[:, None] * (np.append(rows, 0) / self.fps)[None]  # (S, m + 1): the onset's last
            points, along, past = self._at_times(path, times.ravel())
            points = points.reshape(len(paces), len(rows) + 1, *points.shape[1:])
            along = along.reshape(len(paces), len(rows) + 1, -1)[:, -2]
            past = past.reshape(len(paces), len(rows) + 1)[:, -2]
            p = points[:, :-1] - points[:, -1:] if self.params["relative"] else points[:, :-1]
            return p, along, past
        ls = [lengths_ for lengths_ in (_lengths(observed[: i + 1]) for i in rows)]
        alongs = []
        for lengths_ in ls:
            along = anchor + lengths_
            if self.params["clock"] == "lead":
                along = self._lead_clock(path, along)
            alongs.append(along)
        p = np.stack([self._predict(track, path, a) for a in alongs])[None]
        if self.params["relative"]:
            p = p - self._predict(track, path, anchor)
        lead = self._lead(path[0])
        total = sum(self._edge(e).arcs[lead, -1] for e in path)
        return p, alongs[-1][None], np.array([alongs[-1][lead] > total + 0.01 / track.scale])

    def _styled_predict_all(self, track: Track, paths: list[tuple[str, ...]], observed: np.ndarray, start: int,
                            n: int, paces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """:meth:`_styled_predict` for every candidate path at once (the same values): predictions (C, S, m, k, 3),
        places along the paths at the last row (C, S, k) and whether past their ends (C, S); ``None`` when the
        paths' commands cannot be stacked (:class:`_TimedTables`). Without ``tempo``, one pace on the path-length
        clock (:meth:`_styled_clock_all`)."""
        if not paths:
            return None
        if not self.params["tempo"] > 0:
            return self._styled_clock_all(track, paths, observed, start, n)
        rows = np.arange(start, n)
        clock = np.append(rows, 0) / self.fps  # (m + 1,): the onset's last
        t0 = np.array([self._onset_time(track, path) for path in paths])
        times = t0[:, None, None] + paces[None, :, None] * clock[None, None]  # (C, S, m + 1)
        out = self._at_times_all(track.subsystem, paths, times.reshape(len(paths), -1))
        if out is None:
            return None
        points, along, past = out
        points = points.reshape(len(paths), len(paces), len(rows) + 1, *points.shape[2:])
        along = along.reshape(len(paths), len(paces), len(rows) + 1, -1)[:, :, -2]
        past = past.reshape(len(paths), len(paces), len(rows) + 1)[:, :, -2]
        p = points[:, :, :-1] - points[:, :, -1:] if self.params["relative"] else points[:, :, :-1]
        return p, along, past

    def _styled_clock_all(self, track: Track, paths: list[tuple[str, ...]], observed: np.ndarray, start: int,
                          n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`_styled_predict` without ``tempo`` (one pace, the path-length clock) for every candidate path at
        once, the same values: rows ``start .. n - 1``'s path lengths (:func:`_lengths` of the rows up to each) are
        computed once for all paths; the one-command paths (the common case) are placed along their strokes at once
        (:meth:`_StrokeRows.along`, as :meth:`_errors` places them: the same points as :meth:`_predict`), the others
        and ``clock = "lead"`` path by path. Predictions (C, 1, m, k, 3), places along at the last row (C, 1, k),
        past the end (C, 1)."""
        rows = range(start, n)
        walked = np.stack([_lengths(observed[: i + 1]) for i in rows])  # (m, k)
        c_n, m, k = len(paths), len(rows), observed.shape[1]
        p = np.empty((c_n, m, k, 3))
        along = np.empty((c_n, k))
        past = np.empty(c_n, dtype=bool)
        one = [c for c, path in enumerate(paths) if len(path) == 1] if self.params["clock"] != "lead" else []
        if one:
            strokes, totals, leads, anchors, _ = self._stacked(track, tuple(paths[c][0] for c in one))
            x = anchors[None] + walked[:, None]  # (m, C1, k): _along's anchor + lengths
            at = self._stroke_rows.along(np.tile(strokes, m), np.minimum(x, totals[None]).reshape(-1))
            p[one] = at.reshape(m, len(one), k, 3).transpose(1, 0, 2, 3)
            if self.params["relative"]:
                p[one] -= self._stroke_rows.along(strokes, np.minimum(anchors, totals).reshape(-1)).reshape(
                    len(one), 1, k, 3)
            along[one] = x[-1]
            past[one] = x[-1, np.arange(len(one)), leads] > totals[np.arange(len(one)), leads] + 0.01 / track.scale
        chosen = set(one)
        for c, path in enumerate(paths):
            if c not in chosen:
                pc, ac, ec = self._styled_predict(track, path, observed, start, n, np.array([1.0]))
                p[c], along[c], past[c] = pc[0], ac[0], ec[0]
        return p[:, None], along[:, None], past[:, None]

    def _at_times_all(self, subsystem: str, paths: list[tuple[str, ...]],
                      times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """:meth:`_at_times` of C paths at once, path ``c`` at command times ``times[c]`` ((C, N); the same values):
        positions (C, N, k, 3), places along (C, N, k) and past the end (C, N). Each time is on the last edge of its
        path that has begun by then (the first edge before it begins), as :meth:`_at_times` overwrites edge after
        edge; the edges' starts and the places before them are the same running sums."""
        timed = self._time_tables.get(subsystem)
        if timed is None:
            timed = self._time_tables[subsystem] = _TimedTables()
        longest = max(len(path) for path in paths)
        ids = timed.rows([name for path in paths for name in path], self)
        if ids is None:
            return None
        c_n = len(paths)
        slots = np.zeros((c_n, longest), dtype=np.intp)
        used = np.zeros((c_n, longest), dtype=bool)
        at = 0
        for c, path in enumerate(paths):
            slots[c, : len(path)] = ids[at : at + len(path)]
            used[c, : len(path)] = True
            at += len(path)
        # per path, each edge's start (s) and the path length before it, part by part: running sums in path order
        durations = np.where(used, timed.edge_durations[slots], 0.0)
        starts = np.zeros((c_n, longest + 1))
        np.cumsum(durations, axis=1, out=starts[:, 1:])
        before = np.zeros((c_n, longest + 1, timed.totals.shape[1]))
        np.cumsum(np.where(used[..., None], timed.totals[slots], 0.0), axis=1, out=before[:, 1:])
        ends = starts[np.arange(c_n), np.array([len(path) for path in paths])]  # (C,): each path's duration
        begun = (times[:, :, None] - starts[:, None, :longest] >= 0) & used[:, None, :]  # (C, N, L)
        slot = np.maximum(longest - 1 - np.argmax(begun[:, :, ::-1], axis=2), 0)
        slot = np.where(begun.any(axis=2), slot, 0)  # (C, N): the edge of the path each time is on
        cc = np.arange(c_n)[:, None]
        table = slots[cc, slot]  # (C, N)
        local = times - starts[cc, slot]
        g = timed.positions.shape[2]
        u = np.clip(local[..., None] / timed.durations[table], 0.0, 1.0) * (g - 1)  # (C, N, k)
        j = np.clip(np.floor(u).astype(np.intp), 0, g - 2)
        w = u - j
        k = timed.positions.shape[1]
        at = (table[..., None] * k + np.arange(k)) * g + j  # flat index of [table, part, j] (a gather: the same values)
        flat_p, flat_a = timed.positions.reshape(-1, 3), timed.arcs.reshape(-1)
        points = flat_p[at] * (1 - w[..., None]) + flat_p[at + 1] * w[..., None]
        arcs = flat_a[at] * (1 - w) + flat_a[at + 1] * w
        first = slot == 0
        along = np.where(first[..., None], arcs, arcs + before[cc, slot])
        return points, along, times > ends[:, None]

    def _at_times(self, path: tuple[str, ...], times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every part of path ``path`` at command times ``times`` (N,): positions (N, k, 3), places along the path
        (N, k: path length from its start, edge after edge, as :meth:`_along` counts) and whether the time is past
        the path's end (N,). Each part's stroke is tabled uniformly in its own time (:meth:`_table`) and holds its
        end once it has ended; the edges follow one another after each edge's duration."""
        start, before = 0.0, None
        out_p = out_a = None
        for name in path:
            edge, table = self.motor.edge(name), self._edge(name)
            k, g, _ = table.positions.shape
            duration = np.array([c.duration for c in edge.commands])
            local = times - start
            u = np.clip(local[:, None] / duration[None], 0.0, 1.0) * (g - 1)
            j = np.clip(np.floor(u).astype(np.intp), 0, g - 2)
            w = u - j
            cols = np.arange(k)[None]
            points = table.positions[cols, j] * (1 - w[..., None]) + table.positions[cols, j + 1] * w[..., None]
            arcs = table.arcs[cols, j] * (1 - w) + table.arcs[cols, j + 1] * w
            if before is None:
                out_p, out_a, before = points, arcs, np.zeros(k)
            else:
                here = local >= 0
                out_p[here] = points[here]
                out_a[here] = arcs[here] + before
            before = before + table.arcs[:, -1]
            start += edge.duration
        return out_p, out_a, times > start

    # -- drop-out (K&G §4.4, Fig. 3) ----------------------------------------------------------------

    def _survivors(self, errors: Mapping[tuple[str, ...], float],
                   evidence: Mapping[tuple[str, ...], float] | None = None,
                   still: float | None = None) -> dict[tuple[str, ...], float]:
        """The candidates (paths and their prediction errors this frame) that do not drop out.

        ``absolute`` (the paper): those within their limit (:meth:`_limit`: ``threshold``, or ``spread`` times
        their movement's spread between takes). ``relative``: those within their limit (``ceiling``, or the
        spread's) whose ``evidence`` (this frame's errors, or with ``race`` their means since the onset) is within
        ``ratio`` times the best of them, errors under ``min_move`` counted as ``min_move`` (two predictions closer
        than the smallest displacement that counts as a movement are not told apart).

        ``still`` (with ``stillness``): the error of predicting no movement at all (every part where it was at the
        onset); a candidate more than ``min_move`` worse than that explains nothing of what is seen and drops out.
        """
        alive = {path: error for path, error in errors.items() if error <= self._limit(path)}
        if still is not None:
            alive = {path: error for path, error in alive.items() if error <= still + self.params["min_move"]}
        if self.params["dropout"] == "relative" and alive:
            score = errors if evidence is None else evidence
            bar = self.params["ratio"] * max(min(score[p] for p in alive), self.params["min_move"])
            alive = {path: error for path, error in alive.items() if score[path] <= bar}
        return alive

    def _evidence(self, track: Track, errors: Mapping[tuple[str, ...], float]) -> Mapping[tuple[str, ...], float]:
        """What the relative drop-out compares: this frame's errors, or with ``race`` each candidate's mean error
        since the onset (its sums updated here; a path extended this frame inherits its parent's)."""
        if not self.params["race"] and not (self.params["unexplained"] > 0 and self.params["dropout"] == "relative"):
            return errors
        sums = {}
        for path, error in errors.items():
            total, n = track.sums.get(path) or track.sums.get(path[:-1]) or (0.0, 0)
            sums[path] = (total + error, n + 1)
        track.sums = sums
        if not self.params["race"]:
            return errors
        return {path: total / n for path, (total, n) in sums.items()}

    def _explained(self, track: Track, path: tuple[str, ...]) -> bool:
        """With ``unexplained`` (and ``dropout = relative``): whether candidate ``path``'s mean prediction error since
        the onset is at most ``unexplained`` times the demonstration's mean extent (:func:`explained`); always true
        without it."""
        if not (self.params["unexplained"] > 0 and self.params["dropout"] == "relative"):
            return True
        total, n = track.sums.get(path, (0.0, 0))
        extent, frames = track.extent
        return explained(total / max(n, 1), extent / max(frames, 1), self.params["unexplained"],
                         self.params["min_move"])

    def _limit(self, path: tuple[str, ...]) -> float:
        """The prediction error above which candidate ``path`` drops out whatever the others do: ``spread`` times
        its movement's spread between takes (``spread`` > 0 and a movement of several takes), else ``threshold``
        (``absolute``) or ``ceiling`` (``relative``)."""
        if self.params["spread"] > 0:
            spread = self.spreads().get(self._movement_key(path))
            if spread is not None:
                return self.params["spread"] * spread
        if self.params["dropout"] == "relative" and self.params["unexplained"] > 0:
            return float("inf")  # unknown is decided against the demonstration's own extent (:meth:`_explained`)
        return self.params["threshold" if self.params["dropout"] == "absolute" else "ceiling"]

    def spreads(self) -> dict[str, float]:
        """Each movement's spread between takes (issue 18; not in the paper), for movements of several takes
        (``MotorCommandGraph.takes``): the median over its takes of the take's mean prediction error (over its
        frames, as ``error`` combines the parts) under the nearest other take's commands, as the forward model
        would predict the take from them (:meth:`take_errors`). Computed once, when first needed."""
        if self._spreads is None:
            takes = self.motor.takes() if hasattr(self.motor, "takes") else {}
            self._spreads = {}
            if self.params["tempo"] > 0:  # every take's commands stacked once (_at_times_all), not once per new take
                names: dict[str, list[str]] = {}
                for examples in takes.values():
                    for edges, subsystem, *_ in examples:
                        names.setdefault(subsystem, []).extend(edges)
                for subsystem, every in names.items():
                    timed = self._time_tables.get(subsystem)
                    if timed is None:
                        timed = self._time_tables[subsystem] = _TimedTables()
                    timed.rows(list(dict.fromkeys(every)), self)
            for movement, examples in takes.items():
                if len(examples) < 2:
                    continue
                distances = []
                kept: dict[Any, Any] = {"longest": max(len(observed) for _, _, observed, _ in examples)}
                for i, (_, subsystem, observed, fps) in enumerate(examples):
                    others = [tuple(edges) for j, (edges, *_) in enumerate(examples) if j != i]
                    errors = [self.take_errors(subsystem, observed, path, fps, kept=kept) for path in others]
                    distances.append(min((float(np.mean(e)) for e in errors if len(e)), default=float("nan")))
                finite = [d for d in distances if np.isfinite(d)]
                if len(finite) >= 2:
                    self._spreads[movement] = float(np.median(finite))
        return self._spreads

    def take_errors(self, subsystem: str, observed: np.ndarray, path: tuple[str, ...],
                    fps: float | None = None, kept: dict | None = None) -> np.ndarray:
        """The prediction error, frame by frame, of command path ``path`` on a subsystem's observed movement
        ``observed`` (n, k, 3) followed from its first frame: the forward model's own prediction (:meth:`_error`,
        anchors and ``relative`` included) with the observed path lengths up to each frame (the positions
        averaged over three frames, as :func:`_lengths` does, over the whole take at once).

        With the styled comparison (``posture``, ``tempo``; :meth:`_styled`) the take is compared as a
        demonstration is (:meth:`_take_errors_styled`), so that a spread between takes and the errors of the
        candidates it bounds compare like with like. ``fps``: the take's frame rate (the pace's clock; by default
        the segment's, else 30). ``kept``: what :meth:`spreads` keeps between the calls of one movement's takes (each
        take's path lengths and weights, each path's predictions at the paces over the longest take, ``"longest"``
        rows), the same values computed once."""
        from scipy.ndimage import uniform_filter1d

        track = Track(subsystem, self._scale_of(subsystem), self.motor.is_hand(subsystem), "hub", 0, {}, [],
                      first=observed[0])
        walked = kept.get(("walked", id(observed))) if kept is not None else None
        if walked is None:
            smooth = uniform_filter1d(observed, size=3, axis=0, mode="nearest") if len(observed) >= 3 else observed
            walked = np.concatenate([np.zeros((1, observed.shape[1])),
                                     np.cumsum(np.linalg.norm(np.diff(smooth, axis=0), axis=-1), axis=0)])
            if kept is not None:  # the take's array is alive while spreads() runs: its id is its own
                kept[("walked", id(observed))] = walked
        if self._styled(track) and len(path):
            return self._take_errors_styled(track, observed, path, walked,
                                            fps if fps else getattr(self, "fps", None) or 30.0, kept)
        if track.hand or not len(path) or self.params["clock"] == "lead":  # one clock: frame by frame, as followed
            return np.array([self._error(track, path, walked[t], observed[t]) for t in range(1, len(observed))])
        # every frame at once: each part along its strokes of the whole path, laid end to end (what _predict does
        # edge by edge: a part past the end of one edge's stroke goes on along the next, and stops at the last end)
        edges = [self._edge(name) for name in path]
        positions = np.concatenate([e.positions for e in edges], axis=1)  # (k, G, 3)
        totals = np.stack([e.arcs[:, -1] for e in edges])  # (E, k)
        starts = np.concatenate([np.zeros((1, totals.shape[1])), np.cumsum(totals, axis=0)[:-1]])
        arcs = np.concatenate([e.arcs + starts[i][:, None] for i, e in enumerate(edges)], axis=1)  # (k, G)
        along = walked[1:] + self._anchor(track, path[0])  # (T, k)
        predicted = np.stack([np.stack([np.interp(along[:, p], arcs[p], positions[p, :, c]) for c in range(3)],
                                       axis=-1) for p in range(len(arcs))], axis=1)  # (T, k, 3)
        d = np.linalg.norm(predicted + self._onset_offset(track, path[0]) - observed[1:], axis=-1) * track.scale
        return self._take_combined(d, walked, kept)

    def _take_combined(self, d: np.ndarray, walked: np.ndarray, kept: dict | None = None) -> np.ndarray:
        """A take's per-part errors at frames 1 .. n - 1 (n - 1, k) combined as ``error`` says, ``moving`` with the
        path lengths ``walked`` (n, k) up to each frame (:func:`moving_weights`; kept in ``kept`` per take)."""
        if self.params["error"] == "moving":
            weights = kept.get(("weights", id(walked))) if kept is not None else None
            if weights is None:
                weights = np.apply_along_axis(moving_weights, 1, walked[1:])
                if kept is not None:
                    kept[("weights", id(walked))] = weights
            return (d * weights).sum(axis=1)
        return d.max(axis=1) if self.params["error"] == "max" else d.mean(axis=1)

    def _take_errors_styled(self, track: Track, observed: np.ndarray, path: tuple[str, ...], walked: np.ndarray,
                            fps: float, kept: dict | None = None) -> np.ndarray:
        """:meth:`take_errors` in the demonstrator's own style: at each frame ``t`` of the take (1 .. n - 1) the
        error :meth:`_styled_errors` gives when following it, every frame at once. The running sums of
        :mod:`plugins.lib.online_style` over rows 0 .. t are cumulative sums over the take: per pace the residual
        over the frames up to ``t`` (:func:`online_style.distances_all`), the best pace at each frame, and that pace's
        per-part distance at ``t``, each side about its own mean up to ``t`` with ``posture = "removed"``. The parts
        are compared alone (the spreads leave travel out), combined as ``error`` says with the path lengths walked
        up to ``t`` (:func:`moving_weights`)."""
        if self.params["tempo"] > 0:
            # each value is computed by itself (element by element): the predictions of a path over the longest take
            # of a movement, kept, hold those over a shorter one as their first rows (the same bits)
            t0 = self._onset_time(track, path)
            key = ("points", path, fps, t0)
            sums = kept.get(key) if kept is not None else None
            if sums is None or sums[0].shape[1] < len(observed):
                rows = np.arange(max(len(observed), kept["longest"]) if kept is not None else len(observed))
                paces = online_style.paces(self.params["tempo"])
                times = t0 + paces[:, None] * (rows / fps)[None]  # (S, n): row 0 is the onset
                at_once = self._at_times_all(track.subsystem, [path], times.reshape(1, -1))  # each time on its edge
                points = (at_once[0][0] if at_once is not None else self._at_times(path, times.ravel())[0]).reshape(
                    len(paces), len(rows), -1, 3)
                # with their own running sums (online_style.prediction_sums: a shorter take's are their first rows)
                sums = online_style.prediction_sums(points - points[:, :1] if self.params["relative"] else points)
                if kept is not None:
                    kept[key] = sums
            p = None
        else:  # the path-length clock, one pace: each part along its strokes after the path walked (as _predict)
            anchor = self._anchor(track, path[0])
            clock = self._lead_clock if self.params["clock"] == "lead" else (lambda _, along: along)
            p = np.stack([self._predict(track, path, clock(path, anchor + w)) for w in walked])[None]
            if self.params["relative"]:
                p = p - self._predict(track, path, anchor)
            sums = None
        o = observed - observed[0] if self.params["relative"] else observed
        d, _ = online_style.distances_all(o, p, self.params["posture"] == "removed", sums)
        return self._take_combined(d[1:] * track.scale, walked, kept)

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
            travel = self._travel_grid(name, tables[lead][0]) if self.params["travel"] > 0 else None
            table = _EdgeTable(commands, np.stack([positions for _, positions, _ in tables]), arcs, lead, travel)
            self._edges[name] = table
        return table

    def _travel_grid(self, name: str, times: np.ndarray) -> np.ndarray:
        """Where the body went (m/s, body frame) while command ``name`` was shown, at the times ``times`` of its lead
        part's grid (G, 3): the edge's travel (``Edge.travel``, one row per frame shown) read at the same share of
        the command's time (the command was fitted to those frames, so its start is the first and its end the last);
        none known: on the spot (0)."""
        travel = getattr(self.motor.edge(name), "travel", None)
        if travel is None or not len(travel):
            return np.zeros((len(times), 3))
        travel = np.asarray(travel, dtype=float)
        if len(travel) == 1:
            return np.repeat(travel, len(times), axis=0)
        at = times / max(float(times[-1]), 1e-12) * (len(travel) - 1)
        steps = np.arange(len(travel))
        return np.stack([np.interp(at, steps, travel[:, c]) for c in range(3)], axis=1)

    TRAVEL_WINDOW = 0.25
    """Seconds over which the travel seen is averaged (:mod:`plugins.lib.travel`'s window: a step's sway left and
    right cancels)."""

    def _travel_seen(self, track: Track, n: int, lengths: np.ndarray) -> None:
        """With ``travel``: the travel part seen at row ``n - 1`` of the segment (:attr:`Track.travel_seen`) as an
        observer knows it then: the root's mean velocity over the last :attr:`TRAVEL_WINDOW` seconds (its world
        displacement over them, divided by their time; the same average as :func:`plugins.lib.travel.body_velocity`
        takes, from the frames seen so far), turned into the body's frame by the facing at that row
        (:func:`plugins.lib.travel.frame_rotation`), times ``travel`` seconds. Not known (``None``, the travel part
        left out) before the segment has lasted the window: a velocity from one or two frames is mostly
        observation noise. With ``error = "moving"``, the weights of the parts and the travel part
        (:attr:`Track.travel_weights`): the travel's path is the root's path in the world since the onset, the
        parts' their paths relative to the root, each as far as it has been seen to go."""
        from plugins.lib.travel import frame_rotation

        memory, root = self._memory, self._root
        taps = max(1, int(round(self.TRAVEL_WINDOW * memory.fps)))
        track.travel_seen = None
        world = memory.world
        if n - 1 - taps >= 0:
            moved = world[n - 1, root] - world[n - 1 - taps, root]
            angle = frame_rotation(world[n - 1: n], memory.positions[n - 1: n], memory.visible[n - 1: n], root)[0]
            if np.isfinite(moved).all() and np.isfinite(angle):
                v = moved * (memory.fps / taps)
                turned = (v[0] + 1j * v[2]) * np.exp(1j * angle)
                track.travel_seen = np.array([turned.real, v[1], turned.imag]) * self.params["travel"]
        if self.params["error"] == "moving":
            walked = _lengths(world[track.onset:n, root][:, None])[0] if n - track.onset > 1 else 0.0
            track.travel_weights = moving_weights(np.append(lengths, walked if np.isfinite(walked) else 0.0))

    def _travel_predicted(self, path: tuple[str, ...], along: np.ndarray) -> np.ndarray:
        """With ``travel``: the travel part path ``path`` predicts (3,) when its parts are ``along`` it: the travel
        the command was shown with where its first command's lead part is (edge by edge: a lead past the end of
        one edge goes on along the next), times ``travel`` seconds."""
        lead = self._lead(path[0])
        left = float(along[lead])
        for i, name in enumerate(path):
            edge = self._edge(name)
            total = float(edge.arcs[lead, -1])
            if left <= total or i == len(path) - 1:
                point = _along_rows(edge.arcs[lead][None], edge.travel[None], np.array([min(left, total)]))[0]
                return point * self.params["travel"]
            left -= total
        return np.zeros(3)  # no command (not reached)

    def _travel_all(self, subsystem: str, paths: list[tuple[str, ...]], along: np.ndarray) -> np.ndarray | None:
        """:meth:`_travel_predicted` of C paths at once (C, 3; the same values), ``along`` (C, k) their parts' places
        along them, from the commands :meth:`_at_times_all` stacked this frame; ``None`` without their travel."""
        timed = self._time_tables.get(subsystem)
        if timed is None or timed.travel is None:
            return None
        ids, leads, xs = [], [], []
        for c, path in enumerate(paths):  # the edge each lead is on, as _travel_predicted walks them
            lead = self._lead(path[0])
            left = float(along[c, lead])
            for i, name in enumerate(path):
                total = float(timed.totals[timed.index[name][1], lead])
                if left <= total or i == len(path) - 1:
                    ids.append(timed.index[name][1])
                    xs.append(min(left, total))
                    break
                left -= total
            leads.append(lead)
        ids = np.array(ids, dtype=np.intp)
        return _along_rows(timed.arcs[ids, np.array(leads, dtype=np.intp)], timed.travel[ids],
                           np.array(xs)) * self.params["travel"]

    def _travel_batch(self, names: tuple[str, ...], along: np.ndarray, leads: np.ndarray) -> np.ndarray:
        """:meth:`_travel_predicted` of one-command paths ``names`` at once (C, 3), ``along`` (C, k) their parts'
        places along them (already within their strokes) and ``leads`` (C,) their lead parts."""
        edges = [self._edge(name) for name in names]
        kept = self._travel_stacks.get(names)
        if kept is None or not all(a is b for a, b in zip(kept[0], edges)):
            kept = (edges, (np.stack([e.arcs[e.lead] for e in edges]), np.stack([e.travel for e in edges])))
            self._travel_stacks[names] = kept
            if len(self._travel_stacks) > 64:
                self._travel_stacks.popitem(last=False)
        else:
            self._travel_stacks.move_to_end(names)
        arcs, travel = kept[1]
        x = along[np.arange(len(names)), leads]
        return _along_rows(arcs, travel, np.minimum(x, arcs[:, -1])) * self.params["travel"]

    def _with_travel(self, track: Track, d: np.ndarray, dt: np.ndarray) -> np.ndarray:
        """Per-part distances (C, k) and the travel part's (C,) combined as ``error`` says, the travel one more
        part (C,): the largest, the mean over k + 1 parts, or weighted by how far each has been seen to go
        (:attr:`Track.travel_weights`)."""
        error = self.params["error"]
        if error == "moving":
            w = track.travel_weights
            if w is None:
                w = moving_weights(np.zeros(d.shape[1] + 1))
            return d @ w[:-1] + dt * w[-1]
        if error == "max":
            return np.maximum(d.max(axis=1), dt)
        return (d.sum(axis=1) + dt) / (d.shape[1] + 1)

    def _traveling(self, track: Track) -> bool:
        """Whether the travel part is compared this frame: ``travel`` on, a positional subsystem, travel seen."""
        return self.params["travel"] > 0 and not track.hand and track.travel_seen is not None

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
        _, totals, leads, anchors, _ = self._stacked(track, names)
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
        """Distance between the path's prediction and the parts' last observed positions ``last`` (k, 3).

        The largest over the parts, or their mean (``error``); with ``relative`` the prediction is moved by
        the offset between the observed onset posture and the path's start.
        """
        along = self._along(track, path[0], lengths)
        if self.params["clock"] == "lead" and not track.hand:
            along = self._lead_clock(path, along)
        predicted = self._predict(track, path, along)
        if self.params["error"] == "moving":
            self._weights(track, lengths)
        if self._traveling(track):
            d = _norms(predicted + self._onset_offset(track, path[0]) - last) * track.scale
            dt = _norms(self._travel_predicted(path, along) - track.travel_seen)
            return float(self._with_travel(track, d[None], np.array([dt]))[0])
        return self._distance(track, predicted + self._onset_offset(track, path[0]), last)

    def _errors(self, track: Track, paths: list[tuple[str, ...]], lengths: np.ndarray,
                last: np.ndarray) -> dict[tuple[str, ...], float]:
        """:meth:`_error` of every candidate path, in their order: the one-command paths of a positional subsystem
        predicted at once (their strokes stacked part by part, :meth:`_stacked`; the same arithmetic row by row, so
        the same values), the others one by one."""
        batch = [] if track.hand else [path for path in paths if len(path) == 1]
        errors: dict[tuple[str, ...], float] = {}
        if len(batch) > 1:
            rows, totals, leads, anchors, offsets = self._stacked(track, tuple(path[0] for path in batch))
            k = len(lengths)
            along = np.minimum(lengths + anchors, totals)  # (C, k): _along, then _predict's minimum
            if self.params["clock"] == "lead":
                along = np.stack([self._lead_clock((path[0],), a) for path, a in zip(batch, along)])
            predicted = self._stroke_rows.along(rows, along.reshape(-1)).reshape(len(batch), k, 3) + offsets
            d = _norms(predicted - last) * track.scale
            if self._traveling(track):
                travel = self._travel_batch(tuple(path[0] for path in batch), along, leads)
                combined = self._with_travel(track, d, _norms(travel - track.travel_seen))
            else:
                combined = self._combine(track, d, lengths)
            errors = dict(zip(batch, combined.tolist()))
        return {path: errors[path] if path in errors else self._error(track, path, lengths, last) for path in paths}

    def _combine(self, track: Track, d: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        """Per-part distances (C, k) of C predictions combined as ``error`` says (C,)."""
        error = self.params["error"]
        if error == "moving":
            return d @ self._weights(track, lengths)
        return d.max(axis=1) if error == "max" else d.mean(axis=1)

    def _stacked(self, track: Track, names: tuple[str, ...]) -> tuple[np.ndarray, ...]:
        """For commands ``names`` followed by ``track``: their strokes' rows in the table of every stroke
        (:class:`_StrokeRows`, C * k), stroke lengths (C, k), lead parts (C,), anchors (C, k) and onset offsets
        (C, k, 3; 0.0 without ``relative``), stacked once per set of candidates (kept until the set changes; the
        rows, lengths and leads for the last sets of candidates of any track)."""
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
        # without ``relative`` every offset is 0.0: added as a scalar (the same additions as of zeros stacked)
        offsets = np.stack([np.broadcast_to(self._onset_offset(track, n), e.positions[:, 0].shape)
                            for n, e in zip(names, edges)]) if self.params["relative"] else 0.0
        stacked = (*strokes[1], self._anchors(track, names), offsets)
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
        at the stroke's start). With ``relative`` the observed posture is not comparable with the command's
        positions, and a hand's fingers share one clock: both are followed from the start (0).
        """
        anchor = track.anchors.get(name)
        if anchor is None:
            if self.params["relative"] or track.hand:
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

    def _onset_offset(self, track: Track, name: str) -> np.ndarray | float:
        """With ``relative``: the observed onset posture minus where command ``name`` starts (k, 3); else 0."""
        if not self.params["relative"]:
            return 0.0
        edge = self._edge(name)
        if self.params["clock"] == "lead" and not track.hand:  # from where the lead joined the command
            joined = self._lead_clock((name,), self._anchor(track, name))
            return self._first(track) - _along_rows(edge.arcs, edge.positions, np.minimum(joined, edge.arcs[:, -1]))
        return self._first(track) - edge.positions[:, 0]

    def _lead_clock(self, path: tuple[str, ...], along: np.ndarray) -> np.ndarray:
        """With ``clock = "lead"``: how far along ``path`` each part is (k,) at the time at which the lead part of
        its first command is ``along[lead]`` along it (:func:`lead_clock`, edge by edge: a lead past the end of one
        edge goes on along the next, every part with it)."""
        lead = self._lead(path[0])
        left, before = float(along[lead]), np.zeros(len(along))
        for i, name in enumerate(path):
            edge = self._edge(name)
            if left <= edge.arcs[lead, -1] or i == len(path) - 1:
                return before + lead_clock(edge.arcs, lead, left)
            left -= float(edge.arcs[lead, -1])
            before = before + edge.arcs[:, -1]
        return before

    def _first(self, track: Track) -> np.ndarray:
        """The subsystem's parts where they were seen at the track's onset (k, 3)."""
        if track.first is not None:
            return track.first
        return self._at(track.onset)[self.motor.subsystems[track.subsystem]]

    def _distance(self, track: Track, predicted: np.ndarray, observed: np.ndarray) -> float:
        """Per-part distances (k, 3 each) combined as ``error`` says: the largest or the mean (radians of a hand scaled)."""
        d = _norms(predicted - observed) * track.scale
        if self.params["error"] == "moving":
            return float(d @ self._weights(track))
        return float(d.max() if self.params["error"] == "max" else d.mean())

    def _weights(self, track: Track, lengths: np.ndarray | None = None) -> np.ndarray:
        """With ``error = "moving"``: each part's weight (k,), its observed path length since the onset over the
        parts' sum (:func:`moving_weights`); ``lengths`` given, they are kept on the track for the frame's other
        comparisons."""
        if lengths is not None:
            track.weights = moving_weights(lengths)
        elif track.weights is None:
            track.weights = moving_weights(np.zeros(len(self.motor.subsystems[track.subsystem])))
        return track.weights

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
        if self.params["travel"] > 0 and not track.hand:  # where the body went, kept with the new edges
            from plugins.lib.travel import body_velocity

            seen = self._memory
            if np.isfinite(seen.world[:, self._root]).any():
                travel = np.nan_to_num(body_velocity(seen.world, seen.positions, seen.visible, self._root,
                                                     seen.fps))[track.learn_from: track.learn_from + len(observed)]
                return self.motor.learn_observed(track.subsystem, track.last_correct, observed, self.fps,
                                                 criteria=self._criteria, travel=travel)
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
        again). With ``dropout = relative`` a subsystem without a commitment is first committed to the race's
        leader (not checked against the end: the race's finish). Returns the subsystem's track as it is then."""
        if self._leader(track, memory):
            return track
        while track.committed is not None and not self._ended(track, memory):
            self._deviate(track, _lengths(self._observed(track, memory)), memory)
            track = self.tracks[track.subsystem]
            if self._leader(track, memory):
                break
        return track

    def _ended(self, track: Track, memory: np.ndarray) -> bool:
        """Whether the demonstration ended (the last row of ``memory``) where the committed path does."""
        fit = track.styled.get(track.committed_path)
        if self._styled(track) and fit is not None and "error" in fit.extra:  # where the fitted prediction is now
            return fit.extra["error"] <= self.params["deviation"]
        end = self.motor.edge(track.committed_path[-1]).target
        expected = self.motor.state(track.subsystem, end) + self._onset_offset(track, track.committed_path[0])
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
