"""The inverse model: from an observed segment to the motor command that reproduces it (guiding stroke or hand transition).

Kopp & Graeser 2006, §4.3: "after segmentation, an inverse model is applied to
each segment in order to calculate the parameters needed to produce it by a
guiding stroke. To this end, the equations for trajectory formation are applied
in inverse direction."

1. Start, target and duration are the segment's first and last samples and its length.
2. The progress along the chord and the perpendicular residual are measured;
   the residual's principal direction gives the movement plane. A residual
   smaller than ``straight`` times the chord makes the stroke linear.
3. A residual that changes sides is an S, otherwise a C. The largest residual is
   the curvature. The area under the profile gives the roundness (the area
   of ``1 - |2s - 1|^q`` is ``q / (q + 1)``), and where it peaks gives the skewness.
4. The speed profile gives the moment of peak velocity and the end gain.
5. Those closed-form estimates start a bounded least-squares refinement
   (:func:`scipy.optimize.least_squares`) of the timing and shape parameters
   against the observed positions, so noise in one estimate is corrected by the
   trajectory as a whole. A curved stroke is refined both as a C and as an S
   (noise near the ends can make a flat C's residual change sides) and the one
   closer to the observation is kept.

Hands (§4.3): "if Max observes a completed, unknown finger movement by the
demonstrator, the movement will be segmented both, at angular velocity minima
and according to a clustering of movement directions, to detect the start, end,
and via postures of the sighted hand movements. These configurations are used
as key postures to create a new edge in the hand motor command graph".
:func:`transitions_from_segment` takes those break points as key postures and
fits the one remaining parameter, the moment of peak angular velocity (which
also places the key postures on the curve's clock), by a bounded scalar search.

Everything here is mathematics: observed segment in, commands out
(:func:`commands_from_segment`). Adding them to a graph as edges is the motor command
graph's (:meth:`plugins.motor.motor_command_graph.MotorCommandGraph.learn_observed`).
"""

from __future__ import annotations

import numpy as np

# scipy.signal, scipy.optimize and scipy.integrate are imported where they are used: importing them costs every
# command that loads the plugins, most of which never run the inverse model

from plugins.lib.guiding_stroke import GuidingStroke, progress
from plugins.lib.hand_transition import HandTransition

__all__ = ["stroke_from_segment", "transitions_from_segment", "trajectory_error", "commands_from_segment"]

STRAIGHT = 0.03  # the default largest sideways deviation, as a share of the chord, of a straight stroke


def trajectory_error(stroke: GuidingStroke | HandTransition, positions: np.ndarray, fps: float) -> float:
    """Largest distance (m, or radians for a hand transition) between the command's trajectory and observed
    ``positions`` sampled at ``fps``."""
    t = np.arange(len(positions)) / fps
    return float(np.linalg.norm(stroke.position(t) - positions, axis=1).max())


_PEAK_CLIP = (0.1, 0.9)
"""Where the moment of peak velocity read from the speed profile is clipped (a share of the duration)."""


def _timing(p: np.ndarray, fps: float) -> tuple[float, float]:
    """The moment of peak velocity and the end gain, from the (smoothed) speed profile of positions ``p``."""
    return _timings([p], fps)[0]


def _timings(parts: list[np.ndarray], fps: float) -> list[tuple[float, float]]:
    """:func:`_timing` of several parts' positions of one length, their speed profiles smoothed in one call.

    The Savitzky-Golay filter works along the time axis, column by column (a convolution, and a least-squares
    polynomial at each end), so filtering the parts' speeds side by side gives each part's own filtered speed;
    ``tests/plugins/lib/test_inverse_model_once.py`` checks it bit for bit.
    """
    speeds = np.stack([np.linalg.norm(np.diff(p, axis=0), axis=1) * fps for p in parts], axis=1)
    if len(speeds) >= 7:
        from scipy.signal import savgol_filter

        if speeds.shape[1] == 1:  # one part: filtered as a 1-D profile, as it always was
            speeds = savgol_filter(speeds[:, 0], 7, 2, mode="interp")[:, None]
        else:
            speeds = savgol_filter(speeds, 7, 2, axis=0, mode="interp")
    out = []
    for j in range(speeds.shape[1]):
        speed = speeds[:, j]
        peak = float(np.clip((np.argmax(speed) + 0.5) / max(len(speed), 1), *_PEAK_CLIP))
        end_gain = float(np.clip(speed[-1] / max(speed.max(), 1e-12), 0.0, 0.9))
        out.append((peak, end_gain))
    return out


