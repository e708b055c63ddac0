"""Guiding strokes: the motor commands of wrist movement (Kopp & Graeser 2006, §3).

A wrist trajectory is a sequence of *guiding strokes*, each bridging from one
break point to the next "more or less ballistically": straight or curvilinear
(a left or right C, a left or right S) within a fixed movement plane, with a
bell-shaped velocity profile. A stroke states

- ``start`` and ``target`` positions (metres, in the body frame) and ``duration`` (s);
- ``peak``: the moment of maximum velocity as a fraction of the duration;
- ``end_gain``: the velocity at the end point as a fraction of the peak velocity
  (0 stops there; more flows on into the next stroke);
- ``shape``: ``linear``, ``left-c``, ``right-c``, ``left-s`` or ``right-s``;
- ``normal``: the normal of the movement plane (curvilinear strokes);
- ``curvature`` in [0, 1]: from nearly straight (0) to a semicircle (1);
- ``roundness`` in [0, 1]: from nearly rectangular (0) through round (0.5) to
  nearly triangular (1);
- ``skewness`` in [-1, 1]: the bend flattened toward the beginning (< 0) or the end (> 0).

:meth:`GuidingStroke.position` is the forward model: stroke plus elapsed time
gives the predicted position. The inverse model is :mod:`plugins.lib.inverse_model`.

Formulas (``u = t / duration``, ``s`` the progress along the chord ``d = target - start``):

- speed profile ``v(u) = beta(u) + end_gain * ramp(u)``, ``beta(u) = u^a (1-u)^b / max`` with
  ``a = 4 peak``, ``b = 4 (1 - peak)`` (the minimum-jerk bell when ``peak = 0.5``),
  ``ramp`` rising smoothly from 0 at the peak to 1 at the end; ``s(u)`` is its normalised integral;
- lateral offset ``curvature * |d| / 2 * l(s)`` along the in-plane perpendicular
  ``n x d / |n x d|`` (negated for the right-hand shapes), with ``l(s) = 1 - |2w - 1|^q``,
  ``w = s^(2^skewness)`` and ``q = 8^(1 - roundness)``; an S is a C over each half with opposite signs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

__all__ = ["GuidingStroke", "SHAPES", "progress", "lateral_profile"]

SHAPES = ("linear", "left-c", "right-c", "left-s", "right-s")
_GRID = 257  # resolution of the tabulated progress integral


def _beta(u: np.ndarray, peak: float) -> np.ndarray:
    a, b = 4.0 * peak, 4.0 * (1.0 - peak)
    bell = np.power(u, a) * np.power(1.0 - u, b)
    mode = peak  # the maximum of u^a (1-u)^b is at a / (a + b)
    return bell / (mode**a * (1.0 - mode) ** b)


def _ramp(u: np.ndarray, peak: float) -> np.ndarray:
    x = np.clip((u - peak) / max(1.0 - peak, 1e-9), 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def velocity_profile(u: np.ndarray, peak: float, end_gain: float) -> np.ndarray:
    """Relative speed over normalised time ``u`` in [0, 1] (maximum 1 at ``peak`` when ``end_gain`` is 0)."""
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    return _beta(u, peak) + end_gain * _ramp(u, peak)


def progress(u: np.ndarray, peak: float, end_gain: float) -> np.ndarray:
    """Share of the path covered at normalised time ``u``: 0 at 0, 1 at 1, increasing."""
    grid, covered = _progress_table(float(peak), float(end_gain))
    return np.interp(np.clip(u, 0.0, 1.0), grid, covered)


@lru_cache(maxsize=4096)
def _progress_table(peak: float, end_gain: float) -> tuple[np.ndarray, np.ndarray]:
    """The tabulated progress integral of a speed profile (read-only): computed once per ``peak`` and ``end_gain``
    (a repertoire's strokes share a few), not at every evaluation of the forward model."""
    grid = np.linspace(0.0, 1.0, _GRID)
    v = velocity_profile(grid, peak, end_gain)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(grid))])
    covered = cum / cum[-1]
    grid.flags.writeable = covered.flags.writeable = False
    return grid, covered


