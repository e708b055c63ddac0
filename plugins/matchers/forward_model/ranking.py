"""The candidates ranked (B&B 2005, Fig. 13; K&G 2006, §4.4's candidates of Fig. 3): ``Match.candidates``.

Every answer of one followed subsystem carries the movements the forward models considered in the segment with their
prediction errors, the answer first and the others best first: each movement's error is the mean over the frames
followed of its best path's error in each frame, a movement that dropped out held at the error it dropped out with,
so all are measured over the same frames. An unknown answer ranks them all, and names in its details the candidate
that predicted the demonstration longest (:meth:`Ranking.nearest`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from plugins.matchers.forward_model.tracks import Track

__all__ = ["Ranking"]

Path = tuple[str, ...]


class Ranking:
    """What each candidate path stands for in a motor system ``motor``, and the candidates of a segment ranked."""

    def __init__(self, motor: Any) -> None:
        self.motor = motor
        self._keys: dict[Path, str] = {}  # path -> movement (:meth:`movement_key`)
        self._version: tuple | None = None

    def movement_key(self, path: Path) -> str:
        """What a candidate stands for: the labelled movement its sequences are examples of, else its first command.

        Kept per path while the motor system's labels are the same table of the same size (only labelled sequences
        name a movement, and a labelled sequence is added with its label; :meth:`ranked` asks for every path a
        segment predicted)."""
        labels = getattr(self.motor, "labels", None)
        if not isinstance(labels, dict):
            label = self.motor.label_of_path(path)
            return label if label is not None else path[0]
        version = (id(labels), len(labels))
        if self._version != version:
            self._keys, self._version = {}, version
        key = self._keys.get(path)
        if key is None:
            label = self.motor.label_of_path(path)
            key = self._keys[path] = label if label is not None else path[0]
        return key

    def ranked(self, track: Track | None, answer: str | None = None,
               path: Path = ()) -> tuple[tuple[str, float], ...]:
        """The movements a subsystem's forward models considered in this segment, with their prediction errors,
        best first: each movement's error is the mean, over the frames the subsystem has been followed, of the error
        of its best candidate path in each frame; from the frame it dropped out on, the error it dropped out with (it
        is taken to be as far off from then as when it was last predicted), so every movement is measured over the
        same frames. ``answer`` (the movement of the committed ``path``) comes first, with its movement's error;
        the others follow by error. Empty when nothing was predicted."""
        if track is None or not track.trace:
            return ()
        keys: dict[Path, str] = {}
        sums: dict[str, float] = {}
        seen: dict[str, tuple[int, int, float, int]] = {}  # movement -> (first frame index, frames, last, last index)
        for i, (_, errors) in enumerate(track.trace):
            best: dict[str, float] = {}
            for candidate, error in errors.items():
                key = keys.get(candidate)
                if key is None:
                    key = keys[candidate] = self.movement_key(tuple(candidate)) if candidate else ""
                if error < best.get(key, np.inf):
                    best[key] = error
            for key, error in best.items():
                first, count, _, _ = seen.get(key, (i, 0, 0.0, i))
                seen[key] = (first, count + 1, error, i)
                sums[key] = sums.get(key, 0.0) + error
        n = len(track.trace)
        value = {key: (sums[key] + last * (n - 1 - at)) / (n - first) for key, (first, _, last, at) in seen.items()
                 if key and math.isfinite(sums[key])}
        own = self.movement_key(tuple(path)) if path else None
        ranked = sorted(((key, float(v)) for key, v in value.items() if key != own), key=lambda kv: (kv[1], kv[0]))
        if answer is None:
            return tuple(ranked)
        return ((answer, float(value.get(own, np.nan))), *ranked)

    def nearest(self, track: Track | None) -> dict[str, Any]:
        """For an unknown answer: the candidate of ``track`` (the first subsystem to move) that predicted the
        demonstration longest before it was dropped (``nearest``, its movement), for how many frames
        (``predicted_frames``) and its error then (``error_when_dropped``)."""
        if track is None or not track.trace:
            return {}
        last: dict[Path, tuple[int, float]] = {}
        for frame, errors in track.trace:
            for path, error in errors.items():
                last[path] = (frame, error)
        path, (frame, error) = max(last.items(), key=lambda kv: (kv[1][0], -kv[1][1]))
        label = self.movement_key(tuple(path)) if path else None
        return {"nearest": label, "predicted_frames": int(frame), "error_when_dropped": float(error)}
