"""How much of a recording is a tracker's jitter: each part's noise, measured on the recording itself.

A tracker places each joint within a centimetre or two from frame to frame (a depth camera's skeleton tracker, the
hands most; :mod:`plugins.lib.lowpass`), independently from frame to frame. Compared frame by frame, two
recordings of the same movement then differ by the noise of both, and a recording differs from standing still by
its own: squared, ``E|x + n - y - m|^2 = |x - y|^2 + E|n|^2 + E|m|^2``. A comparison that sees motion
(:mod:`plugins.matchers.comparison`) compares velocities too, which a derivative makes noisier still, so on a
tracker's recordings every distance grows by a floor that says nothing of the movements, the more the noisier the
tracker: with 1-2 cm of jitter, performances of one hand gesture lie twice as far apart as recorded clean. The
comparison keeps that floor with each sequence's frames (:attr:`plugins.matchers.comparison.Frames.noise`), and path
search subtracts it from its squared distances (:func:`plugins.matchers.tempo.less_jitter`), which leaves an
estimate of the squared distance of the movements themselves.

:func:`jitter_variance` measures each part's noise on the recording: the residual of a quadratic Savitzky-Golay
smoothing over :data:`plugins.lib.velocity.SMOOTHING` seconds, which a person's movement (below a few hertz) passes
almost unchanged and white noise does not. Its median over the frames is robust to the few frames where a fast
movement leaves a residual of its own. :func:`feature_noise` carries the variance through what the comparison does
with the positions before it compares them: the derivative of :mod:`plugins.lib.velocity`, and for a motion known
whole the low-pass of :mod:`plugins.lib.lowpass`, each by the energy of its impulse response, computed with those
very functions.
"""

from __future__ import annotations

import functools

import numpy as np

from toolkit import Motion

__all__ = ["feature_noise", "jitter_about_root", "jitter_variance"]

_CHI2_3_MEDIAN = 2.3660
"""The median of a chi-square variable with three degrees of freedom (its mean is 3): a Gaussian jitter's squared
length in three dimensions, over its variance per axis."""


@functools.lru_cache(maxsize=64)
def _residual_weights(fps: float) -> np.ndarray:
    """The weights that give a frame's residual from the quadratic Savitzky-Golay smoothing over its window (odd, at
    least 5 frames, :data:`plugins.lib.velocity.SMOOTHING` seconds): one at the middle frame less the smoothing's."""
    from scipy.signal import savgol_coeffs

    from plugins.lib.velocity import window_frames

    taps = window_frames(fps)
    weights = -savgol_coeffs(taps, 2)
    weights[taps // 2] += 1.0
    return weights


def jitter_variance(positions: np.ndarray, seen: np.ndarray, fps: float) -> np.ndarray:
    """Each part's jitter, as its variance along one axis (m^2), (P,): from ``positions`` (n, P, 3) sampled ``fps``
    times a second, where ``seen`` (n, P).

    The residual of a quadratic least-squares fit over each frame's window (the Savitzky-Golay smoothing) is, for
    white noise of variance ``s^2`` per axis, Gaussian with variance ``s^2 (1 - w)``, ``w`` the fit's weight on its
    middle frame (the sum of the residual weights' squares); its squared length over three axes is that times a
    chi-square of three degrees of freedom, whose median is :data:`_CHI2_3_MEDIAN`. Only frames whose whole window
    the part is seen in count, away from the ends (what stands in a hidden frame takes no part in them). A part with
    fewer such frames than one window, or a recording shorter than two windows: 0 (nothing to measure).
    """
    from scipy.ndimage import correlate1d

    positions = np.asarray(positions, dtype=float)
    seen = np.asarray(seen, dtype=bool) & np.isfinite(positions).all(axis=-1)
    n, parts = seen.shape
    weights = _residual_weights(float(fps))
    taps, half = len(weights), len(weights) // 2
    out = np.zeros(parts)
    if n < 2 * taps:
        return out
    runs = np.concatenate([np.zeros((1, parts)), np.cumsum(seen, axis=0)])
    whole = (runs[taps:] - runs[: n - taps + 1]) == taps  # (n - taps + 1, P): frames half .. n - half - 1
    measured = np.flatnonzero(whole.sum(axis=0) >= taps)
    if not len(measured):
        return out
    filled = positions[:, measured]
    if not seen[:, measured].all():  # a hidden frame's residuals are never counted: any finite number will do
        filled = np.where(seen[:, measured, None], filled, 0.0)
    residual = correlate1d(filled, weights, axis=0, mode="nearest")[half : n - half]
    square = np.einsum("npk,npk->np", residual, residual)
    scale = _CHI2_3_MEDIAN * float(weights @ weights)
    if whole[:, measured].all():
        out[measured] = np.median(square, axis=0) / scale
        return out
    for j, part in enumerate(measured):
        out[part] = np.median(square[whole[:, part], j]) / scale
    return out


def jitter_about_root(positions: np.ndarray, visible: np.ndarray, fps: float, body) -> np.ndarray:
    """Each part's jitter about the ``body``'s root (:func:`jitter_variance`: variance per axis, m^2, (P,)) in
    ``positions`` (n, P, 3) seen where ``visible`` (n, P) and finite: what a clip's file or a watched segment gives,
    before anything smooths it. Turning the positions into the body's frame does not change a variance, and the
    facing turns slowly. A joint angle (a finger's) is not a position: 0."""
    positions = np.asarray(positions, dtype=float)
    seen = np.asarray(visible, dtype=bool) & np.isfinite(positions).all(axis=-1)
    root = body.root_index
    jitter = jitter_variance(positions - positions[:, root : root + 1], seen & seen[:, root : root + 1], fps)
    jitter[np.asarray(body.angle_mask, dtype=bool)] = 0.0
    return jitter


def feature_noise(variance: np.ndarray, fps: float, frames: int, low_passed: bool = False) -> np.ndarray:
    """The squared jitter each part brings to what a comparison compares, (P, 2): of its position (m^2) and of its
    velocity ((m/s)^2, :func:`plugins.lib.velocity.derivative`), three axes together, for a part whose jitter has
    ``variance`` (P,) per axis, in a recording of ``frames`` frames at ``fps``; ``low_passed``: the recording was
    low-passed first (:func:`plugins.lib.lowpass.low_passed`, a motion known whole).

    White noise through a linear filter keeps the energy of the filter's impulse response: the impulse is put
    through the same functions the recording went through, in the middle of a recording of its length (a short
    recording the low-pass leaves as it is, it leaves the impulse too)."""
    variance = np.asarray(variance, dtype=float)
    n = max(int(frames), 1)
    if not low_passed:  # the derivative's windows about the middle of any recording as long are the same
        n = min(n, 2 * len(_residual_weights(float(fps))) + 1)
    gains = np.asarray(_gains(float(fps), n, bool(low_passed)))
    return 3.0 * variance[:, None] * gains[None, :]


@functools.lru_cache(maxsize=256)
def _gains(fps: float, n: int, low_passed: bool) -> tuple[float, float]:
    """:func:`feature_noise`'s energies of the impulse responses, of the position and of the velocity."""
    from plugins.lib.lowpass import low_passed as low_pass
    from plugins.lib.velocity import derivative

    impulse = np.zeros((n, 1, 3))
    impulse[n // 2, 0, 0] = 1.0
    if low_passed:
        impulse = low_pass(Motion(impulse, fps, ("part",))).positions
    response = impulse[:, 0, 0]
    velocity = derivative(impulse, fps)[:, 0, 0]
    return float(response @ response), float(velocity @ velocity)
