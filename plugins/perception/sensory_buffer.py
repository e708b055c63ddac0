"""The sensory buffer: an ultra-short memory that bridges dropouts of single parts.

Kopp & Graeser 2006, §4.1: the perception architecture has "an ultra-short term
sensory buffer for compensating sensor drop outs". A part that was seen a moment
ago and is missing now is reported at its last seen position for at most
``hold`` seconds; after that it is hidden, as it should be. Used by the vision
perceptions; positions are kept in world coordinates, so the bridged value is
where the part was, not a guess of where it went.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SensoryBuffer"]


class SensoryBuffer:
    """Holds each part's last seen position for up to ``hold_frames`` frames.

    Parameters
    ----------
    n_parts : int
    hold_frames : int
        0 disables bridging.
    """

    def __init__(self, n_parts: int, hold_frames: int) -> None:
        self.hold_frames = int(hold_frames)
        self.last = np.full((n_parts, 3), np.nan)
        self.age = np.full(n_parts, np.iinfo(np.int64).max // 2, dtype=np.int64)

    def update(self, positions: np.ndarray, visible: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Feed one frame (P, 3) with mask (P,); returns positions and mask with short gaps bridged."""
        visible = np.asarray(visible, dtype=bool) & np.isfinite(positions).all(axis=-1)
        self.last[visible] = positions[visible]
        self.age[visible] = 0
        self.age[~visible] += 1
        bridged = ~visible & (self.age <= self.hold_frames)
        out = np.where(visible[:, None], positions, np.where(bridged[:, None], self.last, np.nan))
        return out, visible | bridged
