"""What an observer saw of the world around its target: the objects, frame by frame (Buchsbaum & Blumberg 2005, §6.1).

Working memory (:class:`toolkit.watching.ObservationLog`) holds what an observer perceived of its target's body;
:class:`Sightings` holds the rest of each percept, on the same rows (row 0 is the first percept since watching
began): the target's heading as perceived, and every object seen, where, what it looked like and how big. An
observer's conclusions about another (behaviour identification, §6.1-6.3) are drawn from these two records only,
never from the world.

What the record says of an object at a row is what the observer last knew of it then:

- an object never seen before that row does not exist for the observer;
- an object seen before but not at that row (hidden, or out of view) is where it was last seen;
- an object that was not seen where the observer's eye should have seen it (:meth:`Perception.in_view
  <toolkit.components.Perception.in_view>`) more than :data:`CARRIED` seconds after it was last seen is gone from
  then on, until it is seen again (eaten, taken away); missed sooner, it may have been carried out of sight a moment
  (a cheese in a hand that went behind the head).

Bounded like working memory: rows older than ``keep`` seconds, or than the first row working memory still holds
(:meth:`forget`), are dropped, except each object's last sighting before them, so an object seen long ago is still
where it was last seen.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["CARRIED", "Sighting", "Sightings"]

CARRIED = 0.5
"""Seconds after its last sighting during which an object missed where it was is not yet gone: it may have been
carried out of sight (a cheese in a hand that went behind the head); missed after that, it is gone."""


@dataclass(frozen=True)
class Sighting:
    """An object as the observer last saw it up to a row: where, what it looked like, when."""

    name: str
    kind: str | None
    position: np.ndarray
    radius: float
    row: int


class _Track:
    """One object's sightings: rows (ascending), positions, and the rows from which it was known to be gone."""

    __slots__ = ("rows", "positions", "n", "kind", "radius", "gone")

    def __init__(self) -> None:
        self.rows = np.zeros(16, dtype=np.int64)
        self.positions = np.zeros((16, 3))
        self.n = 0
        self.kind: str | None = None
        self.radius = 0.0
        self.gone: list[int] = []  # rows at which it was missed where it should have been seen

    def add(self, row: int, position: np.ndarray) -> None:
        if self.n == len(self.rows):
            self.rows = np.concatenate([self.rows, np.zeros_like(self.rows)])
            self.positions = np.concatenate([self.positions, np.zeros_like(self.positions)])
        self.rows[self.n], self.positions[self.n] = row, position
        self.n += 1

    def last(self, row: int) -> int:
        """Index of the last sighting at or before ``row`` (-1: none)."""
        return int(np.searchsorted(self.rows[: self.n], row, side="right")) - 1

    def drop_before(self, row: int) -> None:
        """Drop sightings before ``row`` but the last of them (it still says where the object was last seen)."""
        i = self.last(row - 1)  # the last sighting before ``row``
        if i <= 0:
            return
        k = self.n - i
        self.rows[:k], self.positions[:k] = self.rows[i : self.n].copy(), self.positions[i : self.n].copy()
        self.n = k
        first = int(self.rows[0])
        self.gone = [g for g in self.gone if g > first]  # earlier misses are before every sighting still held


