"""likeme-stillness: a third-party segmenter for likeme.

A segment is a stretch where the fastest of the target's visible parts,
root-relative, moves faster than a threshold; it ends once the body has been still
for ``hold`` seconds. Unlike ``hub-threshold`` it knows nothing of the
observer's own poses, so it also cuts movements that never pass through a hub; but a pose held longer than ``hold`` ends a segment too.
"""

from __future__ import annotations

import numpy as np

from toolkit import Parameter, Segment, Segmenter, hookimpl


class Stillness(Segmenter):
    """Segments where the visible parts move faster than `speed` (m/s), ended by `hold` seconds of rest."""

    name = "stillness"
    parameters = (
        Parameter("speed", float, 0.1, "Speed (m/s) of the fastest visible part above which the body counts as moving.", minimum=0.0),
        Parameter("hold", float, 0.3, "Seconds of rest that end a segment.", minimum=0.0),
        Parameter("min_duration", float, 0.2, "Segments shorter than this (seconds) are dropped.", minimum=0.0),
    )

    def reset(self, parts, fps):
        self._fps = fps
        self._prev = None
        self._frame = -1
        self._start = None
        self._still = 0

    @property
    def active_since(self):
        return self._start

    def push(self, pose, visible):
        self._frame += 1
        pose = np.where(visible[:, None], pose, np.nan)
        moving = False
        if self._prev is not None:
            step = np.linalg.norm(pose - self._prev, axis=1)
            step = step[np.isfinite(step)]
            moving = bool(step.size) and float(step.max()) * self._fps > self.params["speed"]
        self._prev = pose
        if moving:
            if self._start is None:
                self._start = max(self._frame - 1, 0)
            self._still = 0
            return []
        if self._start is not None:
            self._still += 1
            if self._still >= max(1, round(self.params["hold"] * self._fps)):
                return self._close(self._frame - self._still + 1)
        return []

    def flush(self):
        return self._close(self._frame + 1) if self._start is not None else []

    def _close(self, end):
        start, self._start, self._still = self._start, None, 0
        if end - start < max(1, round(self.params["min_duration"] * self._fps)):
            return []
        return [Segment(start, end, self._fps)]


@hookimpl
def likeme_register_segmenters():
    return [Stillness]
