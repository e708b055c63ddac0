"""A part's path cut into strokes where it turns back: what a movement does, whatever its tempo and held place.

Kopp & Graeser 2006, §4.3, cut a movement into guiding strokes at the minima of its speed; a wave is a stroke out to
where the hand is held, one stroke each way per swing, and a stroke back. Cut that way, a tracker's jitter makes a
minimum of the speed wherever the hand moves slowly, and a slow wave is cut into many pieces (measured on the hand
gestures: ``docs/matchers.md``). Here a stroke ends where the path *turns back*: where the part, having gone
farthest from the stroke's start, has come back towards it by ``reversal`` (the hysteresis of a zigzag). Jitter
smaller than ``reversal`` never turns a path back, a stroke that only slows down goes on, and what is left is the
sequence of excursions: out, one per swing, back. Each stroke is its displacement, start to end (the path is
smoothed first, over ``smooth`` seconds, a Savitzky-Golay fit of the second order, so that a reversal is read off
the movement rather than off one noisy frame).

The strokes know nothing of time: a performance four times slower gives the same strokes, and a wave of seven
swings the same strokes as one of four, only more of them. Nor do they know where the part is held, except through
the strokes that take it there and back.
"""

from __future__ import annotations

import numpy as np

from plugins.lib.compiled import kernel

__all__ = ["parts_strokes", "reversal_strokes"]


def reversal_strokes(path: np.ndarray, fps: float, reversal: float, smooth: float = 0.0) -> np.ndarray:
    """The strokes (k, 3) of ``path`` (n, 3), sampled ``fps`` times a second: the displacement of each excursion, cut
    where the path has come back by ``reversal`` (in the path's unit) from the farthest it went from the stroke's
    start (see the module). ``smooth``: seconds of Savitzky-Golay smoothing first (0: none; a window of at least 5
    frames, odd, used only where the path is longer). The last excursion counts where it went at least ``reversal``
    from its start; a path that never goes that far has no stroke."""
    return parts_strokes(np.asarray(path, dtype=float)[:, None], fps, reversal, smooth)[0]


def parts_strokes(paths: np.ndarray, fps: float, reversal: float, smooth: float = 0.0) -> list[np.ndarray]:
    """:func:`reversal_strokes` of each part's path in ``paths`` (n, P, 3), the smoothing done for every part at
    once: one array of strokes (k, 3) per part."""
    paths = np.asarray(paths, dtype=float)
    if len(paths) < 2:
        return [np.zeros((0, 3)) for _ in range(paths.shape[1])]
    width = int(round(smooth * fps)) | 1
    if smooth > 0 and width >= 5 and len(paths) > width:
        from scipy.signal import savgol_filter

        paths = savgol_filter(paths, width, 2, axis=0)
    out = np.empty((len(paths), 3))
    strokes = []
    for p in range(paths.shape[1]):
        count = kernel(_zigzag)(np.ascontiguousarray(paths[:, p]), float(reversal), out)
        strokes.append(out[:count].copy())
    return strokes


def _zigzag(path: np.ndarray, reversal: float, out: np.ndarray) -> int:
    """The strokes of ``path`` into ``out`` (:func:`reversal_strokes`), their number returned. The reference loop,
    compiled where numba is installed (:func:`plugins.lib.compiled.kernel`)."""
    count = 0
    sx, sy, sz = path[0, 0], path[0, 1], path[0, 2]  # the stroke's start
    fx, fy, fz = sx, sy, sz  # the farthest point from it so far
    far = 0.0
    for t in range(1, len(path)):
        x, y, z = path[t, 0], path[t, 1], path[t, 2]
        gone = np.sqrt((x - sx) ** 2 + (y - sy) ** 2 + (z - sz) ** 2)
        if gone > far:
            fx, fy, fz, far = x, y, z, gone
        elif np.sqrt((x - fx) ** 2 + (y - fy) ** 2 + (z - fz) ** 2) >= reversal:
            out[count, 0], out[count, 1], out[count, 2] = fx - sx, fy - sy, fz - sz
            count += 1
            sx, sy, sz = fx, fy, fz
            fx, fy, fz = x, y, z
            far = np.sqrt((x - sx) ** 2 + (y - sy) ** 2 + (z - sz) ** 2)
    if far >= reversal:
        out[count, 0], out[count, 1], out[count, 2] = fx - sx, fy - sy, fz - sz
        count += 1
    return count
