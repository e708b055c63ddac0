"""The watching loop: perceived frames into working memory, segmented, matched, concluded. One class for every watcher.

Buchsbaum & Blumberg 2005, §5 and Kopp & Graeser 2006, §4.1 and Fig. 3 describe one cycle, whatever brings the
frames in. :class:`WatchingLoop` is that cycle, and the only copy of it:

.. code-block:: text

    perceived frames (n, S, 3), visible (n, S)        in the observed body's S parts
      -> mapped by name onto the observer's own P parts   (once, here: nothing downstream maps parts again)
      -> [with a correspondence: perceived log, hidden parts held, then correspondence.map_block: the
          demonstrator's size and rest posture mapped onto the observer's own body]
      -> working memory, ObservationLog (F, P, 3) + (F, P) hidden parts held (toolkit.motion.fill_hidden)
      -> segmenter.push_block(the new rows)              segments that closed, the onset under way after each frame
      -> frame by frame, in order:
           a segment closed at this frame    matcher.conclude(its frames) -> the answer     [commit or not]
           a segment under way               a streaming matcher is fed the frame (from the onset when it begins):
                                             matcher.observe(memory) may commit (response facilitation), after
                                             that report a deviation (Match.stop), and after one commit again

An :class:`~toolkit.runtime.Actor` in a world feeds it one frame a step from its perception and turns what it
reports into run events, interpretation and imitation; an :class:`~toolkit.observe.Observer` feeds it packets of
recorded or live frames and returns :class:`Observation` s. What the loop reports reaches them through a
:class:`Listener`; every call into a component goes through a ``call`` function that applies the caller's failure
policy (:func:`call_component` names the failing plugin; a world in skip mode drops it).

Working memory rows count from the first frame of the stream (``reset``); a :class:`Segment`'s frames are rows.
A matcher reads the segment it follows through a :class:`WorkingMemory`, a view of the rows it has been given so
far: it keeps no frames of its own.

Bounded working memory (a live observer that watches for hours): a loop made with ``keep`` (seconds) holds only the
rows still needed, the segment under way from its onset, the rows a segmenter says it may still report
(``holds_since``) and the last ``keep`` seconds; older rows are dropped and the log's ``offset`` says where the rows
it holds begin, so row numbers still count from the stream's first frame and segments, working memory views and
matchers read the same rows as before. A segment that never closes (a demonstrator who never comes back to rest)
is cut every ``max_segment`` seconds: the loop closes the piece under way (an :class:`Observation` with ``cut``
set, answered by the matcher on its frames) and follows the rest from there; when the segmenter closes the segment
at last, it is reported from the last cut. A segment the segmenter reports that begins before the first row
working memory still holds is reported from that row. Memory is then bounded whatever the input: working memory
by ``max_segment`` plus ``keep`` seconds, a matcher by the ``max_segment`` seconds it follows. Without ``keep``
(the default, an actor in a world and :meth:`Observer.watch <toolkit.observe.Observer.watch>`, which is given the
whole motion) every row is kept and nothing is cut.

What plugins return is checked here, for every watcher alike: segments lie inside the stream, are ordered, disjoint
and non-empty; a match names a movement of the observer's own repertoire (its motor system's) or none (unknown),
with a finite confidence in [0, 1] (:func:`toolkit.answers.check_match`). Anything else is a
:class:`~toolkit.errors.PluginError` naming the plugin, the method, what it returned and what was expected.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from toolkit.answers import check_match, shown
from toolkit.components import Match, Segment
from toolkit.errors import ConfigError, LikemeError, PluginError
from toolkit.motion import Motion, fill_hidden, part_index

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.character import Character

__all__ = ["ObservationLog", "WorkingMemory", "Observation", "Listener", "WatchingLoop", "call_component", "guarded",
           "feed", "follow", "KEEP_SECONDS", "MAX_SEGMENT_SECONDS"]

KEEP_SECONDS = 10.0
"""Seconds of the newest rows a bounded working memory keeps beyond what open segments need (a live observer's
default, :class:`toolkit.observe.Observer`): room for a look back (a view, a gaze) without growing."""

MAX_SEGMENT_SECONDS = 60.0
"""Seconds after which a bounded loop cuts a segment that has not closed: about ten times the longest movement of
the papers' repertoires (a bow, a dance: seconds), so a real movement is never cut, and a minute of working memory
(7,200 frames at 120 fps) is small."""


class ObservationLog:
    """Working memory of what an observer perceived of its target, as growing arrays in the observer's own parts.

    One row per frame since watching began: ``positions`` (F, P, 3) root-relative, ``visible`` (F, P), and
    ``world`` (F, P, 3), the parts' world positions. Hidden parts follow the one rule of
    :func:`toolkit.motion.fill_hidden`, kept up as frames arrive: a hidden part holds its last seen value; when a
    part is seen for the first time, the rows before are set to that sighting; a part not seen yet is NaN.

    Rows no longer needed may be dropped (:meth:`forget`): the log then holds rows ``offset`` to ``n`` (exclusive);
    ``n`` still counts every frame since watching began, and ``positions``, ``visible`` and ``world`` are the rows
    held (all of them while nothing was forgotten).
    """

    slack = 1024
    """Rows :meth:`forget` lets go unused before it moves the rows held to the front (at least as many as it holds:
    each row is then moved about once)."""

    def __init__(self, parts: Sequence[str], fps: float, capacity: int = 1024) -> None:
        self.parts = tuple(parts)
        self.fps = float(fps)
        p = len(self.parts)
        self._pos = np.full((capacity, p, 3), np.nan)
        self._world = np.full((capacity, p, 3), np.nan)
        self._vis = np.zeros((capacity, p), dtype=bool)
        self._seen = np.zeros(p, dtype=bool)  # seen at least once
        self._all_seen = False
        self.n = 0
        self.offset = 0  # the row number of the first row held (self._pos[0])
        self.revision = 0  # counts the rewrites of rows already held (WorkingMemory.revision)

    def append(self, pose: np.ndarray, visible: np.ndarray, world: np.ndarray | None = None) -> None:
        """One frame: root-relative pose (P, 3), visible (P,), world positions (P, 3) if known."""
        self.extend(np.asarray(pose, dtype=float)[None], np.asarray(visible, dtype=bool)[None],
                    None if world is None else np.asarray(world, dtype=float)[None])

    def extend(self, poses: np.ndarray, visible: np.ndarray, world: np.ndarray | None = None) -> None:
        """Frames (n, P, 3) with their visibility (n, P) and world positions (n, P, 3) if known, in order."""
        poses = np.asarray(poses, dtype=float)
        visible = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
        k = len(poses)
        if k == 0:
            return
        start, end = self.n - self.offset, self.n - self.offset + k  # in the arrays
        if end > len(self._pos):
            self._reserve(end)
        self._vis[start:end] = visible
        self._pos[start:end] = self._held(self._pos, poses, visible)
        if world is not None:
            self._world[start:end] = self._held(self._world, np.asarray(world, dtype=float), visible)
        if not self._all_seen:
            first = ~self._seen & visible.any(axis=0)
            if first.any() and start:  # seen for the first time: the rows before hold that sighting
                self.revision += 1
                self._pos[:start, first] = self._pos[start:end][np.argmax(visible[:, first], axis=0), first]
                self._world[:start, first] = self._world[start:end][np.argmax(visible[:, first], axis=0), first]
            self._seen |= visible.any(axis=0)
            self._all_seen = bool(self._seen.all())
        self.n += k

    def _held(self, store: np.ndarray, values: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """``values`` with hidden parts filled by the rule, continuing from the row before (the last seen values)."""
        if visible.all():
            return values
        last = self.n - self.offset - 1
        if self.n and len(values) == 1 and self._all_seen:  # one frame, every part seen before: hold the last row
            return np.where(visible[..., None], values, store[last])
        if self.n:
            before = store[last][None]
            return fill_hidden(np.concatenate([before, values]), np.concatenate([self._seen[None], visible]))[1:]
        return fill_hidden(values, visible)

    def forget(self, before: int) -> None:
        """Rows before row ``before`` are no longer needed: they may be dropped, all but the newest (the log drops
        them once they are as many as the rows it would keep, and at least :attr:`slack`, so a row is moved about
        once; memory stays about twice what is needed at most)."""
        before = min(int(before), self.n - 1)  # the newest row stays: hidden parts hold its values
        dead = before - self.offset
        if dead <= 0 or dead < max(self.slack, self.n - before):
            return
        held = self.n - before
        size = max(2 * held, self.slack, 16)  # new arrays: a view a plugin kept of the old rows stays as it was
        pos, world = np.full((size, *self._pos.shape[1:]), np.nan), np.full((size, *self._world.shape[1:]), np.nan)
        vis = np.zeros((size, self._vis.shape[1]), dtype=bool)
        pos[:held], world[:held], vis[:held] = self._pos[dead : dead + held], self._world[dead : dead + held], \
            self._vis[dead : dead + held]
        self._pos, self._world, self._vis = pos, world, vis
        self.offset = before

    def _rows(self, start: int, stop: int | None = None) -> slice:
        """Rows ``start`` to ``stop`` (row numbers since watching began) as a slice of the arrays; a row that was
        dropped is a ``ValueError`` (a caller that needs it should have kept it)."""
        stop = self.n if stop is None else min(int(stop), self.n)
        if start < self.offset:
            raise ValueError(f"rows from {start} were dropped: working memory holds rows {self.offset}..{self.n}")
        return slice(start - self.offset, max(start, stop) - self.offset)

    def _reserve(self, size: int) -> None:
        """Room for ``size`` frames (the arrays double when full)."""
        if size <= self._pos.shape[0]:
            return
        more = max(size, 2 * self._pos.shape[0]) - self._pos.shape[0]
        self._pos = np.concatenate([self._pos, np.full((more, *self._pos.shape[1:]), np.nan)])
        self._world = np.concatenate([self._world, np.full((more, *self._world.shape[1:]), np.nan)])
        self._vis = np.concatenate([self._vis, np.zeros((more, self._vis.shape[1]), dtype=bool)])

    @property
    def positions(self) -> np.ndarray:
        """Root-relative positions of the rows held (F, P, 3), hidden parts held (a view: do not write)."""
        return self._pos[: self.n - self.offset]

    @property
    def visible(self) -> np.ndarray:
        """Which parts were seen in each row held (F, P)."""
        return self._vis[: self.n - self.offset]

    @property
    def world(self) -> np.ndarray:
        """World positions of the rows held (F, P, 3) as perceived, hidden parts held; NaN where never seen or not
        given."""
        return self._world[: self.n - self.offset]

    def motion(self, start: int | None = None, stop: int | None = None) -> Motion:
        """Rows ``start`` (default: the first held) to ``stop`` as a root-relative :class:`Motion` (a copy), with
        their world positions."""
        rows = self._rows(self.offset if start is None else start, stop)
        return Motion(self._pos[rows].copy(), self.fps, self.parts, self._vis[rows].copy(), self._world[rows].copy())

    def since(self, start: int) -> WorkingMemory:
        """A :class:`WorkingMemory` of the rows from ``start``, holding none of them yet (the loop feeds them)."""
        return WorkingMemory(self, start)


class WorkingMemory:
    """The frames of one segment a matcher has been given: rows ``start`` up to the newest frame fed.

    Kopp & Graeser 2006, §4.1: the visual working memory holds "the positions and movement vectors of the movement
    under consideration". The watching loop makes one when a segment begins (``Matcher.begin``) and feeds it a
    row at a time (``Matcher.observe`` after each); it is a window onto the observer's :class:`ObservationLog`, so
    reading it copies nothing. Coordinates follow the hidden-part rule of :func:`toolkit.motion.fill_hidden`.

    Attributes
    ----------
    start : int
        The segment's first row of working memory (frames since watching began).
    """

    def __init__(self, log: ObservationLog, start: int, stop: int | None = None) -> None:
        self._log = log
        self.start = int(start)
        self._stop = self.start if stop is None else int(stop)

    def feed(self, stop: int) -> None:
        """Rows up to ``stop`` (exclusive) are now the matcher's (the watching loop calls this)."""
        self._stop = min(int(stop), self._log.n)

    @property
    def n(self) -> int:
        """Frames of the segment given so far."""
        return self._stop - self.start

    @property
    def revision(self) -> int:
        """Counts the times rows already in working memory were rewritten (a part seen for the first time: the
        rows before hold that sighting, :class:`ObservationLog`). While it stays the same, the rows given keep
        their values, so a matcher may keep what it computed from them and add only the new rows' share
        (incremental per-frame work)."""
        return self._log.revision

    @property
    def fps(self) -> float:
        return self._log.fps

    @property
    def parts(self) -> tuple[str, ...]:
        return self._log.parts

    @property
    def positions(self) -> np.ndarray:
        """Root-relative positions (n, P, 3) of the frames given so far (a view: do not write)."""
        return self._log._pos[self._log._rows(self.start, self._stop)]

    @property
    def visible(self) -> np.ndarray:
        """Which parts were seen (n, P)."""
        return self._log._vis[self._log._rows(self.start, self._stop)]

    @property
    def world(self) -> np.ndarray:
        """World positions (n, P, 3) as perceived."""
        return self._log._world[self._log._rows(self.start, self._stop)]

    def motion(self) -> Motion:
        """The frames given so far as a root-relative :class:`Motion` (a copy)."""
        return self._log.motion(self.start, self._stop)

    def __repr__(self) -> str:
        return f"WorkingMemory(rows {self.start}..{self._stop} of {self._log.n})"


