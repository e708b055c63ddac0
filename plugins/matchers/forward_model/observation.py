"""The demonstration as the forward model reads it: the segment's working memory in the observer's motor frame.

The watching loop gives the matcher the segment's :class:`~toolkit.watching.WorkingMemory` (root-relative, in the
observer's parts, hidden parts held, never-seen parts NaN); the forward model keeps no frames of its own. It places
the rows at its own root height (finger angles as seen) and reads, for every subsystem it follows, the rows of the
subsystem's parts since the subsystem began to move and the path length each part has covered
(:mod:`~plugins.matchers.forward_model.path_length`). Each row is placed and gathered once and kept while the rows
given are not rewritten (:attr:`WorkingMemory.revision <toolkit.watching.WorkingMemory.revision>`), so a frame costs
the same whatever the length of the segment.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from plugins.matchers.forward_model.path_length import Grown, Walk, lengths

if TYPE_CHECKING:
    from plugins.matchers.forward_model.tracks import Track
    from toolkit.watching import WorkingMemory

__all__ = ["Observation", "Tracked"]


@dataclass
class Tracked:
    """What is kept of one followed subsystem between frames: its rows of the working memory
    (:meth:`Observation.observed`), their path lengths (:class:`~plugins.matchers.forward_model.path_length.Walk`),
    the rows given last, and its candidates' strokes stacked
    (:meth:`Predictions.stacked <plugins.matchers.forward_model.prediction.Predictions.stacked>`)."""

    track: Track
    rows: Grown
    walk: Walk
    last: np.ndarray | None = None
    stacked: tuple | None = None


class Observation:
    """The segment followed (:attr:`memory`, ``None`` between segments) in the motor frame of a motor system
    ``motor`` whose root is placed at ``root_height`` (P, 3: the root's rest position, 0 for finger angles)."""

    def __init__(self, motor: Any, root_height: np.ndarray) -> None:
        self.motor = motor
        self.root_height = root_height
        self.memory: WorkingMemory | None = None
        self.begin(None)

    def begin(self, memory: WorkingMemory | None) -> None:
        """Follow ``memory`` (a new segment), forgetting what was kept of the one before."""
        self.memory = memory
        self._rows: Grown | None = None  # the working memory in the motor frame, row by row
        self._last: np.ndarray | None = None
        self._tracked: dict[str, Tracked] = {}
        self._revision = 0 if memory is None else memory.revision

    def local(self) -> np.ndarray:
        """The working memory in the observer's motor frame (n, P, 3): root-relative positions placed at its own
        root height (finger angles as seen); hidden parts held, never-seen parts NaN.

        Each row is placed once and kept (the same values: each row's own sum), all of them again when rows
        already given were rewritten (:attr:`WorkingMemory.revision <toolkit.watching.WorkingMemory.revision>`: a
        part seen for the first time)."""
        memory = self.memory
        rows, n = self._rows, memory.n
        if rows is None or rows.n > n or self._revision != memory.revision:
            rows = self._rows = Grown(memory.positions.shape[1:], max(64, 2 * n))
            self._tracked, self._revision = {}, memory.revision
        if rows.n < n:
            rows.extend(memory.positions[rows.n : n] + self.root_height)
        self._last = rows.view()
        return self._last

    def at(self, row: int) -> np.ndarray:
        """One row of the working memory in the motor frame (P, 3)."""
        return self.memory.positions[row] + self.root_height

    def first(self, track: Track) -> np.ndarray:
        """The subsystem's parts where they were seen at the track's onset (k, 3)."""
        if track.first is not None:
            return track.first
        return self.at(track.onset)[self.motor.subsystems[track.subsystem]]

    def observed(self, track: Track, memory: np.ndarray) -> np.ndarray:
        """The working memory of a subsystem's parts since it is followed, (n, k, 3).

        Of the working memory :meth:`local` gave last, or of its first rows (a replay after a deviation feeds them
        one more at a time), the rows are gathered once each and kept (a view)."""
        idx = self.motor.subsystems[track.subsystem]
        if memory is None or (memory is not self._last and not self.leading(memory)):
            return memory[track.onset:, idx]
        n = len(memory) - track.onset
        kept = self._tracked.get(track.subsystem)
        if kept is None or kept.track is not track:
            kept = self._tracked[track.subsystem] = Tracked(track, Grown((len(idx), 3)), Walk(len(idx)))
        rows = kept.rows
        if rows.n > n:  # fewer rows than kept (not a replay's next row): gathered whole, not kept
            return memory[track.onset:, idx]
        if rows.n < n:
            rows.extend(memory[track.onset + rows.n :, idx])
        kept.last = rows.view()
        return kept.last

    def leading(self, memory: np.ndarray) -> bool:
        """Whether ``memory`` is the first rows of the working memory :meth:`local` gave last (a view of them, so
        the same values)."""
        local = self._last
        if local is None or memory.base is None or memory.base is not local.base or len(memory) > len(local):
            return False
        return memory.strides == local.strides and memory.shape[1:] == local.shape[1:] and \
            memory.__array_interface__["data"][0] == local.__array_interface__["data"][0]

    def walked(self, track: Track, observed: np.ndarray) -> np.ndarray:
        """``lengths(observed)`` of the rows :meth:`observed` gave last for ``track``, frame by frame
        (:class:`~plugins.matchers.forward_model.path_length.Walk`: the same values, a few rows' work a frame); of
        other rows, computed whole."""
        kept = self._tracked.get(track.subsystem)
        if kept is None or kept.track is not track or kept.last is not observed:
            return lengths(observed)
        return kept.walk.lengths(observed)

    def kept(self, track: Track) -> Tracked | None:
        """What is kept between frames of ``track``, if it is the subsystem's track followed now."""
        kept = self._tracked.get(track.subsystem)
        return kept if kept is not None and kept.track is track else None
