"""Hand transitions: the motor commands of hand-internal movement (Kopp & Graeser 2006, §3 and §4.2).

"Edges in the hand graphs represent parametric transition functions that
define the duration and velocity profile of a movement from one hand
configuration (start node) into another (end node)" (§4.2); a local motor
program for hand-internal movement is "created from a sequence of key hand
postures along with parameters specifying the movement dynamics along the
transitions" (§3).

A hand configuration is the joint angles of its fingers: every finger is an
*angle part* of the body whose three values are radians (base flexion, middle
flexion, spread; :class:`toolkit.body.Hand`). A :class:`HandTransition` moves
one finger through key postures: ``keys`` (m, 3) at ``times`` (m,), a
monotone cubic (:class:`scipy.interpolate.PchipInterpolator`) through them,
as a key-frame animation plays its key poses. The whole movement runs through
that curve with one bell-shaped velocity profile
(:func:`plugins.lib.guiding_stroke.progress` with end gain 0, peaking at
``peak`` of the duration): it starts and ends at rest, and flows through the
via postures, where the angular velocity dips as the fingers change direction
and the ``velocity-direction`` segmenter finds them again (§4.3). ``times``
are on the curve's own clock (from 0 to ``duration``); a key posture is reached
when the bell-shaped progress reaches its time. The fingers of one hand share their timing: an
edge of a hand subsystem holds one transition per finger with the same times.

:meth:`HandTransition.position` is the forward model (edge plus elapsed time
gives the predicted configuration); it has the interface of
:class:`plugins.lib.guiding_stroke.GuidingStroke` so the motor command graph, the
forward-model matcher and the imitation treat wrist and hand edges alike. The
inverse model is :func:`plugins.lib.inverse_model.transitions_from_segment`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from plugins.lib.guiding_stroke import progress

__all__ = ["HandTransition"]


@dataclass(frozen=True)
class HandTransition:
    """One finger's joint angles through key postures with a bell-shaped angular velocity between them.

    Parameters
    ----------
    keys : array, shape (m, 3), m >= 2
        Key postures (radians): the start configuration, via postures, the target configuration.
    times : array, shape (m,)
        Each key posture's place on the curve's clock (seconds; 0 first, strictly increasing; the last is the duration).
    peak : float
        Moment of maximum angular velocity, as a share of the duration (0.05 to 0.95).
    """

    keys: np.ndarray
    times: np.ndarray
    peak: float = 0.5

    def __eq__(self, other: object) -> bool:
        return isinstance(other, HandTransition) and self.to_dict() == other.to_dict()

    __hash__ = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        from scipy.interpolate import PchipInterpolator

        keys = np.asarray(self.keys, dtype=float)
        times = np.asarray(self.times, dtype=float)
        if keys.ndim != 2 or keys.shape[1] != 3 or len(keys) < 2 or not np.isfinite(keys).all():
            raise ValueError("a hand transition needs two or more finite key postures of three joint angles")
        if times.shape != (len(keys),) or times[0] != 0.0 or not np.all(np.diff(times) > 0):
            raise ValueError("a hand transition needs one time per key posture, from 0 and strictly increasing")
        if not 0.05 <= self.peak <= 0.95:
            raise ValueError("peak must lie in [0.05, 0.95]")
        object.__setattr__(self, "keys", keys)
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "peak", float(self.peak))
        # scipy takes the harmonic mean of neighbouring slopes; a subnormal slope overflows its reciprocal to inf,
        # which gives the right limit (a zero derivative at that key) with a RuntimeWarning: not a fault of the keys.
        with np.errstate(over="ignore", divide="ignore"):
            curve = PchipInterpolator(times, keys, axis=0)
        object.__setattr__(self, "_curve", curve)

    @property
    def start(self) -> np.ndarray:
        return self.keys[0]

    @property
    def target(self) -> np.ndarray:
        return self.keys[-1]

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    @property
    def via(self) -> np.ndarray:
        """The via postures between start and target, shape (m - 2, 3)."""
        return self.keys[1:-1]

    @property
    def amplitude(self) -> float:
        """Radians from the start to the target configuration."""
        return float(np.linalg.norm(self.target - self.start))

    def curve(self, w: float | np.ndarray) -> np.ndarray:
        """The joint angles at ``w`` on the curve's own clock (the key postures at ``times``, no velocity profile)."""
        return self._curve(np.clip(np.asarray(w, dtype=float), 0.0, self.duration))

    def position(self, t: float | np.ndarray) -> np.ndarray:
        """Forward model: the joint angles at elapsed time(s) ``t`` (clamped to the transition), shape (..., 3)."""
        u = np.clip(np.asarray(t, dtype=float), 0.0, self.duration) / self.duration
        return self.curve(self.duration * progress(u, self.peak, 0.0))

    def trajectory(self, fps: float) -> np.ndarray:
        """Joint angles sampled at ``fps`` from 0 to the end inclusive, shape (n, 3)."""
        n = max(2, int(round(self.duration * fps)) + 1)
        return self.position(np.linspace(0.0, self.duration, n))

    def retimed(self, duration: float) -> HandTransition:
        """The same transition performed in ``duration`` seconds (speed re-parameterisation, §4.4)."""
        return HandTransition(self.keys, self.times * (float(duration) / self.duration), self.peak)

    def to_dict(self, *, arrays: bool = False) -> dict[str, Any]:
        """The parameters; arrays as nested lists unless ``arrays`` (for saving and reports)."""
        if arrays:
            return {"keys": self.keys.copy(), "times": self.times.copy(), "peak": self.peak}
        return {"keys": self.keys.round(6).tolist(), "times": self.times.round(6).tolist(), "peak": round(self.peak, 6)}
