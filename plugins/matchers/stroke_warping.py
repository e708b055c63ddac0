"""Matcher ``stroke-warping``: the nearest example by warping each part's sequence of strokes (issue 34, real people).

Kopp & Graeser 2006 (§4.1, §4.3) represent a movement as guiding strokes, not as the frames that trace them; a
wave of the hand is a stroke up to where the hand is held, the swings, and a stroke down. This matcher compares
movements so: each part's root-relative path, in the sequence's own body size
(:func:`plugins.matchers.comparison.sequence_size`), is cut into strokes where it turns back
(:func:`plugins.matchers.reversals.reversal_strokes`), and the demonstration's strokes are warped onto each example's,
part by part (:func:`warp_strokes`). What that sees, and what it does not:

- *how a part moves*: the swings of a wave against the single stroke up and down of a raise, which positions (eq. 1)
  barely tell apart where the hand is held at the same height;
- *not the tempo*: strokes have no duration, so a performance four times slower or faster than every example is
  the same strokes;
- *not the number of swings*: a stroke of one sequence may stand for several like it in the other (time warping's
  repeated steps), so seven swings match four;
- *not a stroke cut in two*: up to ``merge`` successive strokes of one sequence may stand for one of the other, at
  the length the path lost by the merge (two strokes in one direction merge for free, a swing and its return
  do not: they cost what they lose);
- *not the size*: the strokes are cut in body sizes, then every part's scaled together to a total length of 1
  (:func:`shares`), each stroke its share of what the sequence does. A wave held low with smaller swings is the
  same strokes as a wave held high with wide ones; what is left is the shape: which parts move, in which
  directions, in which proportions (the lift against the swings). Where a hand is held and how far it goes is the
  motion comparison's to see (path search's and the forward model's, beside which these strokes are an evidence:
  :mod:`plugins.matchers.strokes_evidence`).

The distance of two sequences is, summed over the parts, the share of stroke left unexplained along the best
alignment (:func:`warp_strokes`); a part with no strokes in one sequence leaves all the other's unexplained. A
sequence's distance to standing still is the total share of its strokes, 1 (:meth:`StrokeWarping._still`; 0 with
no stroke at all).
The decision is the matchers' shared one (:mod:`plugins.matchers.decision`): ``calibrated`` (the default) on the
examples themselves, its score the share of the demonstration's stroke length the nearest example leaves
unexplained; ``nearest`` never says "unknown" (a 1-NN classifier).

Everything else is :class:`plugins.matchers.dtw.DTW`'s: every example of every movement is a template, each
movement a ranked candidate by its nearest example, the decision at the segment's end.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from plugins.lib.compiled import kernel
from plugins.matchers.reversals import parts_strokes
from plugins.matchers.decision import Decision, Distance
from plugins.matchers.dtw import DTW, Grouped, body_sized, position_parts
from toolkit import Parameter, hookimpl

__all__ = ["MERGE", "PartStrokes", "REVERSAL", "SMOOTH", "StrokeWarping", "Strokes", "flat_strokes", "shares",
           "stroke_distances", "strokes_still", "warp_strokes"]

REVERSAL = 0.1
"""How far (body sizes) a part comes back from the farthest it went before its stroke ends: the default of
``reversal``, chosen on the generated gestures (``docs/matchers.md``)."""
SMOOTH = 0.33
"""Seconds of smoothing of each part's path before it is cut: the default of ``smooth``."""
MERGE = 3
"""The most successive strokes that may stand for one stroke of the other sequence: the default of ``merge``."""

Strokes = list[np.ndarray]
"""A sequence as this matcher sees it: one array of strokes (k, 3) per compared part, in shares of the sequence's
stroke length (:func:`shares`)."""


class PartStrokes:
    """The strokes of the chosen ``parts`` (indices) of root-relative positions, in the sequence's body size (the
    size of its ``sized`` parts, the position parts), cut where a part turns back by ``reversal`` body sizes after
    ``smooth`` seconds of smoothing, and scaled to shares of their total length (:func:`shares`)."""

    measure = "share of the stroke length left unexplained"

    def __init__(self, parts: np.ndarray, root: int, sized: np.ndarray, reversal: float, smooth: float) -> None:
        self.parts, self.root, self.sized, self.reversal, self.smooth = parts, root, sized, reversal, smooth

    def series(self, rel: np.ndarray, fps: float, track: np.ndarray | None = None) -> Strokes:
        """The strokes of each chosen part of the poses ``rel`` (n, P, 3) sampled ``fps`` times a second, cut in body
        sizes and scaled together to a total length of 1 (:func:`shares`); ``track``: where the root went (n, 3),
        for strokes that see it (:meth:`paths`)."""
        rel, scale = body_sized(rel, self.root, self.sized)
        if not scale > 0:
            return self.none()
        return shares(parts_strokes(self.paths(rel, track) * scale, fps, self.reversal, self.smooth))

    def paths(self, rel: np.ndarray, track: np.ndarray | None) -> np.ndarray:
        """The paths cut into strokes (n, K, 3), metres: the chosen parts' root-relative ones."""
        return rel[:, self.parts]

    @property
    def count(self) -> int:
        """How many paths a sequence's strokes have (K)."""
        return len(self.parts)

    def none(self) -> Strokes:
        """A sequence with no stroke: what standing still gives."""
        return [np.zeros((0, 3)) for _ in range(self.count)]


