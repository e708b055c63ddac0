"""Reference computations the matchers' calibration tests check against, written out take by take."""

from __future__ import annotations

import numpy as np

from plugins.matchers.comparison import Frames
from plugins.matchers.tempo import TEMPO
from plugins.matchers.warping import chain_distances, chain_path


def take_still(comparison, frames: Frames, chains, k: int) -> float:
    """Chain ``k``'s take's own distance to standing still: the mean over its frames (its columns of ``frames``)."""
    return float(np.mean(comparison.still(frames.take(np.arange(chains.starts[k], chains.starts[k + 1])))))


def relative(pairs: dict[int, tuple[float, float]], stills: dict[int, float]) -> float:
    """The nearest chain's relative score, written out: of the chains' (distance, the demonstration's distance to
    standing still) ``pairs``, the one with the least ratio, its distance over the larger of the demonstration's
    distance to standing still and its take's own (``stills``)."""
    k = min(pairs, key=lambda c: pairs[c][0] / pairs[c][1])
    distance, moving = pairs[k]
    return distance / max(moving, stills[k])


def left_out_scores(comparison, takes, frames, chains, paced: bool = False) -> list[float]:
    """Leave one movement out: each take's distance to the nearest take of another movement (its chain's best
    warping, :func:`chain_distances`) over the larger of its own distance to standing still and that take's
    (:func:`relative`); ``paced``: each chain compared at its own tempo (:mod:`plugins.matchers.tempo`), written
    out chain by chain."""
    scores = []
    for c, take in enumerate(takes):
        skip = np.array([m == chains.movements[c] for m in chains.movements])
        others = np.flatnonzero(~skip)
        stills = {k: take_still(comparison, frames, chains, k) for k in others}
        if not paced:
            distances, _ = chain_distances(comparison, take, frames, chains, skip)
            moving = float(np.mean(comparison.still(take)))
            scores.append(relative({k: (distances[k], moving) for k in others}, stills))
            continue
        scores.append(relative({k: _paced(comparison, take, frames, chains, k) for k in others}, stills))
    return scores


def _paced(comparison, take: Frames, frames: Frames, chains, k: int) -> tuple[float, float]:
    """Chain ``k`` against ``take`` at the chain's tempo: the pace from the frames its path steps over, the take's
    motion and travel scaled by its inverse, warped again; that distance and the scaled take's distance to standing
    still."""
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
    return float(distances[k]), float(np.mean(comparison.still(scaled)))


def followed_score(comparison, take: Frames, frames: Frames, chains, k: int, prior: float) -> float:
    """:func:`followed` as one score: the distance over the demonstration's distance to standing still."""
    distance, moving = followed(comparison, take, frames, chains, k, prior)
    return distance / moving


def followed(comparison, take: Frames, frames: Frames, chains, k: int, prior: float) -> tuple[float, float]:
    """Chain ``k`` following ``take`` sample by sample at the pace its best path has gone so far
    (:mod:`plugins.matchers.pacing`), written out: each sample played at ``1 / pace`` and costed against the chain's
    frames, the warping's steps, its best path's frames advanced over, the pace ``(advanced + prior) / (steps +
    prior)``; the chain's mean cost and the played samples' mean distance to standing still."""
    nodes = chains.chain(k)
    m = len(nodes)
    cyclic = bool(chains.cyclic[k])
    pace, still = 1.0, 0.0
    total = length = advanced = None
    for i in range(len(take)):
        sample = take.take([i])
        parts, carry = sample.parts.copy(), sample.carry.copy()
        parts[..., 3:] /= pace
        carry[:, :3] /= pace
        played = Frames(parts, sample.seen, carry, sample.carried)
        still += float(comparison.still(played)[0])
        cost = comparison.costs(played, frames.take(nodes))[0]
        if total is None:
            total, length, advanced = cost.copy(), np.ones(m), np.zeros(m)
        else:
            new, new_len, new_adv = np.empty(m), np.empty(m), np.empty(m)
            for j in range(m):
                options = []  # (total, length, advanced), in the kernel's order of preference
                if j > 0 or (cyclic and m > 1):
                    options.append((total[j - 1], length[j - 1], advanced[j - 1] + 1))
                options.append((total[j], length[j], advanced[j]))
                if j > 0:
                    options.append((new[j - 1], new_len[j - 1], new_adv[j - 1] + 1))
                best = options[0]
                for option in options[1:]:
                    if option[0] < best[0]:
                        best = option
                new[j], new_len[j], new_adv[j] = best[0] + cost[j], best[1] + 1, best[2]
            if cyclic and m > 1:
                j = 0
                while j < m and new[j - 1] + cost[j] < new[j]:
                    new[j], new_len[j], new_adv[j] = new[j - 1] + cost[j], new_len[j - 1] + 1, new_adv[j - 1] + 1
                    j += 1
            total, length, advanced = new, new_len, new_adv
        end = int(np.argmin(total / length))
        pace = float(np.clip((advanced[end] + prior) / (i + prior), 1 / TEMPO, TEMPO)) if i + prior > 0 else 1.0
    return float((total / length).min()), still / len(take)


def followed_left_out_scores(comparison, takes, frames, chains, prior: float) -> list[float]:
    """Leave one movement out, each take followed as a forward model follows it (:func:`followed`), scored by
    :func:`relative`."""
    scores = []
    for c, take in enumerate(takes):
        others = [k for k in range(len(chains)) if chains.movements[k] != chains.movements[c]]
        scores.append(relative({k: followed(comparison, take, frames, chains, k, prior) for k in others},
                               {k: take_still(comparison, frames, chains, k) for k in others}))
    return scores
