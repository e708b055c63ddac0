"""Travel: where the body goes, in its own frame, which root-relative coordinates remove.

Buchsbaum & Blumberg 2005, §5.1 make every observed pose relative to the root and the facing, so a posture means
the same wherever the body stands and whichever way it faces. The same transform removes locomotion: a walk
forwards, a walk backwards, a side step and a run differ mostly in where the root goes relative to the facing,
and in root-relative coordinates they are nearly the same leg swings. The papers' movements are gestures made on
the spot (and a mouse's jump, whose rise stays in the root's height), so they never needed it; real people walk.
This is part of the correspondence problem both papers leave open (B&B §7.1, K&G §6): the observer must see the
other's body travel as it would feel its own travel.

*Travel* is the root's velocity in the body's own frame (m/s: +z forward, +x to the body's left, +y up), found
from the motion's world positions (:attr:`toolkit.motion.Motion.world`) and its root-relative positions, with no
knowledge of how the facing was found: the heading of each frame is the rotation that takes the parts' horizontal
offsets from the root in the world onto their offsets in the body's frame (a least-squares fit over the parts,
:func:`frame_rotation`). A matcher compares it like one more part (:func:`travel_part`): the root's displacement
over ``horizon`` seconds.

Glossary: F frames, P parts; ``world`` (F, P, 3) world positions; ``local`` (F, P, 3) root-relative positions in
the body's frame (hidden parts held, ``docs/conventions.md``); ``visible`` (F, P).
"""

from __future__ import annotations

import numpy as np

__all__ = ["frame_rotation", "body_velocity", "bridged_rows", "travel_part", "travelled", "turned"]


def frame_rotation(world: np.ndarray, local: np.ndarray, visible: np.ndarray, root: int) -> np.ndarray:
    """The rotation about +y (radians) that takes each frame's world offsets from the root onto its body-frame
    offsets, (F,); NaN where fewer than one part besides the root is seen with a horizontal offset.

    With horizontal offsets as complex numbers ``a = x + i z`` (world) and ``b`` (body frame), the angle is that of
    ``sum(conj(a) * b)``: the least-squares rotation (the 2-D Kabsch solution), exact when the offsets are rigid.
    """
    world = np.asarray(world, dtype=float)
    local = np.asarray(local, dtype=float)
    visible = np.asarray(visible, dtype=bool)
    seen = visible & visible[:, root : root + 1]
    seen[:, root] = False
    a = world - world[:, root : root + 1]
    b = local - local[:, root : root + 1]
    ca = a[..., 0] + 1j * a[..., 2]
    cb = b[..., 0] + 1j * b[..., 2]
    ok = seen & np.isfinite(ca) & np.isfinite(cb)
    s = (np.conj(np.where(ok, ca, 0)) * np.where(ok, cb, 0)).sum(axis=1)
    out = np.angle(s)
    out[np.abs(s) < 1e-12] = np.nan
    return out


def turned(world: np.ndarray, local: np.ndarray, visible: np.ndarray, root: int) -> np.ndarray:
    """How far the body has turned since the first frame (radians about +y, unwrapped; NaN where its facing is
    not known), from its world and body-frame positions (:func:`frame_rotation`)."""
    angle = frame_rotation(world, local, visible, root)
    known = np.isfinite(angle)
    out = np.full(len(angle), np.nan)
    if known.any():
        unwrapped = np.unwrap(angle[known])
        out[known] = unwrapped[0] - unwrapped  # the body's heading turns opposite to the frame rotation
    return out


