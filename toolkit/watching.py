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
                                             matcher.observe(memory) may commit once (response facilitation),
                                             and after that report a deviation (details["stop"])

An :class:`~toolkit.runtime.Actor` in a world feeds it one frame a step from its perception and turns what it
reports into run events, interpretation and imitation; an :class:`~toolkit.observe.Observer` feeds it packets of
recorded or live frames and returns :class:`Observation` s. What the loop reports reaches them through a
:class:`Listener`; every call into a component goes through a ``call`` function that applies the caller's failure
policy (:func:`call_component` names the failing plugin; a world in skip mode drops it).

Working memory rows count from the first frame of the stream (``reset``); a :class:`Segment`'s frames are rows.
A matcher reads the segment it follows through a :class:`WorkingMemory`, a view of the rows it has been given so
far: it keeps no frames of its own.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from toolkit.components import Match, Segment
from toolkit.errors import ConfigError, LikemeError, PluginError
from toolkit.motion import Motion, fill_hidden, part_index

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.character import Character

__all__ = ["ObservationLog", "WorkingMemory", "Observation", "Listener", "WatchingLoop", "call_component", "feed",
           "follow"]


class ObservationLog:
    """Working memory of what an observer perceived of its target, as growing arrays in the observer's own parts.

    One row per frame since watching began: ``positions`` (F, P, 3) root-relative, ``visible`` (F, P), and
    ``world`` (F, P, 3), the parts' world positions. Hidden parts follow the one rule of
    :func:`toolkit.motion.fill_hidden`, kept up as frames arrive: a hidden part holds its last seen value; when a
    part is seen for the first time, the rows before are set to that sighting; a part not seen yet is NaN.
    """

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
        start, end = self.n, self.n + k
        if end > len(self._pos):
            self._reserve(end)
        self._vis[start:end] = visible
        self._pos[start:end] = self._held(self._pos, poses, visible)
        if world is not None:
            self._world[start:end] = self._held(self._world, np.asarray(world, dtype=float), visible)
        if not self._all_seen:
            first = ~self._seen & visible.any(axis=0)
            if first.any() and start:  # seen for the first time: the rows before hold that sighting
                self._pos[:start, first] = self._pos[start:end][np.argmax(visible[:, first], axis=0), first]
                self._world[:start, first] = self._world[start:end][np.argmax(visible[:, first], axis=0), first]
            self._seen |= visible.any(axis=0)
            self._all_seen = bool(self._seen.all())
        self.n = end

    def _held(self, store: np.ndarray, values: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """``values`` with hidden parts filled by the rule, continuing from the row before (the last seen values)."""
        if visible.all():
            return values
        if self.n and len(values) == 1 and self._all_seen:  # one frame, every part seen before: hold the last row
            return np.where(visible[..., None], values, store[self.n - 1])
        if self.n:
            before = store[self.n - 1][None]
            return fill_hidden(np.concatenate([before, values]), np.concatenate([self._seen[None], visible]))[1:]
        return fill_hidden(values, visible)

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
        """Root-relative positions (F, P, 3), hidden parts held (a view: do not write)."""
        return self._pos[: self.n]

    @property
    def visible(self) -> np.ndarray:
        """Which parts were seen in each frame (F, P)."""
        return self._vis[: self.n]

    @property
    def world(self) -> np.ndarray:
        """World positions (F, P, 3) as perceived, hidden parts held; NaN where never seen or not given."""
        return self._world[: self.n]

    def motion(self, start: int = 0, stop: int | None = None) -> Motion:
        """Rows ``start`` to ``stop`` as a root-relative :class:`Motion` (a copy), with their world positions."""
        stop = self.n if stop is None else min(stop, self.n)
        return Motion(self._pos[start:stop].copy(), self.fps, self.parts, self._vis[start:stop],
                      self._world[start:stop].copy())

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
    def fps(self) -> float:
        return self._log.fps

    @property
    def parts(self) -> tuple[str, ...]:
        return self._log.parts

    @property
    def positions(self) -> np.ndarray:
        """Root-relative positions (n, P, 3) of the frames given so far (a view: do not write)."""
        return self._log._pos[self.start : self._stop]

    @property
    def visible(self) -> np.ndarray:
        """Which parts were seen (n, P)."""
        return self._log._vis[self.start : self._stop]

    @property
    def world(self) -> np.ndarray:
        """World positions (n, P, 3) as perceived."""
        return self._log._world[self.start : self._stop]

    def motion(self) -> Motion:
        """The frames given so far as a root-relative :class:`Motion` (a copy)."""
        return self._log.motion(self.start, self._stop)

    def __repr__(self) -> str:
        return f"WorkingMemory(rows {self.start}..{self._stop} of {self._log.n})"


@dataclass(frozen=True)
class Observation:
    """One segment found in the stream and what the matcher made of it.

    ``decided_at`` is the number of frames into the segment at which the matcher committed (``None``: at its
    end); ``match`` is ``None`` without a matcher.
    """

    segment: Segment
    match: Match | None
    decided_at: int | None

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
        """After committing, the matcher found the demonstration deviating from it (``match.details["stop"]``)."""


def call_component(character: Character, key: str, method: str, *args: Any, **kwargs: Any) -> Any:
    """Call ``character.<key>.<method>(...)``; anything but a likeme error becomes a :class:`PluginError` naming the
    component and the method. ``None`` if the character has no such component."""
    component = getattr(character, key)
    if component is None:
        return None
    try:
        return getattr(component, method)(*args, **kwargs)
    except LikemeError:
        raise
    except Exception as exc:
        raise PluginError(component.name, f"{type(component).__name__}.{method}", f"{type(exc).__name__}: {exc}") from exc


def _answer(segment: Segment, early: Match | None, late: Match | None) -> Observation:
    """The matcher's answer for a segment: what it concluded at the end, else what it committed to early."""
    if late is None and early is not None:
        return Observation(segment, early, early.decided_at)
    return Observation(segment, late if late is not None else Match.unknown(), None)


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
    """

    def __init__(self, character: Character, *, call: Callable[..., Any] | None = None,
                 listener: Listener | None = None) -> None:
        self.character = character
        self._call = call or (lambda key, method, *a, **k: call_component(character, key, method, *a, **k))
        self.listener = listener or Listener()
        self.memory = ObservationLog(character.body.parts, 30.0, capacity=1)
        self.perceived: ObservationLog | None = None  # before correspondence (only with one)
        self._index = np.arange(len(character.body.parts))
        self._same = True  # the observed body's parts are the observer's, in order
        self._open: int | None = None  # start row of the segment the matcher follows
        self._view: WorkingMemory | None = None
        self._early: Match | None = None

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
            held, seen = self.perceived.positions[first:], self.perceived.visible[first:]
            mapped = self._call("correspondence", "map_block", held, seen)
            if self.character.correspondence is not None:  # not dropped under a skip policy
                mapped = np.asarray(mapped, dtype=float)
                if mapped.shape != held.shape:
                    raise PluginError(self.character.correspondence.name, "Correspondence.map_block",
                                      f"returned an array of shape {mapped.shape}, expected {held.shape}")
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
            return []
        result = self._call("segmenter", "push_block", self.memory.positions[first:], self.memory.visible[first:])
        if self.character.segmenter is None:  # dropped (skip policy)
            return []
        closed, since = self._checked_block(result, n)
        out: list[Observation] = []
        k = 0
        for i in range(n):
            here = []
            while k < len(closed) and closed[k][0] == i:
                here.append(closed[k][1])
                k += 1
            out.extend(self._close(s, split=len(here) > 1) for s in here)
            self._follow(int(since[i]), first + i)
        return out

    def flush(self) -> list[Observation]:
        """End of the stream: the segment under way, if the segmenter accepts it."""
        if self.character.segmenter is None:
            return []
        closed = self._call("segmenter", "flush")
        if self.character.segmenter is None:
            return []
        segments = self._checked_segments(closed or [], "flush")
        return [self._close(s, split=len(segments) > 1) for s in segments]

    def classify(self, poses: np.ndarray, visible: np.ndarray, world: np.ndarray | None = None) -> Observation:
        """Frames (n, S, 3) taken as one whole segment, without the segmenter: what the matcher makes of them, and
        when (a streaming matcher is fed them one by one and may commit early)."""
        first = self._remember(poses, visible, world)
        segment = Segment(first, max(first + 1, self.memory.n), self.memory.fps)
        return self._close(segment, announce=False)

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
            rows = range(since, row + 1)
        else:
            rows = range(row, row + 1)
        for r in rows:
            self._feed(r)

    def _begin(self, start: int) -> None:
        self._open, self._early = start, None
        self._view = self.memory.since(start)
        self._call("matcher", "begin", self._view)

    def _feed(self, row: int) -> None:
        """Give the matcher row ``row``; it may commit (once per segment) or report a deviation."""
        if self.character.matcher is None or self._view is None:
            return
        self._view.feed(row + 1)
        match = self._call("matcher", "observe", self._view)
        if match is None:
            return
        self._check_match(match, "observe")
        if match.details.get("stop"):
            self.listener.deviated(match)
        elif self._early is None:
            self._early = match
            self.listener.recognised(None, match)

    def _close(self, segment: Segment, *, announce: bool = True, split: bool = False) -> Observation:
        """A segment ended: its answer.

        A streaming matcher concludes what it followed. It is fed the segment's own frames first when it did not
        follow it (the segmenter reported it only once it was over), and when it followed it without committing but
        the segmenter closed what was followed as several segments (``split``: strokes of one movement): each of
        those is matched on its own frames. A commitment made while following stands for the first of them.
        """
        if announce:
            self.listener.segment_found(segment)
        matcher = self.character.matcher
        if matcher is None:
            self._open, self._view, self._early = None, None, None
            return Observation(segment, None, None)
        followed = self._open == segment.start and self._view is not None
        if matcher.streaming and (not followed or (split and self._early is None)):
            self._begin(segment.start)  # matched on its own frames, fed one by one
            for r in range(segment.start, segment.end):
                self._feed(r)
        early = self._early if self._open == segment.start else None
        late = self._call("matcher", "conclude", self.memory.motion(segment.start, segment.end))
        if late is not None:
            self._check_match(late, "conclude")
            if late != early:
                self.listener.recognised(segment, late)
        self._open, self._view, self._early = None, None, None
        return _answer(segment, early, late)

    # -- what plugins return ----------------------------------------------------------------------------------

    def _checked_block(self, result: Any, n: int) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        name = self._name("segmenter")
        try:
            closed, since = result
            since = np.asarray(since, dtype=int).reshape(n)
            pairs = [(int(i), s) for i, s in closed]
        except (TypeError, ValueError):
            raise PluginError(name, "Segmenter.push_block", f"returned {result!r}, expected ([(frame in block, "
                              f"Segment), ...], onsets ({n},))") from None
        for i, segment in pairs:
            if not 0 <= i < n:
                raise PluginError(name, "Segmenter.push_block", f"closed a segment at frame {i} of a block of {n}")
        self._checked_segments([s for _, s in pairs], "push_block")
        return sorted(pairs, key=lambda p: p[0]), since

    def _checked_segments(self, segments: Any, method: str) -> list[Segment]:
        for segment in segments:
            if not isinstance(segment, Segment):
                raise PluginError(self._name("segmenter"), f"Segmenter.{method}",
                                  f"returned {segment!r}, expected Segment objects")
            if segment.end > self.memory.n:
                raise PluginError(self._name("segmenter"), f"Segmenter.{method}",
                                  f"returned {segment!r}, which ends after the {self.memory.n} frames seen")
        return list(segments)

    def _check_match(self, match: Any, method: str) -> None:
        if not isinstance(match, Match):
            raise PluginError(self._name("matcher"), f"Matcher.{method}", f"returned {match!r}, expected a Match")

    def _name(self, key: str) -> str:
        component = getattr(self.character, key)
        return component.name if component is not None else key


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
        if early is None and match is not None and not match.details.get("stop"):
            early = match
    return early, matcher.conclude(motion)
