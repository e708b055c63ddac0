"""A tracker's jitter filtered out of a motion known whole: a zero-phase low-pass at the band of human movement.

A tracker places each joint within a centimetre or so from frame to frame (a depth camera's skeleton tracker more,
a marker-based capture less), and the noise is independent from frame to frame: it spreads over every frequency up
to half the frame rate, while a person's voluntary movements lie below a few hertz (a wave of the hand 2-4 Hz; gait
kinematics are low-passed at about 6 Hz in biomechanics, D. A. Winter, *Biomechanics and Motor Control of Human
Movement*, ch. 2). A motion known whole (a repertoire's clip, a demonstration learned as a take) is read through a
fourth-order Butterworth low-pass at :data:`MOVEMENT_BAND`, run forwards and backwards (no delay): at 30 frames a
second it keeps a 3 Hz wave to within 0.5% and leaves about 0.6 of the jitter, and the take a character keeps as
its own movement (B&B §5.2.3's path, K&G §4.3's take) is no longer the tracker's noise of one performance, which
every later performance would be compared with.

A motion seen while it comes in cannot be filtered without delay, and is not: only what is known whole.
"""

from __future__ import annotations

import numpy as np

from toolkit import Motion

__all__ = ["MOVEMENT_BAND", "low_passed"]

MOVEMENT_BAND = 6.0
"""Hz: the cut-off of the low-pass, above which a motion known whole is taken to be jitter, not movement."""

ORDER = 4
"""The Butterworth filter's order (run twice, forwards and backwards: eighth order, no phase)."""

PAD = 2.0
"""Seconds of the motion's odd reflection the filter starts from at each end (fewer in a shorter motion): a dozen
periods of the cut-off, over which its start-up dies out, so that a body walking on at even speed stays on its line
to the end (to within a micrometre; the default padding of 15 frames left 60 micrometres)."""


def low_passed(world: Motion, cutoff: float = MOVEMENT_BAND, keep: np.ndarray | None = None) -> Motion:
    """``world`` with each part's seen positions low-passed at ``cutoff`` Hz (zero phase, :data:`ORDER`).

    Hidden frames stay hidden: the filter runs through them along the straight line between the sightings
    around them (held before the first and after the last), and they are not seen afterwards either. ``keep``
    (P,) bool: parts left as they are (a finger's joint angles, which are not positions). A frame rate at most twice
    ``cutoff`` (nothing above the band to filter) or a motion too short for the filter's start-up (fewer frames
    than :data:`ORDER` times 6) comes back as it is.
    """
    positions = np.asarray(world.positions, dtype=float)
    n, parts = positions.shape[:2]
    if world.fps <= 2.0 * cutoff or n <= 6 * ORDER:
        return world
    from scipy.signal import butter, sosfiltfilt

    seen = np.asarray(world.visible, dtype=bool) & np.isfinite(positions).all(axis=-1)
    columns = np.flatnonzero(seen.any(axis=0) & (np.ones(parts, dtype=bool) if keep is None else ~np.asarray(keep)))
    if not len(columns):
        return world
    filled = positions[:, columns].copy()
    frames = np.arange(n)
    for j, part in enumerate(columns):
        if not seen[:, part].all():
            at = frames[seen[:, part]]
            for k in range(3):
                filled[:, j, k] = np.interp(frames, at, positions[at, part, k])
    sos = butter(ORDER, cutoff, output="sos", fs=world.fps)
    out = positions.copy()
    pad = min(n - 1, int(round(PAD * world.fps)))
    out[:, columns] = np.where(seen[:, columns, None], sosfiltfilt(sos, filled, axis=0, padlen=pad), np.nan)
    return Motion(out, world.fps, world.parts, seen, world.world)