@dataclass(frozen=True)
class Observation:
    """One segment found in the stream and what the matcher made of it.

    ``decided_at`` is the number of frames into the segment at which the matcher committed (``None``: at its
    end); ``match`` is ``None`` without a matcher. ``cut``: the segment had not closed after ``max_segment``
    seconds and the watching loop cut it there (see the module); the rest is followed as a segment of its own.
    """

    segment: Segment
    match: Match | None
    decided_at: int | None
    cut: bool = False

    @property
    def movement(self) -> str | None:
        return self.match.movement if self.match is not None else None

    @property
    def decision_fraction(self) -> float:
        """Share of the segment seen when the matcher committed (1.0 when it waited for the end)."""
        if self.decided_at is None:
            return 1.0
        return float(min(1.0, self.decided_at / self.segment.n_frames))


class Listener:
    """What a watching loop reports as it happens; the default does nothing (an Observer only returns observations).

    The runtime's actors turn these into run events, interpretation, imitation and stopped imitations.
    """

    def segment_found(self, segment: Segment) -> None:
        """The segmenter closed ``segment`` (called before its answer)."""

    def recognised(self, segment: Segment | None, match: Match) -> None:
        """The matcher answered: committed early (``segment`` is ``None``) or at the segment's end."""

    def deviated(self, match: Match) -> None:
        """After committing, the matcher found the demonstration deviating from it (``match.stop``)."""


