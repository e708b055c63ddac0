"""Rest posture: where a body dwells, estimated online from the poses seen so far.

Buchsbaum & Blumberg 2005 (§4.1, §5.1) build everything on the *hub*, the posture movements start from and return
to, and take the observer's own hub as the demonstrator's: the hub-threshold segmenter measures how far the other
is from it, and path search compares the other's poses with one's own. A real person stands their own way
(stooped, wide-legged, proud), so their rest already looks like a movement. Kopp & Graeser 2006 (§6) name the same
gap. This module estimates the demonstrator's own rest posture from where they dwell, so that movement can be
measured from *their* rest and mapped onto *one's own* hub.

Dwelling is being slow for a while. Each frame's speed is the mean speed of the body's visible parts, smoothed over
``window`` seconds (a turning point of a gesture is slow for an instant, a stance for a while), and a frame
weighs ``1 / (speed + dwell_speed)^2``: the slower the body, the more the pose says about its rest. The rest
posture is the weighted mean of the poses seen, forgetting with time constant ``memory`` seconds, so a
demonstrator who changes stance is followed. Everything is causal (a frame's estimate uses that frame and the ones
before) and runs in O(1) memory, vectorised over a block of frames with :func:`scipy.signal.lfilter`.

``dwell_speed`` is in the observed body's own size per second (:func:`plugins.lib.body_size.body_scale`), so the
same setting holds for a mouse and a giant.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

__all__ = ["RestPosture", "dwell_weights"]


def dwell_weights(speed: np.ndarray, dwell_speed: float) -> np.ndarray:
    """How much each frame says about the rest posture: ``exp(-(speed / dwell_speed)^2 / 2)`` (1 when still)."""
    return np.exp(-0.5 * (np.asarray(speed, dtype=float) / dwell_speed) ** 2)


class RestPosture:
    """The running estimate of one demonstrator's rest posture (see the module).

    Parameters
    ----------
    n_parts : int
    fps : float
    dwell_speed : float
        Speed (body sizes per second, the same units as the speeds given) at which a frame's weight has fallen to a
        quarter of a still frame's.
    window : float
        Seconds over which the speed is smoothed (a causal moving average).
    memory : float
        Time constant (s) with which old poses are forgotten; ``inf`` keeps them all.
    """

    def __init__(self, n_parts: int, fps: float, *, dwell_speed: float, window: float, memory: float,
                 prior: np.ndarray | None = None) -> None:
        self.fps = float(fps)
        self.dwell_speed = float(dwell_speed)
        self.decay = 1.0 if not np.isfinite(memory) else float(np.exp(-1.0 / (memory * self.fps)))
        self.taps = max(1, int(round(window * self.fps)))
        self._speeds = np.zeros(0)  # the last taps - 1 speeds, for the moving average across blocks
        self._last: np.ndarray | None = None  # the last pose seen (P, 3)
        self._sum = np.zeros(n_parts * 3) if prior is None else np.asarray(prior, dtype=float).reshape(-1).copy()
        self._weight = 0.0 if prior is None else 1.0

    @property
    def current(self) -> np.ndarray | None:
        """The estimate after the last frame given (P, 3); ``None`` before the first (and without a prior)."""
        return None if self._weight <= 0 else (self._sum / self._weight).reshape(-1, 3)

    def update(self, poses: np.ndarray, visible: np.ndarray, size: float) -> np.ndarray:
        """The rest posture after each frame of a block (n, P, 3): poses (n, P, 3) hidden parts held, masks (n, P),
        ``size`` the body's size (m) that speeds are measured in."""
        poses = np.asarray(poses, dtype=float)
        n, p = poses.shape[:2]
        if n == 0:
            return poses.copy()
        before = poses[:1] if self._last is None else self._last[None]
        step = np.linalg.norm(np.diff(np.concatenate([before, poses]), axis=0), axis=-1)  # (n, P)
        seen = np.asarray(visible, dtype=bool) & np.isfinite(step)
        with np.errstate(invalid="ignore"):
            raw = np.where(seen.any(axis=1), np.where(seen, step, 0.0).sum(axis=1) / np.maximum(seen.sum(axis=1), 1),
                           np.nan) * self.fps / max(size, 1e-9)
        if self._last is None:
            raw[0] = np.nan  # no speed at the very first frame: it counts as still as any
        history = np.concatenate([self._speeds, raw])
        speed = _moving_mean(history, self.taps)[len(self._speeds):]
        self._speeds = history[-(self.taps - 1):] if self.taps > 1 else np.zeros(0)
        speed = np.where(np.isfinite(speed), speed, 0.0)
        w = dwell_weights(speed, self.dwell_speed)
        flat = np.nan_to_num(poses.reshape(n, p * 3))
        a = [1.0, -self.decay]
        sums, _ = lfilter([1.0], a, w[:, None] * flat, axis=0, zi=(self.decay * self._sum)[None])
        weights, _ = lfilter([1.0], a, w, zi=[self.decay * self._weight])
        self._sum, self._weight = sums[-1].copy(), float(weights[-1])
        self._last = poses[-1].copy()
        return (sums / weights[:, None]).reshape(n, p, 3)


def _moving_mean(x: np.ndarray, taps: int) -> np.ndarray:
    """The mean of the last ``taps`` finite values up to each (fewer at the start; NaN with none)."""
    finite = np.isfinite(x)
    c = np.concatenate([[0.0], np.cumsum(np.where(finite, x, 0.0))])
    k = np.concatenate([[0], np.cumsum(finite)])
    i = np.arange(1, len(x) + 1)
    lo = np.maximum(0, i - taps)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(k[i] - k[lo] > 0, (c[i] - c[lo]) / np.maximum(k[i] - k[lo], 1), np.nan)
