"""Body size: another body's segment lengths measured from what is seen of it, and its poses at one's own lengths.

The correspondence problem (Buchsbaum & Blumberg 2005, §7.1; Kopp & Graeser 2006, §6) begins with size: a
demonstrator taller, smaller or differently proportioned than the observer puts every part somewhere else for the
same movement, and eq. 1 (a mean of distances in metres) reads that as a different movement. Here the
demonstrator's bone lengths are estimated from the stream (a running mean over the frames where both ends of a
bone are seen: causal, so a live observer can do it), and each pose is rebuilt outward from the root along the
demonstrator's own bone directions at the observer's bone lengths (:func:`retarget`). The directions, which carry
the movement, are kept; the lengths, which carry the body, become one's own.

Bones come from the body's ``bones`` (pairs of parts); :func:`bone_tree` orders them outward from the root. A
part no bone reaches from the root, and every finger (joint angles, not positions), is left as it is.

All arrays are ``(frames, parts, 3)`` poses, root-relative, with masks ``(frames, parts)``.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np

__all__ = ["bone_tree", "bone_lengths", "rigid_pairs", "RunningLengths", "retarget", "body_scale"]


def bone_tree(parts: Sequence[str], bones: Sequence[tuple[str, str]], root: str,
              skip: Sequence[str] = ()) -> np.ndarray:
    """The bones as (parent, child) part indices (B, 2), breadth first from ``root`` (a parent always comes before
    its children); bones to parts in ``skip`` and bones that would close a cycle are left out."""
    index = {p: i for i, p in enumerate(parts)}
    skipped = set(skip)
    near: dict[str, list[str]] = {p: [] for p in parts}
    for a, b in bones:
        if a in index and b in index and a not in skipped and b not in skipped:
            near[a].append(b)
            near[b].append(a)
    order: list[tuple[int, int]] = []
    seen, frontier = {root}, [root]
    while frontier:
        nxt = []
        for parent in frontier:
            for child in near[parent]:
                if child not in seen:
                    seen.add(child)
                    order.append((index[parent], index[child]))
                    nxt.append(child)
        frontier = nxt
    return np.array(order, dtype=np.intp).reshape(-1, 2)


def bone_lengths(poses: np.ndarray, visible: np.ndarray, tree: np.ndarray) -> np.ndarray:
    """Each bone's length in each frame (n, B); NaN where one of its ends is hidden."""
    poses = np.asarray(poses, dtype=float)
    diff = poses[:, tree[:, 1]] - poses[:, tree[:, 0]]
    lengths = np.sqrt(np.einsum("fbi,fbi->fb", diff, diff))
    seen = np.asarray(visible, dtype=bool)
    return np.where(seen[:, tree[:, 0]] & seen[:, tree[:, 1]], lengths, np.nan)


def rigid_pairs(motions: Sequence[tuple[np.ndarray, np.ndarray]], parts: np.ndarray, *, spread: float = 0.05,
                shortest: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """The pairs of parts whose distance stays the same through one's own movements: the body's rigid links.

    ``motions`` are (poses (n, P, 3), visible (n, P)) of the observer's own movements; ``parts`` (bool (P,)) the
    parts that may take part. A pair is rigid when the standard deviation of its distance is at most ``spread``
    times its mean and the mean is at least ``shortest`` (m). Returns the pairs (K, 2) and their mean distances (K,).
    Bones of a skeleton are rigid pairs; so are, say, the two hips. Between parts animated independently (a
    character drawn from key poses), there may be none: then nothing about size can be measured.
    """
    idx = np.flatnonzero(np.asarray(parts, dtype=bool))
    a, b = np.triu_indices(len(idx), k=1)
    pairs = np.stack([idx[a], idx[b]], axis=1)
    if not len(pairs) or not motions:
        return pairs[:0], np.zeros(0)
    d = np.concatenate([bone_lengths(p, v, pairs) for p, v in motions])
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean, std = np.nanmean(d, axis=0), np.nanstd(d, axis=0)
    keep = np.isfinite(mean) & (mean >= shortest) & (std <= spread * mean)
    return pairs[keep], mean[keep]


class RunningLengths:
    """The demonstrator's bone lengths as the running mean of every length seen so far (causal, O(1) memory).

    :meth:`update` takes a block of per-frame lengths (n, B) with NaN where unseen and returns, for each frame,
    the mean of the lengths seen up to and including it (NaN for a bone not seen yet).
    """

    def __init__(self, n_bones: int) -> None:
        self.total = np.zeros(n_bones)
        self.count = np.zeros(n_bones)

    def update(self, lengths: np.ndarray) -> np.ndarray:
        seen = np.isfinite(lengths)
        total = self.total + np.cumsum(np.where(seen, lengths, 0.0), axis=0)
        count = self.count + np.cumsum(seen, axis=0)
        if len(lengths):
            self.total, self.count = total[-1].copy(), count[-1].copy()
        return _mean(total, count)

    @property
    def mean(self) -> np.ndarray:
        """The mean of every length seen so far (B,); NaN for a bone not seen yet."""
        return _mean(self.total, self.count)


def _mean(total: np.ndarray, count: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def retarget(poses: np.ndarray, tree: np.ndarray, ratio: np.ndarray, root: int) -> np.ndarray:
    """Poses (n, P, 3) rebuilt from the root outward, each bone's offset scaled by its ``ratio`` ((n, B) or (B,)).

    A bone's offset in each frame (child minus parent, as seen) times the observer's length over the
    demonstrator's: its direction, and its length's frame-to-frame noise, stay the demonstrator's, its mean length
    becomes the observer's. Parts the tree does not reach are returned as they are; the root stays where it is.
    """
    poses = np.asarray(poses, dtype=float)
    out = poses.copy()
    ratio = np.broadcast_to(np.asarray(ratio, dtype=float), (len(poses), len(tree)))
    for b, (parent, child) in enumerate(tree):
        out[:, child] = out[:, parent] + (poses[:, child] - poses[:, parent]) * ratio[:, b, None]
    out[:, root] = poses[:, root]
    return out


def body_scale(pose: np.ndarray, parts: np.ndarray | None = None) -> float | np.ndarray:
    """A body's size from one pose: the root-mean-square distance of its parts from their centroid (m).

    The scale that relative thresholds are measured in: it needs no skeleton (any parts will do), is about 0.45 m
    for a standing adult and grows with the body. ``parts`` (bool (P,)) selects the parts (position parts). Parts
    with a coordinate that is not finite are left out; fewer than two parts left: 0. A pose (P, 3) gives a number;
    poses (..., P, 3) give one per pose.
    """
    pose = np.asarray(pose, dtype=float)
    if parts is not None:
        pose = pose[..., np.asarray(parts, dtype=bool), :]
    ok = np.isfinite(pose).all(axis=-1)
    count = ok.sum(axis=-1)
    safe = np.where(ok[..., None], pose, 0.0)
    centre = safe.sum(axis=-2) / np.maximum(count, 1)[..., None]
    spread = np.where(ok, ((safe - centre[..., None, :]) ** 2).sum(axis=-1), 0.0).sum(axis=-1)
    size = np.where(count >= 2, np.sqrt(spread / np.maximum(count, 1)), 0.0)
    return float(size) if size.ndim == 0 else size