def call_component(character: Character, key: str, method: str, *args: Any, **kwargs: Any) -> Any:
    """Call ``character.<key>.<method>(...)``; anything but a likeme error becomes a :class:`PluginError` naming the
    component and the method. ``None`` if the character has no such component."""
    component = getattr(character, key)
    if component is None:
        return None
    return guarded(component, method, *args, **kwargs)


def guarded(component: Any, method: str, *args: Any, **kwargs: Any) -> Any:
    """Call ``component.<method>(...)``; anything but a likeme error becomes a :class:`PluginError` naming the
    component and the method (as :func:`call_component`, for a component that is not one of a character's)."""
    try:
        return getattr(component, method)(*args, **kwargs)
    except LikemeError:
        raise
    except Exception as exc:
        raise PluginError(getattr(component, "name", type(component).__name__), f"{type(component).__name__}.{method}",
                          f"{type(exc).__name__}: {exc}") from exc


def _answer(segment: Segment, early: Match | None, late: Match | None, cut: bool = False) -> Observation:
    """The matcher's answer for a segment: what it concluded at the end, else what it committed to early. A
    commitment the matcher decided at a frame but could report only at the end (decided on rows it had not taken in
    yet, :meth:`Matcher.conclude <toolkit.components.Matcher.conclude>`) keeps that frame, so the answer is the same
    whatever packets the rows came in."""
    if late is None and early is not None:
        return Observation(segment, early, early.decided_at, cut)
    if late is None:
        return Observation(segment, Match.unknown(), None, cut)
    return Observation(segment, late, late.decided_at if late.movement is not None and not late.stop else None, cut)


