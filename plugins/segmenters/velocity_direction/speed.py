"""How fast the chosen parts move over the sensory memory, and how fast a tracker's jitter alone makes them seem.

Kopp & Graeser 2006, §4.1: a sensory memory of about a tenth of a second detects the onset and the end of a
movement. The paper's speed is each part's displacement over that memory (``memory`` frames) divided by its
duration. A tracker that jitters by ``sigma`` metres at 30 frames/s makes a part standing still seem to move at
about ``2.3 * sigma * 30 / 3`` m/s over a tenth of a second: 0.23 m/s for a centimetre, as fast as a slow gesture.

Two things make the speed hold on such a tracker, each a parameter of the segmenter:

- ``window``: each part's velocity is the slope of the least-squares line through its positions over the last
  ``window`` seconds (:func:`line_weights`; a Savitzky-Golay first derivative of degree 1, taken at the window's
  last frame with the lag of its middle, ``(frames - 1) / 2``). Its noise is ``sigma * fps * sqrt(12 / (w (w^2 -
  1)))`` for ``w`` frames, against ``sigma * fps * sqrt(2) / memory`` for the displacement: 2.5 times lower over
  0.2 s at 30 frames/s, more at higher rates.
- ``jitter``: the demonstrator's rest speed is at least ``jitter`` times the root-mean-square speed the tracker's
  jitter alone gives (:class:`Jitter`). The jitter is measured from the positions themselves: a second difference
  ``x[t] - 2 x[t-1] + x[t-2]`` of white noise has ``sqrt(6) sigma`` per coordinate, whereas a person's movement
  changes its velocity little from one frame to the next, so the median of its length over ``floor`` seconds
  (``1.538 * sqrt(6) * sigma`` for noise: the median of a chi distribution with three degrees of freedom) gives
  ``sigma`` of each part whether the person moves or stands. The noisiest chosen part counts.
"""

from __future__ import annotations

import warnings

import numpy as np

__all__ = ["line_weights", "line_speeds", "longer_fits", "speed_noise", "Jitter", "CHI3_MEDIAN"]

CHI3_MEDIAN = 1.5382
"""The median length of a vector of three independent standard normal coordinates."""


def line_weights(frames: int, fps: float) -> np.ndarray:
    """Weights (frames,) whose dot product with ``frames`` equally spaced samples (oldest first) is the slope, per
    second, of the least-squares line through them."""
    i = np.arange(frames) - (frames - 1) / 2.0
    return i / float(i @ i) * fps


def longer_fits(frames: int, stretch: int, fps: float) -> list[tuple[np.ndarray, int]]:
    """The line fits a ``frames``-frame window is lengthened to, up to ``stretch`` frames: twice, four times ...
    as long while shorter than ``stretch``, then ``stretch`` itself; each as its :func:`line_weights` and its delay
    (frames, the window's middle). None if ``stretch`` is no longer than ``frames``.

    Their noise falls as the window's length to the power 3/2 (see the module): doubling the window lowers the
    speed a tracker's jitter alone gives by 2.8."""
    widths = []
    w = 2 * frames
    while w < stretch:
        widths.append(w)
        w *= 2
    if stretch > frames:
        widths.append(stretch)
    return [(line_weights(w, fps), (w - 1) // 2) for w in widths]


def line_speeds(rows: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """The fastest part's speed at each frame whose ``len(weights)`` frames (it and the ones before) are in ``rows``
    (N, 3m: the chosen parts' positions): (N - len(weights) + 1,); NaN where no part is seen over the whole window.

    Each part's velocity is its positions' dot product with ``weights`` (:func:`line_weights`); a part with a value
    that is not finite in the window is not counted."""
    w = len(weights)
    n = len(rows) - w + 1
    if n <= 0:
        return np.zeros(0)
    windows = np.lib.stride_tricks.sliding_window_view(rows, w, axis=0)  # (n, 3m, w)
    velocity = (windows @ weights).reshape(n, -1, 3)
    speed = np.sqrt((velocity * velocity).sum(axis=2))
    finite = np.isfinite(speed)
    best = np.where(finite, speed, -np.inf).max(axis=1)
    return np.where(finite.any(axis=1), best, np.nan)


def speed_noise(sigma, weights: np.ndarray):
    """The root-mean-square speed (m/s; a 3-D norm) a part standing still seems to move at when its positions
    jitter by ``sigma`` (a number or an array) per coordinate and its velocity is the dot product of ``weights``
    with them."""
    return np.asarray(sigma) * np.sqrt(3.0 * float(weights @ weights))


class Jitter:
    """The tracker's jitter ``sigma`` (m a coordinate) of the noisiest chosen part, from the last ``floor`` frames'
    second differences (see the module); measured at frames 2, 4, 8, ... (as soon as there is something to measure)
    and then every ``every`` frames, and held in between, so frames pushed one by one and in blocks see the same
    values.

    Parameters
    ----------
    parts : int
        Chosen parts (each row holds 3 coordinates a part).
    floor : int
        Frames over which the median is taken.
    every : int
        Frames between two measurements.
    """

    def __init__(self, parts: int, floor: int, every: int) -> None:
        self.every = max(1, int(every))
        self.floor = max(3, int(floor))
        self._last = np.zeros((0, 3 * parts))  # the (at most two) rows before the next
        self._steps = np.zeros((0, parts))  # the last `floor` second differences' lengths
        self._parts = parts
        self.sigma = 0.0
        self._frame = -1

    def update(self, rows: np.ndarray) -> np.ndarray:
        """``sigma`` after each of the frames ``rows`` (n, 3m), the frames' own included."""
        rows = np.asarray(rows, dtype=float)
        n = len(rows)
        if not n:
            return np.zeros(0)
        full = np.concatenate([self._last, rows])
        second = (full[2:] - 2.0 * full[1:-1] + full[:-2]).reshape(-1, self._parts, 3)
        lengths = np.sqrt((second * second).sum(axis=2))  # one a block frame from its last len(lengths) frames
        steps = np.concatenate([self._steps, lengths])
        before = len(self._steps) - (n - len(lengths))  # steps row of block frame 0's second difference, if any
        frames = self._frame + 1 + np.arange(n)
        out = np.full(n, self.sigma)
        # every `every` frames, and at frames 2, 4, 8, ... before (a first measure as soon as there is one)
        early = (frames < self.every) & (frames >= 2) & ((frames & (frames - 1)) == 0)
        for f in np.flatnonzero((frames % self.every == 0) | early).tolist():
            upto = before + f + 1  # the rows up to frame f
            if upto <= 0:
                continue
            window = steps[max(0, upto - self.floor) : upto]
            finite = np.isfinite(window)
            if finite.all():
                level = np.median(window, axis=0)
            else:
                with warnings.catch_warnings():  # a part never seen in the window: no level (NaN), said here
                    warnings.simplefilter("ignore", RuntimeWarning)
                    level = np.nanmedian(np.where(finite, window, np.nan), axis=0)
            level = level[np.isfinite(level)]
            out[f:] = float(level.max()) / (CHI3_MEDIAN * np.sqrt(6.0)) if level.size else 0.0
        self.sigma = float(out[-1])
        self._frame += n
        self._steps = steps[-self.floor :]
        self._last = full[-2:]
        return out