def travelled(world: np.ndarray, local: np.ndarray, visible: np.ndarray, root: int) -> np.ndarray:
    """Where the root has gone since the first frame whose facing is known, in the body's frame at that frame (F,
    3), metres: a walk forwards goes along +z whichever way the body faced in the world, a walk backwards along -z, a
    turning walk curves to the side it turns to. NaN where the root is not seen, and everywhere when no facing is
    ever known (:func:`frame_rotation`)."""
    world = np.asarray(world, dtype=float)
    angle = frame_rotation(world, local, visible, root)
    out = np.full((len(world), 3), np.nan)
    known = np.flatnonzero(np.isfinite(angle))
    if not len(known):
        return out
    offset = world[:, root] - world[known[0], root]
    horizontal = (offset[:, 0] + 1j * offset[:, 2]) * np.exp(1j * angle[known[0]])
    out[:, 0], out[:, 1], out[:, 2] = horizontal.real, offset[:, 1], horizontal.imag
    out[~(np.asarray(visible, dtype=bool)[:, root] & np.isfinite(offset).all(axis=1))] = np.nan
    return out


def bridged_rows(values: np.ndarray, seen: np.ndarray) -> np.ndarray:
    """``values`` (n, k) with the rows not ``seen`` (n,) filled in: on a straight line between the seen rows around
    them, held beyond the first and the last. At least one row must be seen."""
    if seen.all():  # np.interp at its own sample points gives those samples back: no call needed
        return values
    steps = np.arange(len(values))
    return np.stack([np.interp(steps, steps[seen], values[seen, k]) for k in range(values.shape[1])], axis=1)


def body_velocity(world: np.ndarray, local: np.ndarray, visible: np.ndarray, root: int, fps: float,
                  window: float = 0.25, frames: np.ndarray | None = None) -> np.ndarray:
    """The root's velocity in the body's own frame (F, 3), m/s; NaN where the root or the facing is not known.

    The world velocity is the centred difference of the root's world position, averaged over ``window`` seconds
    (a step's sway left and right cancels; a change of pace within a second is kept), then turned by each frame's
    :func:`frame_rotation`. A motion of one frame has no velocity (NaN). With ``frames`` (indices), only those
    frames' rows (len(frames), 3): the same numbers as ``body_velocity(...)[frames]``, with the facing found at those
    frames only (path search samples a segment at its node rate).
    """
    from scipy.ndimage import uniform_filter1d

    world = np.asarray(world, dtype=float)
    n = len(world)
    out = np.full((n if frames is None else len(frames), 3), np.nan)
    if n < 2:
        return out
    root_seen = np.asarray(visible, dtype=bool)[:, root] & np.isfinite(world[:, root]).all(axis=1)
    if root_seen.sum() < 2:
        return out
    track = bridged_rows(world[:, root], root_seen)
    velocity = np.empty((n, 3))  # np.gradient(track, axis=0) (unit spacing, first-order edges), the same numbers
    velocity[1:-1] = (track[2:] - track[:-2]) / 2.0
    velocity[0] = track[1] - track[0]
    velocity[-1] = track[-1] - track[-2]
    velocity *= fps
    taps = max(1, int(round(window * fps)))
    if taps > 1:
        velocity = uniform_filter1d(velocity, taps, axis=0, mode="nearest")
    if frames is None:
        angle = frame_rotation(world, local, visible, root)
    else:  # the facing frame by frame: only where asked
        frames = np.asarray(frames, dtype=np.intp)
        velocity, root_seen = velocity[frames], root_seen[frames]
        angle = frame_rotation(world[frames], np.asarray(local)[frames], np.asarray(visible)[frames], root)
    horizontal = (velocity[:, 0] + 1j * velocity[:, 2]) * np.exp(1j * angle)
    out[:, 0], out[:, 1], out[:, 2] = horizontal.real, velocity[:, 1], horizontal.imag
    out[~root_seen | ~np.isfinite(angle)] = np.nan
    return out


def travel_part(velocity: np.ndarray, horizon: float) -> np.ndarray:
    """Travel as one more part to compare (F, 3): the root's displacement over ``horizon`` seconds at the current
    velocity, in metres, so eq. 1 compares it with the same weight and units as a part's position."""
    return np.asarray(velocity, dtype=float) * float(horizon)