def lateral_profile(s: np.ndarray, shape: str, roundness: float, skewness: float) -> np.ndarray:
    """Signed lateral offset (amplitude 1) of a shape over path progress ``s`` in [0, 1]."""
    s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
    q = 8.0 ** (1.0 - roundness)

    def bump(x: np.ndarray) -> np.ndarray:
        w = np.power(x, 2.0**skewness)
        return 1.0 - np.power(np.abs(2.0 * w - 1.0), q)

    if shape == "linear":
        return np.zeros_like(s)
    if shape.endswith("-c"):
        out = bump(s)
    else:  # an S: one bump each way, half as wide
        out = np.where(s < 0.5, bump(np.minimum(2.0 * s, 1.0)), -bump(np.clip(2.0 * s - 1.0, 0.0, 1.0))) * 0.5
    return -out if shape.startswith("right") else out


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of two 3-vectors, written out (the same products and differences, without its generality)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _in_plane_perpendicular(chord: np.ndarray, normal: np.ndarray) -> np.ndarray:
    perp = _cross(normal, chord)
    n = np.linalg.norm(perp)
    if n < 1e-12:  # normal along the chord: any perpendicular will do
        helper = np.array([0.0, 1.0, 0.0]) if abs(chord[1]) < 0.9 * np.linalg.norm(chord) else np.array([1.0, 0.0, 0.0])
        perp = _cross(helper, chord)
        n = np.linalg.norm(perp)
    return perp / max(n, 1e-12)


@dataclass(frozen=True)
class GuidingStroke:
    """One guiding stroke (see the module docstring for every parameter)."""

    start: np.ndarray
    target: np.ndarray
    duration: float
    peak: float = 0.5
    end_gain: float = 0.0
    shape: str = "linear"
    normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    curvature: float = 0.0
    roundness: float = 0.5
    skewness: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", np.asarray(self.start, dtype=float).reshape(3))
        object.__setattr__(self, "target", np.asarray(self.target, dtype=float).reshape(3))
        normal = np.asarray(self.normal, dtype=float).reshape(3)
        object.__setattr__(self, "normal", normal / max(np.linalg.norm(normal), 1e-12))
        if self.shape not in SHAPES:
            raise ValueError(f"unknown stroke shape {self.shape!r}; expected one of {', '.join(SHAPES)}")
        if not self.duration > 0:
            raise ValueError("a stroke needs a positive duration")
        if not 0.05 <= self.peak <= 0.95 or not 0.0 <= self.end_gain < 1.0:
            raise ValueError("peak must lie in [0.05, 0.95] and end_gain in [0, 1)")
        if not 0.0 <= self.curvature <= 1.0 or not 0.0 <= self.roundness <= 1.0 or not -1.0 <= self.skewness <= 1.0:
            raise ValueError("curvature and roundness lie in [0, 1], skewness in [-1, 1]")

    @property
    def chord(self) -> np.ndarray:
        return self.target - self.start

    @property
    def amplitude(self) -> float:
        return float(np.linalg.norm(self.chord))

    def position(self, t: float | np.ndarray) -> np.ndarray:
        """Forward model: the position at elapsed time(s) ``t`` (clamped to the stroke), shape (..., 3)."""
        u = np.asarray(t, dtype=float) / self.duration
        s = progress(u, self.peak, self.end_gain)
        base = self.start + s[..., None] * self.chord
        if self.shape == "linear" or self.curvature == 0.0:
            return base
        perp = _in_plane_perpendicular(self.chord, self.normal)
        lateral = lateral_profile(s, self.shape, self.roundness, self.skewness)
        return base + (0.5 * self.curvature * self.amplitude * lateral)[..., None] * perp

    def trajectory(self, fps: float) -> np.ndarray:
        """Positions sampled at ``fps`` from 0 to the end inclusive, shape (n, 3)."""
        n = max(2, int(round(self.duration * fps)) + 1)
        return self.position(np.linspace(0.0, self.duration, n))

    def retimed(self, duration: float) -> GuidingStroke:
        """The same stroke performed in ``duration`` seconds (speed re-parameterisation, K&G §4.4)."""
        return GuidingStroke(**{**self.to_dict(arrays=True), "duration": float(duration)})

    def to_dict(self, *, arrays: bool = False) -> dict[str, Any]:
        """The parameters; vectors as lists unless ``arrays`` (for saving and reports)."""
        vec = (lambda v: np.array(v)) if arrays else (lambda v: [round(float(x), 6) for x in v])
        return {
            "start": vec(self.start), "target": vec(self.target), "duration": float(self.duration),
            "peak": float(self.peak), "end_gain": float(self.end_gain), "shape": self.shape, "normal": vec(self.normal),
            "curvature": float(self.curvature), "roundness": float(self.roundness), "skewness": float(self.skewness),
        }
