"""Style: what differs between performers and styles of one movement, and how a comparison leaves it out.

Buchsbaum & Blumberg 2005 (§5.1, eq. 1) compare the demonstrator's root-relative poses with one's own as they are,
and leave the correspondence between bodies open (§7.1); Kopp & Graeser 2006 do the same (§6). Two people, or one
person in two styles, make the same movement from a different *held posture* (stooped, proud, wide-legged) and
with a different *amplitude* (exaggerated, timid). Both are properties of the whole movement, not of any pose in
it, so they are measured over a segment (the demonstration watched) or a take (the clip a posegraph path came
from), each on its own:

- **posture**: each part's mean position over the segment (:func:`mean_posture`). Eq. 1 on poses centred on their
  own segment's mean compares the movement about its own held posture: adding a constant offset to a part over the
  whole demonstration changes nothing (a stoop held through a bow, a hand held higher through a wave).
- **stillness**: how little each part moves in the segment, relative to the part that moves most
  (:func:`stillness`). The mean posture of the parts that take no part in a movement is the stance; that of the
  parts that move is also *where* the movement happens (a hand to the mouth, or to the face). Removing each part's
  mean in proportion to its stillness in the demonstration, from the demonstration and from every take alike,
  cancels the stance and keeps where the moving parts go.
- **tempo**: the movement's *frequency* (:func:`frequency`), its root-mean-square speed over its extent (below): the
  same movement performed twice as fast has twice the frequency, at any size and from any held posture, so a clip
  or a demonstration can be sampled in its own time (the posegraph's ``tempo``).
- **amplitude**: the root-mean-square distance of the parts from that mean posture (:func:`extent`), one length for
  the whole segment. Scaling the movement about its posture by ``reference / extent`` (:func:`rescale`) compares
  the movement's shape at a common size: the same gesture made twice as large or half as large compares close.

:func:`take_means` gives each node of a posegraph its take's mean posture and extent, so the graph's side is
centred and rescaled once when it is built and the search itself is unchanged.
"""

from __future__ import annotations

import numpy as np

__all__ = ["extent", "frequency", "mean_posture", "rescale", "stillness", "take_means"]


def mean_posture(poses: np.ndarray, visible: np.ndarray) -> np.ndarray:
    """Each part's mean position over the frames it is seen, (P, 3), from poses (n, P, 3) and masks (n, P).

    A part never seen (or never finite) gets NaN: it has no posture to remove.
    """
    poses = np.asarray(poses, dtype=float)
    seen = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
    count = seen.sum(axis=0)
    total = np.where(seen[..., None], poses, 0.0).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count[:, None] > 0, total / np.maximum(count, 1)[:, None], np.nan)


def extent(poses: np.ndarray, visible: np.ndarray, posture: np.ndarray | None = None) -> float:
    """The movement's amplitude: the root-mean-square distance of the seen parts from their mean posture (m), over
    every seen (frame, part); 0 for a segment with nothing seen. ``posture`` (P, 3): the mean to measure from
    (default :func:`mean_posture`)."""
    poses = np.asarray(poses, dtype=float)
    seen = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
    if not seen.any():
        return 0.0
    mean = mean_posture(poses, seen) if posture is None else np.asarray(posture, dtype=float)
    dev = poses - mean
    return float(np.sqrt(np.einsum("ij,ij->i", dev[seen], dev[seen]).mean()))


def stillness(poses: np.ndarray, visible: np.ndarray, posture: np.ndarray | None = None) -> np.ndarray:
    """How still each part is in the segment, (P,) in [0, 1]: 1 minus its root-mean-square distance from its mean
    posture over that of the segment's most moving part. The part that moves most is 0, a part that does not move
    is 1; every part 1 when nothing moves (beyond 1e-9 of the largest coordinate: rounding)."""
    poses = np.asarray(poses, dtype=float)
    seen = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
    mean = mean_posture(poses, seen) if posture is None else np.asarray(posture, dtype=float)
    dev = np.where(seen[..., None], poses - np.nan_to_num(mean), 0.0)
    move = np.sqrt((dev ** 2).sum(axis=(0, 2)) / np.maximum(seen.sum(axis=0), 1))
    top = move.max(initial=0.0)
    scale = float(np.abs(np.where(seen[..., None], poses, 0.0)).max(initial=0.0))
    if not top > 1e-9 * max(scale, 1.0):  # nothing moves beyond the rounding of the positions
        return np.ones(poses.shape[1])
    return 1.0 - move / top


def rescale(size: float, reference: float, limit: float) -> float:
    """The factor that brings a movement of amplitude ``size`` to ``reference``, kept within ``[1/limit, limit]``
    (a movement is taken for a larger or smaller version of another up to ``limit`` times, as path search's
    ``max_skip`` takes one up to that many times faster). 1 when either amplitude is 0 or not finite."""
    if not (size > 0 and reference > 0 and np.isfinite(size) and np.isfinite(reference)):
        return 1.0
    return float(np.clip(reference / size, 1.0 / limit, limit))


def take_means(poses: np.ndarray, takes: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Each node's take posture and amplitude: ``(posture (N, P, 3), extent (N,))`` for nodes ``poses`` (N, P, 3)
    grouped into ``takes`` (arrays of node indices). A node in no take (a hub) is its own posture, of amplitude 0:
    centred, it is the posture held still."""
    poses = np.asarray(poses, dtype=float)
    posture = poses.copy()
    size = np.zeros(len(poses))
    for take in takes:
        take = np.asarray(take, dtype=np.intp)
        if not len(take):
            continue
        seen = np.isfinite(poses[take]).all(axis=-1)
        mean = mean_posture(poses[take], seen)
        posture[take] = np.where(np.isfinite(mean), mean, poses[take])
        size[take] = extent(poses[take], seen, mean)
    return posture, size


def frequency(poses: np.ndarray, visible: np.ndarray, rate: float) -> float:
    """A movement's frequency (1/s): the root-mean-square speed of its parts between successive samples (poses (n, P,
    3) sampled ``rate`` times a second, masks (n, P); the steps where a part is seen at both ends) over their RMS
    distance from their mean posture (:func:`extent`). The same movement performed ``c`` times as fast has ``c``
    times the frequency, at any size and from any held posture; a sinusoid of angular frequency ``w`` reads
    ``2 rate sin(w / (2 rate))``, within 1% of ``w`` up to ``w = rate / 2``. 0 when it does not move."""
    poses = np.asarray(poses, dtype=float)
    seen = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
    size = extent(poses, seen)
    both = seen[1:] & seen[:-1]
    if not (size > 0 and both.any()):
        return 0.0
    step = np.where(both[..., None], np.diff(np.where(seen[..., None], poses, 0.0), axis=0), 0.0)
    moving = float(np.sqrt((step ** 2).sum() / both.sum())) * rate
    return moving / size
