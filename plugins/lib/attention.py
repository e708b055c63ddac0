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

Attention to what tells one's own movements apart (issue 18, not in the papers): one take of each movement cannot
say which of its parts belong to the movement, but the repertoire does say where each movement differs from the
others. :func:`part_distances` measures a take against a path of nodes part by part, and :func:`contrast_weights`
turns such per-part distances into weights by the same rule as :func:`movement_weights`:

``w_p = (1 - share) / P + share * c_p / sum(c)``,  ``c_p`` the part's distance from the other movements,

so ``share = 0`` is eq. 1's plain mean, a part that lies alike in every movement (``c_p = 0``) keeps the floor
``(1 - share) / P``, and the weights sum to 1 whatever the body's size.
"""

from __future__ import annotations

import numpy as np

__all__ = ["contrast_weights", "movement_weights", "part_distances"]


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


def part_distances(poses: np.ndarray, path: np.ndarray, visible: np.ndarray) -> np.ndarray:
    """Each part's mean eq. 2 distance (B&B §5.1) between poses (n, P, 3) and the poses of a path aligned with them
    (n, P, 3), over the samples where the part is seen (masks (n, P)); (P,), 0 for a part never seen.

    The parts' share of eq. 3 along the path: their mean over the parts seen in every sample is eq. 3 per sample."""
    poses, path = np.asarray(poses, dtype=float), np.asarray(path, dtype=float)
    seen = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1) & np.isfinite(path).all(axis=-1)
    d = np.sqrt(((np.where(seen[..., None], poses - path, 0.0)) ** 2).sum(axis=-1))
    return d.sum(axis=0) / np.maximum(seen.sum(axis=0), 1)


def contrast_weights(distances: np.ndarray, share: float) -> np.ndarray:
    """Per-part weights (..., P) from per-part distances (..., P) to what is to be told apart (see the module):
    ``(1 - share) / P + share * c_p / sum(c)``; every part ``1 / P`` where every distance is 0 (nothing to tell
    apart). ``share = 1`` weighs only the parts that differ."""
    c = np.maximum(np.nan_to_num(np.asarray(distances, dtype=float)), 0.0)
    p = c.shape[-1]
    total = c.sum(axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        part = np.where(total > 0, c / np.where(total > 0, total, 1.0), 1.0 / p)
    return (1.0 - share) / p + share * part
