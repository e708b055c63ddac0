"""Reference computations the matchers' calibration tests check against, written out take by take."""

from __future__ import annotations

import numpy as np

from plugins.matchers.warping import chain_distances


def left_out_scores(comparison, takes, frames, chains) -> list[float]:
    """Leave one movement out: each take's distance to the nearest take of another movement (its chain's best
    warping, :func:`chain_distances`) over its own distance to standing still."""
    scores = []
    for c, take in enumerate(takes):
        skip = np.array([m == chains.movements[c] for m in chains.movements])
        distances, _ = chain_distances(comparison, take, frames, chains, skip)
        scores.append(distances.min() / np.mean(comparison.still(take)))
    return scores
