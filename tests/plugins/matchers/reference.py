"""Reference computations the matchers' calibration tests check against, written out take by take."""

from __future__ import annotations

import numpy as np

from plugins.matchers.comparison import Frames
from plugins.matchers.tempo import TEMPO
from plugins.matchers.warping import chain_distances, chain_path


def left_out_scores(comparison, takes, frames, chains, paced: bool = False) -> list[float]:
    """Leave one movement out: each take's distance to the nearest take of another movement (its chain's best
    warping, :func:`chain_distances`) over its own distance to standing still; ``paced``: each chain compared at its
    own tempo (:mod:`plugins.matchers.tempo`), written out chain by chain."""
    scores = []
    for c, take in enumerate(takes):
        skip = np.array([m == chains.movements[c] for m in chains.movements])
        if not paced:
            distances, _ = chain_distances(comparison, take, frames, chains, skip)
            scores.append(distances.min() / np.mean(comparison.still(take)))
            continue
        scores.append(min(_paced_score(comparison, take, frames, chains, k) for k in np.flatnonzero(~skip)))
    return scores


def _paced_score(comparison, take: Frames, frames: Frames, chains, k: int) -> float:
    """Chain ``k`` against ``take`` at the chain's tempo: the pace from the frames its path steps over, the take's
    motion and travel scaled by its inverse, warped again, over the scaled take's distance to standing still."""
    _, cost = chain_distances(comparison, take, frames, chains)
    nodes = list(chains.chain(k))
    columns = np.array([nodes.index(node) for node in chain_path(cost, chains, k)])
    advanced = (np.diff(columns) % len(nodes)).sum()
    pace = np.clip(advanced / (len(take) - 1), 1 / TEMPO, TEMPO) if len(take) > 1 else 1.0
    parts, carry = take.parts.copy(), take.carry.copy()
    parts[..., 3:] /= pace
    carry[:, :3] /= pace
    scaled = Frames(parts, take.seen, carry, take.carried)
    only = np.ones(len(chains), dtype=bool)
    only[k] = False
    distances, _ = chain_distances(comparison, scaled, frames, chains, only)
    return float(distances[k] / np.mean(comparison.still(scaled)))
