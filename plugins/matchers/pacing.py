"""The warping advanced sample by sample as a demonstration comes in, each take followed at the pace it has gone so far.

Kopp & Graeser 2006, §4.4: the forward models predict a demonstration while it comes in, and a familiar movement
performed faster or slower must still be predicted (their speed re-parameterisation). Time warping follows any
tempo *when* poses come; the motion comparison (:class:`plugins.matchers.comparison.Motion`) also sees *how fast*
each part moves, which changes with tempo (:mod:`plugins.matchers.tempo`: a wave performed three times as slowly lies
nearer standing still than the wave, frame by frame). Path search sees the whole demonstration and warps twice, the
second time at the pace the first found (:func:`plugins.matchers.tempo.paced_distances`). A forward model cannot wait
for the end, so here each take (a chain) is followed at the pace its own best path has gone so far:

- after each sample, the chain's *pace* is the frames of the chain its best path advanced over per step from sample
  to sample, with :data:`PRIOR` seconds of steps at the take's own tempo counted in (the first steps alone say
  little: one step is 0, 1 or 2 frames), held within ``1 / TEMPO`` and ``TEMPO`` (:data:`plugins.matchers.tempo.TEMPO`);
- the next sample is costed against the chain's frames with its motion and travel multiplied by ``1 / pace``
  (:class:`plugins.matchers.comparison.Paired`: what it would be at the take's tempo), and the warping steps on
  (the steps and the free beginning and end of :mod:`plugins.matchers.warping`);
- its distance to standing still is taken at the same pace, so each chain's *score* is its best path's mean cost over
  the demonstration's mean distance to standing still as that chain has paced it, or the nearest take's own where it
  moves more (the relative score, :func:`plugins.matchers.decision.relative_scores`).

A demonstration at the take's own tempo is followed as the unpaced warping follows it. The numbers after a sample do
not depend on how the samples before it came in (one by one or at once): the costs are computed pair by pair
(:meth:`Paired.pairwise`). A forward model's calibration follows each take the same way (:func:`followed_scores`),
so the scores it commits on, the answer at the end and the decision's threshold are one measure.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from plugins.lib.compiled import kernel
from plugins.matchers.comparison import Frames, Motion, Paired
from plugins.matchers.tempo import TEMPO
from plugins.matchers.decision import relative_scores
from plugins.matchers.warping import Chains, chain_stills, kept, kept_chains

__all__ = ["Followed", "PRIOR", "PacedWarping", "followed_scores"]

PRIOR = 0.5
"""Seconds of steps at the take's own tempo counted into each chain's pace (see the module): after half a second of a
demonstration at half the tempo the pace is 0.75, after two seconds 0.6."""


def _follow(fixed, moving, moving2, still_parts, starts, cyclic, state, chain_state, first, prior, tempo, out, ends):
    """The warping of :func:`plugins.matchers.warping._warp` advanced by the samples whose costs against every
    column are split in ``fixed``, ``moving``, ``moving2`` (r, M) (:class:`Paired`), each chain ``c`` costed at
    speed ``1 / pace``, from the state after the ``first`` samples before them (none: a fresh start): ``state``
    (3, M), each column's best path's summed cost, length and frames advanced over; ``chain_state`` (2, C), each
    chain's pace and the samples' summed distance to standing still at its paces (a sample's is ``sqrt(fixed +
    s^2 moving2)`` of its ``still_parts`` (2, r)). After each sample: each chain's best mean cost so far
    (``out[0]``, (r, C)), its mean distance to standing still at its paces so far (``out[1]``), the column its best
    path ends in (``ends``); then the chain's pace from that path, ``(advanced + prior) / (steps + prior)`` within
    ``1 / tempo`` and ``tempo``. The states are left as after the last sample. Plain Python as written (the
    reference), compiled by :func:`plugins.lib.compiled.kernel`."""
    rows = fixed.shape[0]
    total, length, advanced = state[0], state[1], state[2]
    pace, still = chain_state[0], chain_state[1]
    distance, moved = out[0], out[1]
    width = total.shape[0]
    now = np.empty(width)
    now_len = np.empty(width)
    now_adv = np.empty(width)
    cost = np.empty(width)
    for i in range(rows):
        k = first + i
        for c in range(len(starts) - 1):
            a = starts[c]
            m = starts[c + 1] - a
            s = 1.0 / pace[c]
            still[c] += np.sqrt(still_parts[0, i] + s * s * still_parts[1, i])
            for j in range(m):
                square = fixed[i, a + j] + s * moving[i, a + j] + s * s * moving2[i, a + j]
                cost[a + j] = np.sqrt(square) if square > 0.0 else 0.0
            if k == 0:
                for j in range(m):
                    now[a + j] = cost[a + j]
                    now_len[a + j] = 1.0
                    now_adv[a + j] = 0.0
            else:
                for j in range(m):
                    if j > 0:
                        d, dl, da = total[a + j - 1], length[a + j - 1], advanced[a + j - 1] + 1.0
                    elif cyclic[c] and m > 1:
                        d, dl, da = total[a + m - 1], length[a + m - 1], advanced[a + m - 1] + 1.0
                    else:
                        d, dl, da = np.inf, 0.0, 0.0
                    if total[a + j] < d:
                        d, dl, da = total[a + j], length[a + j], advanced[a + j]
                    if j > 0 and now[a + j - 1] < d:
                        d, dl, da = now[a + j - 1], now_len[a + j - 1], now_adv[a + j - 1] + 1.0
                    now[a + j] = d + cost[a + j]
                    now_len[a + j] = dl + 1.0
                    now_adv[a + j] = da
                if cyclic[c] and m > 1:  # the same sample on from the last node to the first, then on along the chain
                    j = 0
                    while j < m:
                        left = a + (m - 1 if j == 0 else j - 1)
                        value = now[left] + cost[a + j]
                        if value < now[a + j]:
                            now[a + j] = value
                            now_len[a + j] = now_len[left] + 1.0
                            now_adv[a + j] = now_adv[left] + 1.0
                            j += 1
                        else:
                            break
            best = np.inf
            at = -1
            for j in range(m):
                mean = now[a + j] / now_len[a + j]
                if mean < best:
                    best = mean
                    at = j
            distance[i, c] = best
            moved[i, c] = still[c] / (k + 1)
            ends[i, c] = at
            if at >= 0:
                p = (now_adv[a + at] + prior) / (k + prior) if k + prior > 0 else 1.0
                pace[c] = min(max(p, 1.0 / tempo), tempo)
        for q in range(width):
            total[q] = now[q]
            length[q] = now_len[q]
            advanced[q] = now_adv[q]


class Followed(NamedTuple):
    """What each chain made of the samples a :class:`PacedWarping` took, after each sample (arrays (r, C)): its best
    path's mean cost so far (``distance``), the demonstration's mean distance to standing still so far at the
    chain's paces (``moved``) and the frame (the index within the chain) its best path ends on (``ends``); and each
    sample's own distance to standing still at its own tempo (``still``, (r,): :meth:`Motion.still`, from the same
    sums)."""

    distance: np.ndarray
    moved: np.ndarray
    ends: np.ndarray
    still: np.ndarray


class PacedWarping:
    """Every chain followed sample by sample at its own pace (see the module).

    Parameters
    ----------
    comparison : Motion
        A comparison whose motion scales with tempo (``paced``).
    frames : Frames
        The frames of every chain, chain after chain (``Frames.join`` of the takes').
    chains : Chains
    rate : float
        Samples a second (the :data:`PRIOR` in samples).
    """

    def __init__(self, comparison: Motion, frames: Frames, chains: Chains, rate: float) -> None:
        if not comparison.paced:
            raise ValueError(f"a paced warping needs a comparison whose motion scales with tempo, not "
                             f"{type(comparison).__name__}")
        self.comparison, self.frames, self.chains = comparison, frames, chains
        self.prior = PRIOR * float(rate)
        self.state = np.zeros((3, len(frames)))  # each column's best path: summed cost, length, frames advanced
        self.chain_state = np.zeros((2, len(chains)))  # each chain's pace and summed distance to standing still
        self.chain_state[0] = 1.0
        self.samples = 0

    @property
    def pace(self) -> np.ndarray:
        """Each chain's pace after the samples taken so far (C,)."""
        return self.chain_state[0]

    def advance(self, samples: Frames) -> Followed:
        """Take the next samples; what each chain made of them (:class:`Followed`). :attr:`pace` is each chain's
        pace after the last of them."""
        r, chains = len(samples), len(self.chains)
        out = np.empty((2, r, chains))
        out[0], out[1] = np.inf, 0.0
        ends = np.full((r, chains), -1, dtype=np.intp)
        still_parts = np.stack(self.comparison.still_split(samples)) if r else np.zeros((2, 0))
        if r and len(self.frames):
            paired = Paired.pairwise(samples, self.frames)
            kernel(_follow)(paired.fixed, paired.moving, paired.moving2, still_parts, self.chains.starts,
                            self.chains.cyclic, self.state, self.chain_state, self.samples, self.prior, TEMPO, out,
                            ends)
            self.samples += r
        distance, moved = out
        return Followed(distance, moved, ends, np.sqrt(still_parts[0] + still_parts[1]))


def followed_scores(comparison: Motion, samples: Frames, nodes: Frames, chains: Chains,
                    skip: np.ndarray | None = None, *, rate: float) -> np.ndarray:
    """Each chain's score after the demonstration ``samples`` followed to its end (:class:`PacedWarping`): its
    distance over the demonstration's distance to standing still at its pace (C,) (``inf`` for a chain left out by
    ``skip``, and where the demonstration does not move at all); what a forward model's calibration measures
    (:func:`plugins.matchers.warping.chain_calibration`, with ``rate`` given)."""
    keep = kept(chains, skip)
    scores = np.full(len(chains), np.inf)
    if not len(samples) or not keep.any():
        return scores
    frames, starts, cyclic, _ = kept_chains(nodes, chains, keep)
    movements = tuple(m for m, k in zip(chains.movements, keep) if k)
    warping = PacedWarping(comparison, frames, Chains(np.arange(len(frames), dtype=np.intp), starts, movements,
                                                      cyclic), rate)
    followed = warping.advance(samples)
    scores[keep] = relative_scores(followed.distance[-1], followed.moved[-1], chain_stills(comparison, frames, starts))
    return scores