class Sightings:
    """Per row of working memory: the target's perceived heading and the objects seen (see the module's text).

    Parameters
    ----------
    fps : float
        Frame rate of the rows.
    keep : float
        Seconds of rows kept (older sightings are dropped, except each object's last).
    start : int
        The row of the first record (rows before it were perceived before this record began: nothing is known of
        them).
    """

    def __init__(self, fps: float, keep: float = 120.0, start: int = 0) -> None:
        self.fps = float(fps)
        self.keep = max(1, int(round(keep * fps)))
        self.n = int(start)
        self.offset = int(start)  # the first row whose headings are held
        self._heading = np.full(1024, np.nan)
        self._objects: dict[str, _Track] = {}

    def record(self, row: int, heading: float, objects: Mapping[str, Any], kinds: Mapping[str, str] | None = None,
               sizes: Mapping[str, float] | None = None, missed: Any = ()) -> None:
        """The percept of row ``row`` (the next row): the target's ``heading``, the ``objects`` seen (name to world
        position) with their ``kinds`` and ``sizes``, and the names of remembered objects ``missed`` where they
        should have been seen."""
        if row != self.n:
            raise ValueError(f"sightings are recorded in order: row {row} after {self.n} rows")
        i = row - self.offset
        if i >= len(self._heading):
            self._heading = np.concatenate([self._heading, np.full(len(self._heading), np.nan)])
        self._heading[i] = heading if np.isfinite(heading) else np.nan
        kinds, sizes = kinds or {}, sizes or {}
        for name, position in objects.items():
            position = np.asarray(position, dtype=float).reshape(3)
            if not np.isfinite(position).all():
                continue
            track = self._objects.get(name)
            if track is None:
                track = self._objects[name] = _Track()
            track.add(row, position)
            if name in kinds:
                track.kind = kinds[name]
            if name in sizes:
                track.radius = float(sizes[name])
        for name in missed:
            track = self._objects.get(name)
            if track is not None and not self._carried(track, row):
                track.gone.append(row)
        self.n += 1
        if self.n - self.offset > 2 * self.keep:
            self.forget(self.n - self.keep)

    def _carried(self, track: _Track, row: int) -> bool:
        """Whether an object missed at ``row`` may still be about, out of sight a moment: it was last seen at most
        :data:`CARRIED` seconds before (carried behind the head, say), so missing it proves nothing yet."""
        return track.n > 0 and row - int(track.rows[track.n - 1]) <= CARRIED * self.fps

    def remembered(self, row: int | None = None) -> dict[str, np.ndarray]:
        """Where each object the observer still believes in was last seen, at ``row`` (default: the newest)."""
        return {s.name: s.position for s in self.at(self.n - 1 if row is None else row).values()}

    def at(self, row: int) -> dict[str, Sighting]:
        """Every object as last seen at or before ``row``, and not gone since: name to :class:`Sighting`."""
        out = {}
        for name, track in self._objects.items():
            i = track.last(row)
            if i < 0:
                continue  # never seen by then
            seen = int(track.rows[i])
            if any(seen < g <= row for g in track.gone):
                continue  # missed where it should have been seen, after it was last seen
            out[name] = Sighting(name, track.kind, track.positions[i].copy(), track.radius, seen)
        return out

    def track(self, name: str, row: int) -> tuple[np.ndarray, np.ndarray]:
        """The rows (k,) and positions (k, 3) at which ``name`` was seen up to ``row`` (the ones still held)."""
        track = self._objects.get(name)
        if track is None:
            return np.zeros(0, dtype=np.int64), np.zeros((0, 3))
        i = track.last(row) + 1
        return track.rows[:i].copy(), track.positions[:i].copy()

    def heading(self, row: int) -> float:
        """The target's heading as perceived at ``row`` (the nearest held row with one; NaN: never found)."""
        held = self._heading[: self.n - self.offset]
        known = np.flatnonzero(np.isfinite(held))
        if not len(known):
            return float("nan")
        i = row - self.offset
        return float(held[known[np.argmin(np.abs(known - i))]])

    def forget(self, before: int) -> None:
        """Rows before ``before`` are no longer needed: drop them (each object's last sighting before stays)."""
        before = min(int(before), self.n)
        dead = before - self.offset
        if dead <= 0:
            return
        held = self.n - before
        heading = np.full(max(2 * held, 1024), np.nan)
        heading[:held] = self._heading[dead : dead + held]
        self._heading = heading
        self.offset = before
        for track in self._objects.values():
            track.drop_before(before)

    @property
    def size(self) -> int:
        """Sightings held (all objects): what the bound keeps small."""
        return sum(t.n for t in self._objects.values())
