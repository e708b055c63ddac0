"""Attention to what moves: how much each body part counts when a movement is compared with one's own.

Kopp & Graeser 2006 (§4.1, §4.4) follow the *moving* subsystems of the demonstrator's body and predict each on its
own; Buchsbaum & Blumberg 2005 (§5.1, eq. 1) average the distance over every visible part alike. On real people
the second lets the parts that do not take part in the movement (a differently held head, a stance) outweigh the
few that do (a waving hand): a still, differently held body dominates the mean. Here each part's weight grows
with how much it moves in the segment watched:

``w_p = (1 - attention) / P + attention * m_p / sum(m)``,  ``m_p`` the part's root-mean-square deviation from its
mean position over the segment (visible frames),

so ``attention = 0`` is eq. 1's plain mean and ``attention = 1`` counts only what moves. The weights sum to 1 and
need no unit: the same setting holds for any body size.
"""

from __future__ import annotations

import numpy as np

__all__ = ["movement_weights"]


def movement_weights(poses: np.ndarray, visible: np.ndarray, attention: float, parts: np.ndarray | None = None
                     ) -> np.ndarray:
    """Per-part weights (P,) from a segment's root-relative poses (n, P, 3) and masks (n, P) (see the module).

    ``parts`` (bool (P,)) selects the parts that may count (position parts); the others weigh 0.
    """
    poses = np.asarray(poses, dtype=float)
    visible = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
    p = poses.shape[1]
    use = np.ones(p, dtype=bool) if parts is None else np.asarray(parts, dtype=bool)
    count = visible.sum(axis=0)
    x = np.where(visible[..., None], poses, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = x.sum(axis=0) / np.maximum(count, 1)[:, None]
        dev = np.where(visible[..., None], poses - mean, 0.0)
        move = np.sqrt((dev ** 2).sum(axis=(0, 2)) / np.maximum(count, 1))
    move = np.where(use & (count > 0), move, 0.0)
    n = max(int(use.sum()), 1)
    share = move / move.sum() if move.sum() > 0 else np.where(use, 1.0 / n, 0.0)
    return np.where(use, (1.0 - attention) / n + attention * share, 0.0)