def _eventful(closed: Sequence[tuple[int, Any]], onsets: Sequence[int], n: int) -> list[int]:
    """The frames of a block of ``n`` where something happens, and each frame just before them: a segment closes
    (``closed``: frame in block, segment), the onset of the segment under way changes (``onsets``: one per frame,
    -1: none), the last frame. Between two of them the onset stays what it was."""
    at = {0, n - 1}
    for i, _ in closed:
        at.update((i - 1, i))
    change = np.flatnonzero(np.diff(np.asarray(onsets, dtype=np.int64))) + 1
    at.update(change.tolist())
    at.update((change - 1).tolist())
    return sorted(i for i in at if 0 <= i < n)


def _seconds(value: float | None, name: str) -> float | None:
    """A bound in seconds: ``None`` or a finite number >= 0 (else a :class:`ConfigError`)."""
    if value is None:
        return None
    try:
        value = float(value)
    except (TypeError, ValueError):
        value = float("nan")
    if not np.isfinite(value) or value < 0:
        raise ConfigError(f"{name} = {value!r}", key=(name,), expected="a finite number of seconds >= 0, or none")
    return value


class WatchingLoop:
    """One observer's perceive-segment-match cycle over a stream of perceived frames (see the module).

    Parameters
    ----------
    character : Character
        The observer: its body's parts are working memory's parts; its segmenter and matcher are used (read at
        every call, so a component dropped under a skip policy is simply absent from then on).
    call : callable, optional
        ``call(key, method, *args)`` calls a component of the character under the caller's failure policy
        (default: :func:`call_component`).
    listener : Listener, optional
        Told of segments, recognitions and deviations as they happen.
    keep : float, optional
        Bounded working memory (see the module): seconds of the newest rows kept beyond what the segment under way
        and the segmenter need (:data:`KEEP_SECONDS` for a live observer). ``None`` (the default): every row is
        kept and nothing is cut.
    max_segment : float, optional
        With ``keep``: seconds after which a segment that has not closed is cut (:data:`MAX_SEGMENT_SECONDS`;
        ``None``: never, and a segment under way holds its rows however long it lasts).
    """

    def __init__(self, character: Character, *, call: Callable[..., Any] | None = None,
                 listener: Listener | None = None, keep: float | None = None,
                 max_segment: float | None = MAX_SEGMENT_SECONDS) -> None:
        self.character = character
        self._call = call or (lambda key, method, *a, **k: call_component(character, key, method, *a, **k))
        self._direct = call is None  # components are called by call_component (the matcher once a frame: directly)
        self.listener = listener or Listener()
        self.keep = _seconds(keep, "keep")
        self.max_segment = _seconds(max_segment, "max_segment")
        if self.max_segment == 0:
            raise ConfigError("max_segment = 0", key=("max_segment",), expected="more than 0 seconds, or none")
        self.memory = ObservationLog(character.body.parts, 30.0, capacity=1)
        self.perceived: ObservationLog | None = None  # before correspondence (only with one)
        self._index = np.arange(len(character.body.parts))
        self._same = True  # the observed body's parts are the observer's, in order
        self._open: int | None = None  # start row of the segment the matcher follows
        self._view: WorkingMemory | None = None
        self._early: Match | None = None
        self._stopped: Match | None = None  # the commitment a deviation stopped
        self._since = -1  # the onset of the segment under way, from the last cut (-1: none)
        self._floor = 0  # no segment is reported from before this row (the last cut)
        self._last_end = 0  # the end of the last segment the segmenter closed (they are ordered and disjoint)
        self._known: set[str] = set()  # movements found in the motor system's repertoire
        self._keep_frames: int | None = None
        self._max_frames: int | None = None

    # -- the stream ----------------------------------------------------------------------------------------

    def reset(self, parts: Sequence[str], fps: float, *, capacity: int = 1024) -> None:
        """A new stream of frames of a body whose parts are ``parts``, at ``fps``: working memory, frame numbering
        and the segmenter start again; the observed parts are mapped by name onto the observer's own."""
        own = self.character.body.parts
        self._index = part_index(parts, own)
        self._same = tuple(parts) == tuple(own)
        if not (self._index >= 0).any():
            raise ConfigError("the observed body shares no part with the observer's own", expected=f"parts named "
                              f"like the observer's: {list(own)}", available=list(parts))
        self.memory = ObservationLog(own, fps, capacity=capacity)
        self.perceived = ObservationLog(own, fps, capacity=capacity) if self.character.correspondence else None
        self._open, self._view, self._early = None, None, None
        self._since, self._floor, self._last_end, self._known = -1, 0, 0, set()
        bounded = self.keep is not None
        self._keep_frames = int(round(self.keep * float(fps))) if bounded else None
        self._max_frames = max(1, int(round(self.max_segment * float(fps)))) if bounded and self.max_segment else None
        self._call("correspondence", "reset", own, float(fps))
        self._call("segmenter", "reset", own, float(fps))

    def _onto(self, values: np.ndarray, fill: Any) -> np.ndarray:
        """Observed values (n, S, ...) in the observer's parts (n, P, ...); ``fill`` where it has no such part."""
        values = np.asarray(values)
        if self._same:
            return values
        have = self._index >= 0
        out = np.full((values.shape[0], len(self._index), *values.shape[2:]), fill, dtype=values.dtype)
        out[:, have] = values[:, self._index[have]]
        return out

    def _remember(self, poses: np.ndarray, visible: np.ndarray, world: np.ndarray | None) -> int:
        """Perceived frames in the observed parts into working memory, through the correspondence if there is one;
        the first new row."""
        first = self.memory.n
        poses, visible = self._onto(poses, np.nan), self._onto(np.asarray(visible, dtype=bool), False)
        world = None if world is None else self._onto(world, np.nan)
        if self.perceived is not None and self.character.correspondence is not None:
            self.perceived.extend(poses, visible, world)
            rows = self.perceived._rows(first)
            held, seen = self.perceived._pos[rows], self.perceived._vis[rows]
            mapped = self._call("correspondence", "map_block", held, seen)
            if self.character.correspondence is not None:  # not dropped under a skip policy
                try:
                    mapped = np.asarray(mapped, dtype=float)
                except (TypeError, ValueError):
                    mapped = np.asarray(None)
                if mapped.shape != held.shape:
                    raise PluginError(self.character.correspondence.name, "Correspondence.map_block",
                                      f"returned {shown(mapped)}, expected an array of shape {held.shape}")
                poses, visible = mapped, seen
        self.memory.extend(poses, visible, world)
        return first

    def push(self, poses: np.ndarray, visible: np.ndarray, world: np.ndarray | None = None) -> list[Observation]:
        """Perceived frames in the order they arrived: root-relative poses (n, S, 3), visibility (n, S) and world
        positions (n, S, 3) if known, in the observed body's parts. Returns the observations of the segments that
        closed during them (the same whatever the packet sizes)."""
        first = self._remember(poses, visible, world)
        n = self.memory.n - first
        segmenter = self.character.segmenter
        if n == 0 or segmenter is None:
            self._forget()
            return []
        new = WorkingMemory(self.memory, first, self.memory.n)
        result = self._call("segmenter", "push_block", new.positions, new.visible)
        if self.character.segmenter is None:  # dropped (skip policy)
            return []
        closed, since = self._checked_block(result, n, first)
        out: list[Observation] = []
        k, onsets = 0, since.tolist()
        matcher = self.character.matcher
        frames: Sequence[int] = range(n)
        if self._max_frames is None and (matcher is None or not matcher.streaming):
            # nothing is fed frame by frame and nothing is cut: a frame where no segment closes only sets the onset
            # of the segment under way, which the next such frame sets again. The frames that close segments and
            # the last frame leave the same state, the same observations in the same order.
            frames = sorted({i for i, _ in closed} | {n - 1})
        elif self._max_frames is None:
            # a streaming matcher, nothing cut: the rows between two frames where something happens (a segment
            # closes, the onset changes) and the frames before those are given at once (_follow: Matcher.replay),
            # which leaves the state and the reports that giving them one by one leaves, in the same order
            frames = _eventful(closed, onsets, n)
        for i in frames:
            if k < len(closed) and closed[k][0] == i:  # segments closed at this frame
                here = []
                while k < len(closed) and closed[k][0] == i:
                    here.append(closed[k][1])
                    k += 1
                here = self._clipped(here)
                out.extend(self._close(s, split=len(here) > 1) for s in here)
            row = first + i
            onset = onsets[i]
            if onset >= 0:
                onset = max(onset, self._floor, self.memory.offset)
                if self._max_frames is not None and row - onset >= self._max_frames:  # never closed: cut it here
                    reason = f"still open after {self.max_segment:g} s: cut"
                    out.append(self._close(Segment(onset, row, self.memory.fps, reason), cut=True))
                    self._floor = onset = row
            self._since = onset
            self._follow(onset, row)
        self._forget()
        return out

    def flush(self) -> list[Observation]:
        """End of the stream: the segment under way, if the segmenter accepts it."""
        if self.character.segmenter is None:
            return []
        closed = self._call("segmenter", "flush")
        if self.character.segmenter is None:
            return []
        segments = self._clipped(self._checked_segments(closed or [], "flush", self.memory.n))
        self._since = -1
        return [self._close(s, split=len(segments) > 1) for s in segments]

    def classify(self, poses: np.ndarray, visible: np.ndarray, world: np.ndarray | None = None) -> Observation:
        """Frames (n, S, 3) taken as one whole segment, without the segmenter: what the matcher makes of them, and
        when (a streaming matcher is fed them one by one and may commit early)."""
        first = self._remember(poses, visible, world)
        segment = Segment(first, max(first + 1, self.memory.n), self.memory.fps)
        return self._close(segment, announce=False)

    # -- bounded working memory -------------------------------------------------------------------------------

    def _clipped(self, segments: list[Segment]) -> list[Segment]:
        """Segments the segmenter closed, each from the last cut or the first row still held at the earliest (a
        segment wholly before them was answered already, as the pieces it was cut into)."""
        low = max(self._floor, self.memory.offset)
        if not segments or segments[0].start >= low:
            return segments
        return [s if s.start >= low else Segment(low, s.end, s.fps, s.reason) for s in segments if s.end > low]

    def _forget(self) -> None:
        """Bounded working memory: rows before the segment under way, before what the segmenter may still report
        (its ``holds_since``, at most ``max_segment`` back) and before the last ``keep`` seconds may go."""
        if self._keep_frames is None:
            return
        n = self.memory.n
        need = n - self._keep_frames
        if self._since >= 0:
            need = min(need, self._since)
        if self._open is not None:
            need = min(need, self._open)
        holds = getattr(self.character.segmenter, "holds_since", None)
        if isinstance(holds, (int, np.integer)) and holds >= 0:
            need = min(need, max(int(holds), self._floor, n - self._max_frames if self._max_frames else 0))
        self.memory.forget(need)  # it holds at most twice the rows from there on (ObservationLog.forget)
        if self.perceived is not None:
            self.perceived.forget(need)

    # -- following a segment ----------------------------------------------------------------------------------

    def _follow(self, since: int, row: int) -> None:
        """After row ``row``: the segment under way began at ``since`` (-1: none). A streaming matcher is begun at
        a new onset and fed the rows from it, else fed this row."""
        matcher = self.character.matcher
        if since < 0:
            self._open, self._view = None, None
            return
        if matcher is None or not matcher.streaming:
            self._open = since
            return
        if self._open != since:
            self._begin(since)
            self._replay(row + 1)  # the rows since the onset, all there already
        elif self._view is not None and row > self._view.start + self._view.n:  # rows skipped by push: at once
            self._replay(row + 1)
        else:
            self._feed(row)

    def _begin(self, start: int) -> None:
        self._open, self._early = start, None
        self._view = self.memory.since(start)
        self._call("matcher", "begin", self._view)

    def _feed(self, row: int) -> None:
        """Give the matcher row ``row``; it may commit, report a deviation of its commitment, and commit again after
        one."""
        if self.character.matcher is None or self._view is None:
            return
        self._view.feed(row + 1)
        if self._direct:  # call_component, without its indirections (once a frame)
            match = guarded(self.character.matcher, "observe", self._view)
        else:
            match = self._call("matcher", "observe", self._view)
        if match is None or self.character.matcher is None:
            return
        self._reported(match, "observe")

    def _reported(self, match: Any, method: str) -> None:
        """What the matcher returned after a row (by ``method``), checked and told: a deviation, or its commitment."""
        self._check_match(match, method)
        if match.stop:
            self.listener.deviated(match)
            self._stopped = self._early  # a movement that prevails after it may be committed to (Fig. 3)
        elif self._early is None or self._early is self._stopped:
            self._early = match
            self.listener.recognised(None, match)

    def _replay(self, stop: int) -> None:
        """Give the matcher the rows of the segment it follows up to ``stop`` (exclusive), all in working memory
        already: at once (:meth:`Matcher.replay <toolkit.components.Matcher.replay>`), then what it returned is
        checked and told in order, as :meth:`_feed` would after each row. Under a caller's failure policy (a world's:
        a failing matcher may be dropped between two rows) they are fed one at a time."""
        matcher, view = self.character.matcher, self._view
        if matcher is None or view is None:
            return
        if not self._direct:
            for r in range(view.start + view.n, stop):
                self._feed(r)
            return
        events = guarded(matcher, "replay", view, stop)
        try:
            events = [(int(row), match) for row, match in events]
        except (TypeError, ValueError):
            raise PluginError(self._name("matcher"), f"{type(matcher).__name__}.replay", f"returned {shown(events)}, "
                              f"expected [(row, Match), ...]") from None
        if view.n != stop - view.start:
            raise PluginError(self._name("matcher"), f"{type(matcher).__name__}.replay", f"left {view.n} rows of the segment "
                              f"from row {view.start} given, expected {stop - view.start} (up to row {stop})")
        for _, match in events:
            self._reported(match, "replay")

    def _close(self, segment: Segment, *, announce: bool = True, split: bool = False, cut: bool = False) -> Observation:
        """A segment ended: its answer.

        A streaming matcher concludes what it followed. It is fed the segment's own frames first when it did not
        follow it (the segmenter reported it only once it was over), and when it followed it without committing but
        the segmenter closed what was followed as several segments (``split``: strokes of one movement): each of
        those is matched on its own frames. A commitment made while following stands for the first of them. The
        first of them is not fed again when the matcher says it settled within its frames (:meth:`_settled_within`):
        its state is then the one feeding them again would leave, and its view is cut to the segment.
        """
        if announce:
            self.listener.segment_found(segment)
        matcher = self.character.matcher
        if matcher is None:
            self._open, self._view, self._early = None, None, None
            return Observation(segment, None, None, cut)
        followed = self._open == segment.start and self._view is not None
        if matcher.streaming and (not followed or (split and self._early is None)):
            if followed and self._settled_within(segment):  # its state on these frames is the one it has
                self._view.feed(segment.end)
            else:
                self._begin(segment.start)  # matched on its own frames
                self._replay(segment.end)
        early = self._early if self._open == segment.start else None
        late = self._call("matcher", "conclude", self.memory.motion(segment.start, segment.end))
        if late is not None and self.character.matcher is not None:
            self._check_match(late, "conclude")
            if late != early:
                self.listener.recognised(segment, late)
        self._open, self._view, self._early = None, None, None
        return _answer(segment, early, late, cut)

    def _settled_within(self, segment: Segment) -> bool:
        """Whether the matcher that followed from ``segment.start`` says (:meth:`Matcher.settled
        <toolkit.components.Matcher.settled>`: after how many frames nothing more changed, or ``None``) that nothing
        changed after the segment's frames: feeding them again from a new start would leave the state it has (the
        first stroke of a split movement; nothing was committed, so nothing was reported or learned while
        following)."""
        frames = self._call("matcher", "settled")
        return isinstance(frames, (int, np.integer)) and 0 < frames <= segment.end - segment.start

    # -- what plugins return ----------------------------------------------------------------------------------

    def _checked_block(self, result: Any, n: int, first: int) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        """``push_block``'s answer for a block of ``n`` rows from row ``first``, checked: each segment closed at a
        frame of the block, ending by that frame, ordered and disjoint; an onset (or -1) per frame, none after it."""
        name, where = self._name("segmenter"), f"{self._type('segmenter')}.push_block"
        try:
            closed, since = result
            since = np.asarray(since)
            if since.dtype.kind not in "iu" and not (since.dtype.kind == "f" and np.isfinite(since).all()
                                                     and (since == np.round(since)).all()):
                raise TypeError
            since = since.astype(np.int64).reshape(n)
            pairs = [(int(i), s) for i, s in closed]
        except (TypeError, ValueError, OverflowError):
            raise PluginError(name, where, f"returned {shown(result)}, expected ([(frame in block, Segment), ...], "
                              f"onsets ({n},))") from None
        rows = first + np.arange(n)
        bad = np.flatnonzero((since > rows) | (since < -1))
        if len(bad):
            i = int(bad[0])
            raise PluginError(name, where, f"said a segment under way began at frame {int(since[i])} after frame "
                              f"{first + i}, expected a frame from 0 up to {first + i}, or -1 for none")
        for i, segment in pairs:
            if not 0 <= i < n:
                raise PluginError(name, where, f"closed a segment at frame {i} of a block of {n}, expected 0..{n - 1}")
        pairs = sorted(pairs, key=lambda p: p[0])
        for i, segment in pairs:
            self._checked_segments([segment], "push_block", first + i + 1)
        return pairs, since

    def _checked_segments(self, segments: Any, method: str, frames: int) -> list[Segment]:
        """Segments the segmenter returned, checked: inside the ``frames`` seen so far, ordered and disjoint
        (from every segment it closed before), non-empty."""
        name, where = self._name("segmenter"), f"{self._type('segmenter')}.{method}"
        try:
            segments = list(segments)
        except TypeError:
            raise PluginError(name, where, f"returned {shown(segments)}, expected a list of Segments") from None
        for segment in segments:
            if not isinstance(segment, Segment):
                raise PluginError(name, where, f"returned {shown(segment)}, expected Segment objects")
            start, end = segment.start, segment.end
            if not (isinstance(start, (int, np.integer)) and isinstance(end, (int, np.integer))):
                raise PluginError(name, where, f"returned {shown(segment)}, expected whole frame numbers")
            if not 0 <= start < end:
                raise PluginError(name, where, f"returned an empty segment {start}..{end}, expected 0 <= start < end")
            if end > frames:
                raise PluginError(name, where, f"returned a segment {start}..{end}, which ends after the {frames} "
                                  f"frames seen, expected segments inside the stream")
            if start < self._last_end:
                raise PluginError(name, where, f"returned a segment {start}..{end} that begins before the end of the "
                                  f"segment before it ({self._last_end}), expected ordered, disjoint segments")
            self._last_end = int(end)
        return segments

    def _check_match(self, match: Any, method: str) -> None:
        check_match(self.character, match, method, self._known)

    def _name(self, key: str) -> str:
        component = getattr(self.character, key)
        return component.name if component is not None else key

    def _type(self, key: str) -> str:
        component = getattr(self.character, key)
        return type(component).__name__ if component is not None else key.capitalize()


def feed(matcher: Any, motion: Motion) -> Iterator[Match | None]:
    """Begin a streaming matcher on ``motion`` (root-relative, in the observer's own parts) and feed it the frames
    one by one, as the watching loop feeds a segment: its answer after each (``None``, a commitment, a deviation).

    The matcher is left holding the segment, so ``matcher.conclude(motion)`` and ``matcher.inspect()`` can follow.
    """
    log = ObservationLog(motion.parts, motion.fps, capacity=max(1, motion.n_frames))
    log.extend(motion.positions, motion.visible)
    memory = log.since(0)
    matcher.begin(memory)
    for row in range(motion.n_frames):
        memory.feed(row + 1)
        yield matcher.observe(memory)


def follow(matcher: Any, motion: Motion) -> tuple[Match | None, Match | None]:
    """A streaming matcher fed the frames of ``motion`` (:func:`feed`), then concluded: (its first commitment, its
    conclusion). For a streaming matcher's batch ``match``."""
    early = None
    for match in feed(matcher, motion):
        if early is None and match is not None and not match.stop:
            early = match
    return early, matcher.conclude(motion)