class FlatTemplates(Grouped):
    """The templates grouped by movement (:class:`~plugins.matchers.dtw.Grouped`) and their strokes one after another
    for the compiled pass (:func:`flat_strokes`: ``flat``, ``flat_starts``), made once per list of templates."""

    def __init__(self, templates: list[Strokes], labels: list[str]):
        super().__init__(templates, labels)
        self.flat, self.flat_starts = flat_strokes(templates)


class StrokeWarping(DTW):
    """Nearest example by warping the parts' strokes (see the module); decides at the segment's end."""

    name = "stroke-warping"
    parameters = (
        Parameter("parts", list, [], "The parts compared (empty: every position part; a finger's joint angle is not "
                  "one).", items=str),
        Parameter("reversal", float, REVERSAL, "How far (body sizes) a part must come back from the farthest it went "
                  "for its stroke to end: smaller excursions, and a tracker's jitter, are no strokes.", minimum=0.0,
                  check=lambda v: None if v > 0 else "must be above 0"),
        Parameter("smooth", float, SMOOTH, "Seconds of Savitzky-Golay smoothing of each path before it is cut "
                  "(0: none).", minimum=0.0, seconds=True),
        Parameter("merge", int, MERGE, "The most successive strokes of one sequence that may stand for one stroke of "
                  "the other (1: none).", minimum=1, maximum=10),
        Parameter("decision", str, "calibrated", "When the nearest example is 'unknown' (plugins.matchers.decision): "
                  "'calibrated', beyond a threshold calibrated on the examples themselves ([matcher.calibrated]); "
                  "'nearest', never.", choices=("calibrated", "nearest")),
        Parameter("calibrated", doc="The calibration of decision = 'calibrated'.", parameters=(
            Parameter("known_rejected", float, 0.05, "The share of a known movement's performances that may be "
                      "called unknown, as far as the repertoire's takes of one movement show how they vary.",
                      minimum=0.0, maximum=1.0),
        )),
    )

    def _chosen_features(self, body: Any) -> PartStrokes:
        parts, sized = position_parts(body, self.params["parts"])
        return PartStrokes(parts, body.root_index, sized, self.params["reversal"], self.params["smooth"])

    def _compile(self) -> None:
        warp_strokes(np.zeros((1, 3)), np.zeros((1, 3)))

    def _chosen_decision(self) -> Decision:
        if self.params["decision"] == "calibrated":
            return self._calibrated()
        return Distance(0.0, self.features.measure)

    def _prepare(self) -> FlatTemplates:
        return FlatTemplates(self.templates, self.labels)

    def _distances(self, series: Strokes) -> np.ndarray:
        prep = self._prepared()
        return stroke_distances(series, prep.flat, prep.flat_starts, self.params["merge"])

    def _still(self, series: Strokes) -> float:
        return strokes_still(series)


def shares(series: Strokes) -> Strokes:
    """The strokes of every part scaled together to a total length of 1, each stroke its share of the sequence's
    stroke length (a sequence with no stroke as it is): what the parts do, whatever the size they do it at."""
    total = strokes_still(series)
    return [strokes / total for strokes in series] if total > 0 else series


def strokes_still(series: Strokes) -> float:
    """A sequence's distance to standing still: the total length of its parts' strokes (1 once in shares,
    :func:`shares`; 0 with no stroke)."""
    return float(sum(np.linalg.norm(strokes, axis=1).sum() for strokes in series))


def warp_strokes(a: np.ndarray, b: np.ndarray, merge: int = MERGE) -> float:
    """The stroke length left unexplained when the strokes ``a`` (n, 3) and ``b`` (m, 3) are warped onto each other.

    Dynamic programming over the two sequences, each step aligning a run of strokes of one with a run of the other
    (one of the two runs a single stroke, the other up to ``merge`` strokes) at the cost ``|Σa - Σb| + (Σ|a| - |Σa|)
    + (Σ|b| - |Σb|)``: the difference of the runs' displacements, and the length each run loses by being taken as
    one stroke. A stroke may also stand for several strokes of the other sequence, one after another (time
    warping's repeated steps). An empty sequence leaves all the other's length unexplained."""
    a, b = np.asarray(a, dtype=float).reshape(-1, 3), np.asarray(b, dtype=float).reshape(-1, 3)
    out = np.empty(1)
    kernel(_warp_all)(a, np.array([0, len(a)]), b, np.array([0, len(b)]), 1, int(merge), out)
    return float(out[0])