def _closed_form(p: np.ndarray, fps: float, straight: float, family: str | None = None,
                 timing: tuple[float, float] | None = None) -> dict:
    """The closed-form estimates; ``timing`` is :func:`_timing` of the same ``p`` when already computed."""
    from scipy.integrate import trapezoid

    start, target = p[0], p[-1]
    chord = target - start
    length = float(np.linalg.norm(chord))
    axis = chord / max(length, 1e-12)
    s = np.clip((p - start) @ axis / max(length, 1e-12), 0.0, 1.0)
    residual = p - (start + s[:, None] * chord)
    peak, end_gain = _timing(p, fps) if timing is None else timing
    est = {"start": start, "target": target, "duration": (len(p) - 1) / fps, "peak": peak, "end_gain": end_gain}
    size = np.linalg.norm(residual, axis=1)
    if length < 1e-6 or size.max() < straight * length:
        return {**est, "shape": "linear"}
    # movement plane: the residual's principal direction, perpendicular to the chord
    _, _, vt = np.linalg.svd(residual, full_matrices=False)
    side = vt[0] - (vt[0] @ axis) * axis
    side /= max(np.linalg.norm(side), 1e-12)
    normal = np.cross(axis, side)  # then normal x chord points along side: positive lateral is "left"
    lateral = residual @ side / (0.5 * length)
    hi, lo = lateral.max(), lateral.min()
    s_shape = min(hi, -lo) > 0.3 * max(hi, -lo) if family is None else family == "s"
    if s_shape:  # both ways: an S, whose first half bends to the left for "left-s"
        first = lateral[s < 0.5]
        left_first = first.size > 0 and first.max() >= -first.min()
        shape, amplitude = ("left-s" if left_first else "right-s"), 2 * max(hi, -lo)
        profile = np.abs(lateral) * 2
    else:
        sign = 1.0 if hi >= -lo else -1.0
        shape, amplitude = ("left-c" if sign > 0 else "right-c"), max(hi, -lo)
        profile = sign * lateral
    # a normal pointing backwards (towards -z, the body's back) is flipped with the side, for readable parameters
    if normal[2] < 0 or (abs(normal[2]) < 1e-9 and normal[1] < 0):
        normal = -normal
        shape = shape.replace("left", "RIGHT").replace("right", "left").replace("RIGHT", "right")
    area = float(trapezoid(np.clip(profile / max(profile.max(), 1e-12), 0, 1), s)) if len(s) > 1 else 0.5
    area = float(np.clip(area, 0.51, 0.93))
    q = area / (1 - area)
    roundness = float(np.clip(1 - np.log(q) / np.log(8), 0.0, 1.0))
    s_peak = float(np.clip(s[np.argmax(profile)], 0.05, 0.95)) if shape.endswith("-c") else 0.5
    skewness = float(np.clip(np.log2(np.log(0.5) / np.log(s_peak)), -1, 1)) if shape.endswith("-c") else 0.0
    return {**est, "shape": shape, "normal": normal, "curvature": float(np.clip(amplitude, 0.0, 1.0)),
            "roundness": roundness, "skewness": skewness}


def stroke_from_segment(positions: np.ndarray, fps: float, *, straight: float = STRAIGHT, refine: bool = True) -> GuidingStroke:
    """The guiding stroke that reproduces a segment of wrist positions (N, 3) sampled at ``fps`` (N >= 2).

    Parameters
    ----------
    positions : array, shape (N, 3)
        Observed positions in the body frame, NaN-free (hidden samples interpolated beforehand).
    fps : float
    straight : float
        Largest sideways deviation, as a share of the chord, still taken as a straight stroke.
    refine : bool
        Refine the closed-form estimates by least squares.
    """
    p = _checked(positions)
    return _stroke(p, fps, straight, refine, _timing(p, fps))


