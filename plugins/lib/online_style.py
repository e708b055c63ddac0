"""The styled comparison estimated online: a prediction fitted to the frames seen so far by held posture and pace.

Path search compares a whole segment about its own held posture, at a common amplitude and sampled at its own tempo
(:mod:`plugins.lib.style`). The forward model (Kopp & Graeser 2006, §4.4) commits while the movement is still going
on, so it cannot measure these over the whole segment: here each is estimated from the frames seen so far, for each
candidate command apart (its prediction for every frame seen, ``P_i``, against the observation ``O_i``, (k, 3)
each), from running sums, so a frame costs the same at any length of segment:

- **posture** (``centred``): each side centred on its own mean over the frames seen, ``O_i - mean(O)`` against
  ``P_i - mean(P)``: a constant offset of a part over the movement (a stance held otherwise, a hand held higher)
  cancels on both sides alike, as :func:`plugins.lib.style.mean_posture` removed does over a segment;
- **tempo** (several ``P`` rows, one per pace): the command is predicted at ``S`` paces (command seconds per second
  seen, :func:`paces`); the pace whose fit (with the posture above) leaves the least squared residual over the frames
  seen is the demonstrator's, and the prediction follows it.

Amplitude (the observation divided by its extent over the command's, within a factor 2, as path search's
``amplitude``) was built here too and measured, as the least-squares factor ``sum(O . P) / sum(P . P)`` and as the
ratio of the root-mean-square extents: it lowered the forward model's accuracy on the Bandai-Namco clips in every
combination, and was removed (docs/benchmarks.md, "The forward model's styled comparison (issue 18, fmstyled)").

The sums are per pace (S): ``sp`` (S, k, 3) the summed predictions, ``spp`` and ``sop`` (S,) the summed squares
``P . P`` and products ``O . P``; and of the observation ``so`` (k, 3), ``soo`` and the frames ``n``. The pace chosen
is the same when the demonstration and the commands are scaled together (the residuals scale with them), and, with
the posture removed, when either is moved: no length enters.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Observed", "Fit", "paces", "residuals", "fitted", "residuals_all", "distances_all", "prediction_sums", "STEP"]

STEP = 1.12
"""Ratio of successive paces (:func:`paces`): 12%, the steps of the forward model's speed grid (``_speed``)."""


def paces(limit: float) -> np.ndarray:
    """The paces tried for a tempo kept within ``limit`` either way: geometric from ``1 / limit`` to ``limit`` in
    equal steps of at most :data:`STEP` (15 for 2: 10.4% apart), with 1 among them; ``[1.0]`` for a limit of 0 or 1
    (tempo off)."""
    if not limit > 1.0:
        return np.array([1.0])
    half = int(np.ceil(np.log(limit) / np.log(STEP)))
    return np.exp(np.linspace(-np.log(limit), np.log(limit), 2 * half + 1))


@dataclass
class Observed:
    """Running sums of the observation over the frames seen: ``n``, ``so`` (k, 3) and ``soo``."""

    n: int
    so: np.ndarray
    soo: float = 0.0

    @classmethod
    def empty(cls, k: int) -> Observed:
        return cls(0, np.zeros((k, 3)))

    def add(self, o: np.ndarray) -> None:
        """Frames ``o`` (m, k, 3) seen."""
        o = np.nan_to_num(np.asarray(o, dtype=float))
        self.n += len(o)
        self.so = self.so + o.sum(axis=0)
        self.soo += float((o * o).sum())


@dataclass
class Fit:
    """One candidate's running sums over the frames seen, at each of S paces (see the module): ``sp``, ``spp``,
    ``sop`` and the frames ``n``; ``extra``, what its user keeps with it (the forward model: the last frame's place
    along the path, pace, whether it passed the path's end, and error). A path extended from another goes on from a
    :meth:`copy` of its sums: its predictions of the frames before are the same."""

    sp: np.ndarray
    spp: np.ndarray
    sop: np.ndarray
    n: int = 0
    extra: dict = field(default_factory=dict)

    @classmethod
    def empty(cls, s: int, k: int) -> Fit:
        return cls(np.zeros((s, k, 3)), np.zeros(s), np.zeros(s))

    def copy(self) -> Fit:
        return Fit(self.sp.copy(), self.spp.copy(), self.sop.copy(), self.n, dict(self.extra))

    def add(self, o: np.ndarray, p: np.ndarray) -> None:
        """Frames ``o`` (m, k, 3) seen and the candidate's predictions of them ``p`` (S, m, k, 3)."""
        o = np.nan_to_num(np.asarray(o, dtype=float))
        p = np.nan_to_num(np.asarray(p, dtype=float))
        self.n += o.shape[0]
        self.sp = self.sp + p.sum(axis=1)
        self.spp = self.spp + (p * p).sum(axis=(1, 2, 3))
        self.sop = self.sop + np.einsum("mkc,smkc->s", o, p)


def fitted(obs: Observed, fit: Fit, centred: bool) -> np.ndarray:
    """Per pace (S,): the residual sum of squares over the frames seen of the observation against the prediction,
    each centred on its own mean over them when ``centred``."""
    c = 1.0 / max(obs.n, 1) if centred else 0.0
    soo = obs.soo - c * float((obs.so * obs.so).sum())
    sop = fit.sop - c * np.einsum("kc,skc->s", obs.so, fit.sp)
    spp = fit.spp - c * (fit.sp * fit.sp).sum(axis=(1, 2))
    return np.maximum(soo - 2.0 * sop + spp, 0.0)