def stroke_distances(series: Strokes, flat: np.ndarray, flat_starts: np.ndarray, merge: int = MERGE) -> np.ndarray:
    """:func:`warp_strokes` of ``series`` against every sequence laid out flat by :func:`flat_strokes`, summed over
    the parts, in one compiled pass: (S,)."""
    a, a_starts = flat_strokes([series])
    out = np.empty((len(flat_starts) - 1) // max(1, len(series)))
    kernel(_warp_all)(a, a_starts, flat, flat_starts, len(series), int(merge), out)
    return out


def flat_strokes(sequences: list[Strokes]) -> tuple[np.ndarray, np.ndarray]:
    """The strokes of every part of every sequence one after another (N, 3), and where each sequence's part begins
    (S * P + 1,): sequence ``s``'s part ``p`` is ``flat[starts[s * P + p] : starts[s * P + p + 1]]``."""
    pieces = [strokes for sequence in sequences for strokes in sequence]
    counts = np.array([len(strokes) for strokes in pieces], dtype=np.int64)
    flat = np.concatenate(pieces) if pieces else np.zeros((0, 3))
    return np.ascontiguousarray(flat, dtype=float), np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)


def _warp_all(a: np.ndarray, a_starts: np.ndarray, b: np.ndarray, b_starts: np.ndarray, parts: int, merge: int,
              out: np.ndarray) -> None:
    """:func:`warp_strokes` of the sequence ``a`` against each sequence of ``b``, summed over their ``parts`` parts,
    into ``out``; both flat as :func:`flat_strokes` lays them out. The reference loop, compiled where numba is
    installed (:func:`plugins.lib.compiled.kernel`): a run's displacement and length are differences of running sums (the
    length a run loses never below 0, which rounding could make it)."""
    longest_a = 0
    for p in range(parts):
        longest_a = max(longest_a, a_starts[p + 1] - a_starts[p])
    longest_b = 0
    for k in range(len(b_starts) - 1):
        longest_b = max(longest_b, b_starts[k + 1] - b_starts[k])
    sum_a, sum_b = np.zeros((longest_a + 1, 3)), np.zeros((longest_b + 1, 3))
    len_a, len_b = np.zeros(longest_a + 1), np.zeros(longest_b + 1)
    cost = np.empty((longest_a + 1, longest_b + 1))
    for t in range(len(out)):
        total = 0.0
        for p in range(parts):
            a0, b0 = a_starts[p], b_starts[t * parts + p]
            n, m = a_starts[p + 1] - a0, b_starts[t * parts + p + 1] - b0
            for i in range(n):
                sum_a[i + 1] = sum_a[i] + a[a0 + i]
                len_a[i + 1] = len_a[i] + np.sqrt(a[a0 + i, 0] ** 2 + a[a0 + i, 1] ** 2 + a[a0 + i, 2] ** 2)
            for j in range(m):
                sum_b[j + 1] = sum_b[j] + b[b0 + j]
                len_b[j + 1] = len_b[j] + np.sqrt(b[b0 + j, 0] ** 2 + b[b0 + j, 1] ** 2 + b[b0 + j, 2] ** 2)
            if n == 0 or m == 0:  # nothing explains the other's strokes
                total += len_a[n] + len_b[m]
                continue
            cost[0, 0] = 0.0
            for j in range(1, m + 1):
                cost[0, j] = np.inf
            for i in range(1, n + 1):
                cost[i, 0] = np.inf
                for j in range(1, m + 1):
                    best = np.inf
                    for ki in range(1, min(merge, i) + 1):
                        for kj in range(1, min(merge, j) + 1):
                            if ki > 1 and kj > 1:
                                break
                            ax, ay, az = (sum_a[i, 0] - sum_a[i - ki, 0], sum_a[i, 1] - sum_a[i - ki, 1],
                                          sum_a[i, 2] - sum_a[i - ki, 2])
                            bx, by, bz = (sum_b[j, 0] - sum_b[j - kj, 0], sum_b[j, 1] - sum_b[j - kj, 1],
                                          sum_b[j, 2] - sum_b[j - kj, 2])
                            step = (np.sqrt((ax - bx) ** 2 + (ay - by) ** 2 + (az - bz) ** 2)
                                    + max(0.0, len_a[i] - len_a[i - ki] - np.sqrt(ax * ax + ay * ay + az * az))
                                    + max(0.0, len_b[j] - len_b[j - kj] - np.sqrt(bx * bx + by * by + bz * bz)))
                            best = min(best, cost[i - ki, j - kj] + step)
                            if ki == 1 and kj == 1:  # one stroke standing for several of the other
                                best = min(best, cost[i - 1, j] + step, cost[i, j - 1] + step)
                    cost[i, j] = best
            total += cost[n, m]
        out[t] = total


@hookimpl
def likeme_register_matchers():
    return [StrokeWarping]