def _checked(positions: np.ndarray) -> np.ndarray:
    p = np.asarray(positions, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2 or not np.isfinite(p).all():
        raise ValueError("the inverse model needs two or more finite positions (N, 3)")
    return p


def _stroke(p: np.ndarray, fps: float, straight: float, refine: bool, timing: tuple[float, float]) -> GuidingStroke:
    """:func:`stroke_from_segment` of checked positions ``p`` whose :func:`_timing` is ``timing``."""
    est = _closed_form(p, fps, straight, timing=timing)
    if not refine:
        return GuidingStroke(**est)
    # the speed profile's peak in the first or last tenth (clipped there) is noise, not a bell: a slow stroke seen
    # with tracker noise whose frame-to-frame speed is as large as the stroke's own. The fit then also starts from
    # a symmetric bell (peak 0.5, no end gain), and the start that reproduces the observation better is kept.
    timings = [timing] + ([(0.5, 0.0)] if timing[0] in (_PEAK_CLIP[0], _PEAK_CLIP[1]) else [])
    if est["shape"] == "linear":
        fits = [_refined({**est, "peak": peak, "end_gain": gain}, p, fps) for peak, gain in timings]
        return min(fits, key=lambda stroke: trajectory_error(stroke, p, fps))
    # C or S: observation noise at the ends can make a C's residual change sides; both families are fitted and
    # the one that reproduces the observation better is kept (the speed profile is the same: filtered once)
    fits = [_refined(_closed_form(p, fps, straight, family, t), p, fps) for t in timings for family in ("c", "s")]
    return min(fits, key=lambda stroke: (trajectory_error(stroke, p, fps), stroke.shape != est["shape"]))


def _refined(est: dict, p: np.ndarray, fps: float) -> GuidingStroke:
    """The closed-form stroke ``est`` refined by bounded least squares against positions ``p``; the better of the two."""
    from scipy.optimize import least_squares

    stroke = GuidingStroke(**est)
    t = np.arange(len(p)) / fps
    curved = stroke.shape != "linear"
    names = ["peak", "end_gain"] + (["curvature", "roundness", "skewness"] if curved else [])
    lower = {"peak": 0.05, "end_gain": 0.0, "curvature": 0.0, "roundness": 0.0, "skewness": -1.0}
    upper = {"peak": 0.95, "end_gain": 0.95, "curvature": 1.0, "roundness": 1.0, "skewness": 1.0}
    x0 = np.array([np.clip(est.get(n, 0.0), lower[n] + 1e-6, upper[n] - 1e-6) for n in names])

    def residual(x: np.ndarray) -> np.ndarray:
        candidate = GuidingStroke(**{**est, **dict(zip(names, x))})
        return (candidate.position(t) - p).ravel()

    fit = least_squares(residual, x0, bounds=([lower[n] for n in names], [upper[n] for n in names]), x_scale="jac", max_nfev=200)
    refined = GuidingStroke(**{**est, **dict(zip(names, fit.x))})
    return refined if trajectory_error(refined, p, fps) <= trajectory_error(stroke, p, fps) else stroke


def transitions_from_segment(angles: np.ndarray, fps: float, breaks: list[int] | tuple[int, ...] = ()) -> list[HandTransition]:
    """The hand transitions (one per finger, shared timing) that reproduce a segment of finger joint angles.

    Parameters
    ----------
    angles : array, shape (N, k, 3)
        Observed joint angles (radians) of the hand's k fingers, NaN-free, N >= 2.
    fps : float
    breaks : list of int
        Frames of the via postures (the angular-velocity minima and direction changes found by the segmenter).
    """
    from scipy.optimize import minimize_scalar

    a = np.asarray(angles, dtype=float)
    if a.ndim != 3 or a.shape[2] != 3 or len(a) < 2 or not np.isfinite(a).all():
        raise ValueError("the hand inverse model needs two or more finite configurations (N, k, 3)")
    frames = np.array(sorted({0, *(int(b) for b in breaks if 0 < b < len(a) - 1), len(a) - 1}))
    duration = (len(a) - 1) / fps
    t = np.arange(len(a)) / fps

    def build(peak: float) -> list[HandTransition]:
        # the key postures' places on the curve's clock: where the bell-shaped progress is when they were seen
        times = duration * progress(frames / (len(a) - 1), peak, 0.0)
        return [HandTransition(a[frames, j], times, peak) for j in range(a.shape[1])]

    def error(peak: float) -> float:
        return float(sum(np.sum((tr.position(t) - a[:, j]) ** 2) for j, tr in enumerate(build(peak))))

    fit = minimize_scalar(error, bounds=(0.05, 0.95), method="bounded", options={"xatol": 1e-3})
    return build(float(fit.x) if error(float(fit.x)) <= error(0.5) else 0.5)


def commands_from_segment(observed: np.ndarray, fps: float, breaks: list[int] | tuple[int, ...], *, hand: bool,
                          refine: bool = True) -> list[tuple[list[GuidingStroke] | list[HandTransition], bool]]:
    """The motor commands that reproduce an observed segment of a subsystem's k parts, stroke by stroke (§4.3).

    Parameters
    ----------
    observed : array, shape (n, k, 3)
        Positions of a wrist subsystem's parts, or joint angles of a hand's fingers, NaN-free.
    fps : float
    breaks : list of int
        Frames where one stroke ends and the next begins (:func:`plugins.lib.strokes.breaks`).
    hand : bool
        A hand: one piece, whose key postures are the break points (:func:`transitions_from_segment`); else one
        piece per stroke between break points, a guiding stroke per part (:func:`stroke_from_segment`), pieces
        shorter than two frames left out.
    refine : bool
        Refine the guiding strokes by least squares.

    Returns
    -------
    list of (commands, last)
        Each piece's commands (one per part), and whether it is the segment's last piece (which a motor command
        graph may end in its hub).
    """
    n, k, _ = observed.shape
    if hand:
        return [(transitions_from_segment(observed, fps, breaks), True)]
    cuts = [0, *breaks, n - 1]
    pieces: list[tuple[list[GuidingStroke] | list[HandTransition], bool]] = []
    for i, (a, b) in enumerate(zip(cuts, cuts[1:])):
        if b - a < 2:
            continue
        parts = [_checked(observed[a : b + 1, j]) for j in range(k)]
        timings = _timings(parts, fps)  # the k parts' speed profiles filtered in one call
        pieces.append(([_stroke(p, fps, STRAIGHT, refine, timing) for p, timing in zip(parts, timings)],
                       i == len(cuts) - 2))
    return pieces