def residuals(obs: Observed, fit: Fit, o: np.ndarray, p: np.ndarray, centred: bool) -> tuple[np.ndarray, int]:
    """This frame's per-part distances (k,) between the observation ``o`` (k, 3) and the prediction ``p`` (S, k, 3)
    at the best pace (the least residual over the frames seen, this one included), each side centred on its mean
    over the frames seen when ``centred``: ``|(o - mean O) - (p - mean P)|``; with the best pace's index."""
    rss = fitted(obs, fit, centred)
    best = int(np.argmin(rss))
    c = 1.0 / max(obs.n, 1) if centred else 0.0
    d = np.linalg.norm((np.asarray(o, dtype=float) - obs.so * c) - (p[best] - fit.sp[best] * c), axis=-1)
    return d, best


def residuals_all(obs: Observed, fits: list[Fit], o: np.ndarray, p: np.ndarray,
                  centred: bool) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`Fit.add` and :func:`residuals` of C candidates at once (the same values as one by one): the frames
    ``o`` (m, k, 3) seen and the candidates' predictions of them ``p`` (C, S, m, k, 3) added to ``fits``' sums
    (each fit's arrays replaced by its row of the stacked sums), then each candidate's per-part distances at its
    best pace for the last frame (C, k) and that pace's index (C,). ``obs`` has had ``o`` added."""
    on = np.nan_to_num(np.asarray(o, dtype=float))
    pn = np.nan_to_num(np.asarray(p, dtype=float))
    sp = np.stack([f.sp for f in fits]) + pn.sum(axis=2)  # (C, S, k, 3)
    spp = np.stack([f.spp for f in fits]) + (pn * pn).sum(axis=(2, 3, 4))  # (C, S)
    sop = np.stack([f.sop for f in fits]) + np.einsum("mkx,csmkx->cs", on, pn)
    for i, f in enumerate(fits):
        f.n += on.shape[0]
        f.sp, f.spp, f.sop = sp[i], spp[i], sop[i]
    c = 1.0 / max(obs.n, 1) if centred else 0.0
    soo = obs.soo - c * float((obs.so * obs.so).sum())
    rss = np.maximum(soo - 2.0 * (sop - c * np.einsum("kx,cskx->cs", obs.so, sp))
                     + (spp - c * (sp * sp).sum(axis=(2, 3))), 0.0)
    best = np.argmin(rss, axis=1)
    at = np.arange(len(fits))
    last = np.asarray(p, dtype=float)[at, best, -1]  # (C, k, 3)
    d = np.linalg.norm((np.asarray(o[-1], dtype=float) - obs.so * c) - (last - sp[at, best] * c), axis=-1)
    return d, best


def prediction_sums(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A candidate's own running sums for :func:`distances_all`, from its predictions ``p`` (S, n, k, 3) at S paces:
    the predictions (NaN as 0), their cumulative sums over the rows ``sp`` (S, n, k, 3), the cumulative sums of their
    squares ``spp`` (S, n) and the squares of ``sp`` summed ``(sp * sp).sum(axis=(2, 3))`` (S, n). Each row's values
    depend on the rows up to it only (cumulative sums run row after row; the other sums are per row), so the sums of a
    longer prediction hold those of its first rows: a prediction used with several observations of different lengths
    is summed once."""
    p = np.nan_to_num(np.asarray(p, dtype=float))
    sp = np.cumsum(p, axis=1)  # (S, n, k, 3)
    return p, sp, np.cumsum((p * p).sum(axis=(2, 3)), axis=1), (sp * sp).sum(axis=(2, 3))


def distances_all(o: np.ndarray, p: np.ndarray | None, centred: bool,
                  sums: tuple[np.ndarray, ...] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`residuals` at every frame of a whole movement at once, as following it frame by frame gives them: the
    observation ``o`` (n, k, 3) and a candidate's predictions ``p`` (S, n, k, 3) at S paces; the running sums over
    rows 0 .. t are cumulative sums. Returns each frame's per-part distances (n, k) at the pace whose fit over the
    frames up to it leaves the least squared residual, and that pace's index (n,). ``sums``: :func:`prediction_sums`
    of ``p`` or of a longer prediction whose first n rows are ``p`` (``p`` is then not read): the same values."""
    o = np.nan_to_num(np.asarray(o, dtype=float))
    m = len(o)
    if sums is None:
        sums = prediction_sums(p)
    # the first m rows, laid out as computed whole (the same sums below)
    p, sp = np.ascontiguousarray(sums[0][:, :m]), np.ascontiguousarray(sums[1][:, :m])
    spp, spsp = sums[2][:, :m], sums[3][:, :m]
    n = np.arange(1, m + 1)
    c = 1.0 / n if centred else np.zeros(m)
    so = np.cumsum(o, axis=0)  # (n, k, 3)
    soo = np.cumsum((o * o).sum(axis=(1, 2)))
    sop = np.cumsum(np.einsum("nkc,snkc->sn", o, p), axis=1)
    rss = (soo - c * (so * so).sum(axis=(1, 2)))[None] - 2.0 * (sop - c * np.einsum("nkc,snkc->sn", so, sp)) \
        + spp - c * spsp
    best = np.argmin(np.maximum(rss, 0.0), axis=0)  # (n,)
    at = np.arange(m)
    mo = so * c[:, None, None]
    mp = sp[best, at] * c[:, None, None]
    return np.linalg.norm((o - mo) - (p[best, at] - mp), axis=-1), best
