"""Velocities of sampled motion: the time derivative a tracker's jitter does not pass through.

Kopp & Graeser 2006 (§4.3) read a movement's strokes from its velocity profile; a comparison that sees motion
(:mod:`plugins.matchers.comparison`) compares velocities. Differences of successive frames amplify a tracker's
frame-to-frame noise by the frame rate (1 cm of jitter at 30 frames/s is 0.4 m/s of apparent speed), so the
derivative here is a second-order Savitzky-Golay filter's over :data:`SMOOTHING` seconds: a least-squares
parabola through the frames of that window, differentiated at its middle. It passes movements slower than a few
hertz unchanged and leaves out faster wobble, at any frame rate.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SMOOTHING", "derivative", "window_frames"]

SMOOTHING = 0.2
"""Seconds of the Savitzky-Golay window (at least 5 frames): a fifth of a second, shorter than any stroke of a
human movement (K&G §4.3's strokes last a quarter of a second and more)."""


def window_frames(fps: float, window: float = SMOOTHING) -> int:
    """The frames of a Savitzky-Golay window of ``window`` seconds at ``fps``: odd, at least 5."""
    return max(5, int(round(window * fps)) | 1)


def derivative(values: np.ndarray, fps: float, window: float = SMOOTHING) -> np.ndarray:
    """The time derivative of ``values`` (n, ...) sampled ``fps`` times a second (units per second).

    A second-order Savitzky-Golay derivative over ``window`` seconds (at least 5 frames, odd; the window's own
    fit at the ends), central differences where the sequence is shorter than that, and zeros for a single frame.
    """
    from scipy.signal import savgol_filter

    values = np.asarray(values, dtype=float)
    n = len(values)
    if n < 2:
        return np.zeros_like(values)
    taps = window_frames(fps, window)
    if n >= taps:
        return savgol_filter(values, taps, 2, deriv=1, delta=1.0 / fps, axis=0, mode="interp")
    return np.gradient(values, 1.0 / fps, axis=0)
