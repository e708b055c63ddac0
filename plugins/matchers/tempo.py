"""A demonstration compared at each take's tempo: its motion rescaled by the pace its warping found.

Time warping (:mod:`plugins.matchers.warping`) lets a slower performance stay on a take's frames and a faster one pass
several at a sample, so *when* each pose comes no longer matters. *How fast* each part moves still does: the motion
comparison (:class:`plugins.matchers.comparison.Motion`) sees each part's velocity and the body's travel, and a walk
performed at half the pace moves every part, and the body, at half the speed. Aligned frame by frame with the take,
such a walk's velocities lie nearer to standing still than to the take's, and a held pose explains it better than
the walk does. Styles change tempo by up to four times (a raise of a hand took 37 to 163 frames across the styles of
one performer, issue 34; the Bandai-Namco styles walk at 0.4-1.4 m/s).

So each chain (a take) is compared twice:

1. the warping aligns the demonstration with the chain as it is, and counts the chain's frames its best path
   advanced over from the first sample to the last: over the steps between samples this is the *pace*, 1 at the
   take's own tempo, 0.5 for a performance half as fast (it stayed on each frame for two samples), 2 for one twice
   as fast;
2. the demonstration's motion and travel are multiplied by ``1 / pace`` (what they would be at the take's tempo;
   the shape and the turn since the onset do not change with tempo) and the warping aligns it again.

Each chain's *score* is its distance at its own tempo over the demonstration's distance to standing still at that
tempo (the relative score of :func:`plugins.matchers.decision.relative_scores`, which takes the nearest take's own
motion where it moves more), so that chains compared at different paces rank alike. The pace is held within
``1 / TEMPO`` and ``TEMPO``: a path that stays on one frame of a held pose has pace 0, and a demonstration's motion
multiplied without bound would make its own jitter a movement.

Positions have no tempo (:class:`plugins.matchers.comparison.Poses`, the papers' eq. 1): for them the second pass is
the first, and it is not made.

A tracker's jitter adds to both distances (:mod:`plugins.lib.jitter`): where the frames know it
(:attr:`plugins.matchers.comparison.Frames.noise`: a demonstration seen whole, a take from a recording), it is taken
out of both before the one is divided by the other (:func:`less_jitter`), so that a score says more of how far the
movements lie apart and less of how noisy the trackers were: the hand gestures of ``likeme bench make-gestures``,
recorded with 1 cm of jitter (2 cm at the hands), score a median 0.34 from their movements in the normal style with
it and 0.23 without it, against 0.15 recorded clean.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plugins.matchers.comparison import Comparison, Frames
from plugins.matchers.decision import relative_scores
from plugins.matchers.warping import Chains, chain_stills, kept, kept_chains, warp_chains

__all__ = ["Paced", "TEMPO", "less_jitter", "paced_distances", "paced_scores", "paces"]

TEMPO = 4.0
"""How many times slower or faster than a take a performance may be and still be compared at the take's tempo
(issue 34: tempo varies up to four times between styles). Beyond it the pace is held at the limit."""


@dataclass(frozen=True)
class Paced:
    """Every chain compared with a demonstration at the chain's own tempo.

    Attributes
    ----------
    scores : array, shape (C,)
        Each chain's distance at its pace over the demonstration's distance to standing still at that pace, or
        over the nearest take's own where that take moves more (:func:`~plugins.matchers.decision.relative_scores`;
        ``inf`` for a chain left out, and where the demonstration does not move at all).
    distances : array, shape (C,)
        Each chain's distance at its pace, in the comparison's unit (``inf`` for a chain left out).
    pace : array, shape (C,)
        Each chain's frames per sample of the demonstration, within ``1 / TEMPO`` and ``TEMPO`` (1 for a chain left
        out, and for a demonstration of one sample).
    cost : array, shape (n, M) or None
        The frame distances at each chain's pace (every chain kept), what :func:`plugins.matchers.warping.chain_path`
        follows back; ``None`` when nothing was compared.
    """

    scores: np.ndarray
    distances: np.ndarray
    pace: np.ndarray
    cost: np.ndarray | None


def paces(advanced: np.ndarray, samples: int) -> np.ndarray:
    """Each chain's pace: the frames its best path advanced over (:func:`~plugins.matchers.warping.warp_chains`)
    per step from sample to sample, within ``1 / TEMPO`` and ``TEMPO`` (1 for a single sample)."""
    advanced = np.asarray(advanced, dtype=float)
    if samples < 2:
        return np.ones(len(advanced))
    return np.clip(advanced / (samples - 1), 1.0 / TEMPO, TEMPO)


def paced_distances(comparison: Comparison, samples: Frames, nodes: Frames, chains: Chains,
                    skip: np.ndarray | None = None) -> Paced:
    """Every chain against the demonstration ``samples`` at the chain's own tempo (see the module); ``nodes``: the
    frames of every chain, chain after chain; ``skip`` (C,) bool: chains left out."""
    keep = kept(chains, skip)
    scores, distances = np.full(len(chains), np.inf), np.full(len(chains), np.inf)
    pace = np.ones(len(chains))
    if len(samples) == 0 or not keep.any():
        return Paced(scores, distances, pace, None)
    frames, starts, cyclic, columns = kept_chains(nodes, chains, keep)
    paired = comparison.paired(samples, frames)
    cost = paired.at(1.0)
    found, _, advanced = warp_chains(cost, starts, cyclic)
    if comparison.paced:
        at = paces(advanced, len(samples))
        cost = paired.at(np.repeat(1.0 / at, np.diff(starts)))
        found, _, _ = warp_chains(cost, starts, cyclic)
        moving = comparison.still_at(samples, 1.0 / at).mean(axis=0)
        pace[keep] = at
    else:
        moving = np.full(len(found), float(np.mean(comparison.still(samples))))
    if samples.noise is not None or frames.noise is not None:
        found, moving = less_jitter(found, moving, samples, frames, starts, pace[keep])
    scores[keep] = relative_scores(found, moving, chain_stills(comparison, frames, starts))
    distances[keep] = found
    if columns is not None:
        full = np.zeros((len(samples), len(nodes)))
        full[:, columns] = cost
        cost = full
    return Paced(scores, distances, pace, cost)


def less_jitter(found: np.ndarray, moving: np.ndarray, samples: Frames, frames: Frames, starts: np.ndarray,
                pace: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each chain's distance ``found`` (K,) and the demonstration's distance to standing still at the chain's
    ``pace`` (K,) less the tracker's jitter (:attr:`Frames.noise`, :mod:`plugins.lib.jitter`): squared, the
    demonstration's mean squared noise at that pace (its motion's noise times ``1 / pace`` squared, as its motion)
    and the chain's own (the mean over its frames, ``frames`` chain after chain from ``starts``) subtracted, at least
    0. What is left lies far nearer the distance of the movements themselves, but keeps some of the noise: a chain's
    distance is a mean of frame distances, and the square of a mean is not the mean of the squares the noise adds
    to (at 1.5 cm of jitter, 3 cm at the hands, about a third of the rise in the scores remains,
    ``tests/plugins/matchers/path_search/test_jitter_scores.py``).

    A demonstration that moves no more than its jitter moves by its jitter: its distance to standing still is held
    at its noise, not brought to 0, so that its scores stay finite and rank its movements as before."""
    noise = samples.floor
    own = (noise[:, :1] + noise[:, 1:] / (pace[None, :] ** 2)).mean(axis=0)
    take = np.add.reduceat(frames.floor.sum(axis=1), starts[:-1]) / np.diff(starts)
    return np.sqrt(np.maximum(found ** 2 - own - take, 0.0)), np.sqrt(np.maximum(moving ** 2 - own, own))


def paced_scores(comparison: Comparison, samples: Frames, nodes: Frames, chains: Chains,
                 skip: np.ndarray | None = None) -> np.ndarray:
    """:attr:`Paced.scores` of :func:`paced_distances`: what a calibration of the decision measures
    (:func:`plugins.matchers.warping.chain_calibration`)."""
    return paced_distances(comparison, samples, nodes, chains, skip).scores
