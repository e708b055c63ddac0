"""Matcher ``dtw``: the nearest template by multivariate dynamic time warping (a baseline, via dtaidistance).

What most users compare against: every example of every movement of the
observer's repertoire is a template (``MotorSystem.examples``: the clips of a clip
repertoire, :mod:`plugins.lib.clip_repertoire`, else the motor system's own
performance of each movement), the observed segment is warped onto each with multivariate DTW
(:func:`dtaidistance.dtw_ndim.distance_fast`, squared Euclidean inner
distance over all root-relative part coordinates) and the closest template's
movement wins. DTW needs the whole segment: it decides at the segment's end
(decision fraction 1.0). It learns nothing.

dtaidistance returns the square root of the summed squared distances along the
warping path; its square is divided by the summed lengths of the two series and
the root taken again (a root-mean-square distance per frame, in metres), so that
long and short templates compete fairly. (Dividing the root itself by the
length, as earlier versions did, shrinks with the template's length and made the
longest template nearest to everything.) Whether the nearest template is near
enough is the matchers' shared decision (:mod:`plugins.matchers.decision`):
``distance``, unknown beyond ``[matcher.distance] max_distance`` (0, the
default: always the nearest, what a DTW 1-NN classifier answers), or
``calibrated`` on the templates themselves (each left out of its movement and
each movement left out, warped against the rest), its score the distance over
the segment's own distance to standing still (the root-mean-square distance of
its frames from their mean pose). Every movement is a ranked candidate
(``Match.candidates``), by the distance of its nearest example.

What is warped (``features``, a strategy chosen once at ``attach``, :data:`FEATURES`): ``positions`` (the
default, :class:`Positions`), every part's root-relative position in metres, what most users compare against; or
the stronger baselines issue 34 measured on real people, :class:`BodyMotion` over the parts named in ``parts``
(every position part: ``[]``), each sequence in its own body size (:func:`plugins.matchers.comparison.sequence_size`):
``motion``, the parts' root-relative positions and their velocities (a DTW 1-NN "on hip-centred, size-normalised
positions and velocities of the moving parts", 0.905 on the Kinect actions there); ``velocity``, the velocities
alone, blind to where a part is held ("on the hands' velocities in the body frame, scaled by body size", 0.97 on
the hand gestures there, with ``parts = ["left_hand", "right_hand"]``). A velocity is a Savitzky-Golay derivative
(:func:`plugins.lib.velocity.derivative`) times :data:`plugins.matchers.comparison.HORIZON` seconds, so that it
counts as a displacement, as in path search's motion comparison. These measure in body sizes, and ``decision =
"distance"`` takes only ``max_distance = 0`` with them (always the nearest); ``"calibrated"`` any.

Speed (issue 22): with numba installed and no band, :func:`warp_all` warps the
segment against every template in one compiled call, with dtaidistance's
arithmetic in dtaidistance's order (the same bits; ``tests/test_dtw_kernel.py``
compares them); otherwise dtaidistance is called once per template.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from plugins.lib.compiled import compiled
from plugins.lib.velocity import derivative
from plugins.matchers.comparison import HORIZON, sequence_size
from plugins.matchers.decision import Calibrated, Calibration, Decision, Distance
from toolkit import ConfigError, Match, Matcher, Motion, Parameter, hookimpl

__all__ = ["DTW", "FEATURES", "BodyMotion", "Grouped", "Positions", "body_sized", "frame_distance", "position_parts",
           "warp_all"]


class Positions:
    """Every part's root-relative position (m), every ``stride``-th frame, flat: what most users compare against."""

    measure = "root-mean-square distance per frame after warping (m)"

    def __init__(self, stride: int) -> None:
        self.stride = stride

    def series(self, rel: np.ndarray, fps: float) -> np.ndarray:
        """The series (n', P * 3) of root-relative positions ``rel`` (n, P, 3)."""
        series = rel[:: self.stride].reshape(-1, rel.shape[1] * 3)
        if not np.isfinite(series).all():  # nan_to_num changes nothing in a finite series (and costs more than this)
            series = np.nan_to_num(series)
        return np.ascontiguousarray(series, dtype=np.double)


class BodyMotion(Positions):
    """The chosen ``parts``' root-relative positions and (or) velocities (times :data:`HORIZON`), over the sequence's
    body size, the size of its ``sized`` parts (the position parts; see the module): issue 34's baselines on real
    people."""

    measure = "root-mean-square distance per frame after warping (body sizes)"

    def __init__(self, stride: int, parts: np.ndarray, root: int, sized: np.ndarray, *, positions: bool) -> None:
        super().__init__(stride)
        self.parts, self.root, self.sized, self.positions = parts, root, sized, positions

    def series(self, rel: np.ndarray, fps: float) -> np.ndarray:
        rel, scale = body_sized(rel, self.root, self.sized)
        features = [derivative(rel[:, self.parts], fps) * (HORIZON * scale)]
        if self.positions:
            features.insert(0, rel[:, self.parts] * scale)
        return super().series(np.concatenate(features, axis=1), fps)


def body_sized(rel: np.ndarray, root: int, sized: np.ndarray) -> tuple[np.ndarray, float]:
    """Poses ``rel`` (n, P, 3), NaN as 0, their position parts ``sized`` relative to the ``root`` part, and one over the
    sequence's body size (:func:`~plugins.matchers.comparison.sequence_size` of those parts; 0 where it has none)."""
    rel = np.nan_to_num(np.asarray(rel, dtype=float))
    rel[:, sized] = rel[:, sized] - rel[:, root : root + 1]
    size = sequence_size(rel[:, sized], np.ones((len(rel), len(sized)), dtype=bool))
    return rel, (1.0 / size if size > 0 else 0.0)


def position_parts(body: Any, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """The indices of the parts ``names`` (a matcher's ``parts`` parameter; empty: every position part) and of every
    position part of ``body`` (what a body size is measured on). A finger's joint angle is not a position: naming one
    is a :class:`~toolkit.ConfigError` that lists the position parts, as is naming a part the body lacks."""
    positional = [p for p, angle in zip(body.parts, body.angle_mask) if not angle]
    names = names or positional
    parts = np.array([body.index(p, key=("parts", i)) for i, p in enumerate(names)], dtype=np.intp)
    if body.angle_mask[parts].any():
        raise ConfigError(f"{names[int(np.argmax(body.angle_mask[parts]))]!r} is a finger's joint angle, not a "
                          "position", key=("parts",), expected="position parts", available=positional)
    return parts, body.indices(positional)


FEATURES = ("positions", "motion", "velocity")
"""What ``dtw`` may warp (its ``features`` parameter)."""


def frame_distance(series: np.ndarray, template: np.ndarray, window: float = 0.0) -> float:
    """Root-mean-square distance per frame (m) of two series (n, D) and (m, D) warped onto each other.

    ``window``: Sakoe-Chiba band as a share of the longer series (0: none). The same series at any length
    (every frame repeated k times) is at the same distance from the same template.
    """
    series = np.ascontiguousarray(series, dtype=np.double)
    template = np.ascontiguousarray(template, dtype=np.double)
    d = _dtw(series, template, _band(window, len(series), len(template)))
    return float(np.sqrt(d * d / (len(series) + len(template))))


def _band(window: float, n: int, m: int) -> int | None:
    """The Sakoe-Chiba band (frames) of ``window`` for series of ``n`` and ``m`` frames; ``None``: none."""
    band = int(window * max(n, m)) or None
    return None if band is None else max(band, abs(n - m) + 1)


def _dtw(series: np.ndarray, template: np.ndarray, band: int | None, max_dist: float | None = None) -> float:
    """:func:`dtaidistance.dtw_ndim.distance_fast` of two C-contiguous double arrays: the same C function with the
    same settings (:func:`_c_settings`), without its per-call checks and settings object (most of a short
    segment's cost). Where that C module or its signature is not there (another dtaidistance release, a build
    without C), the public :func:`~dtaidistance.dtw_ndim.distance_fast` gives the same number.

    ``max_dist`` (dtaidistance's early abandoning): infinity as soon as the distance is sure to exceed it; a distance
    up to it is the same number as without it (only cells above it, which no path up to it goes through, are
    skipped). ``None`` or 0: never abandoned."""
    try:
        from dtaidistance import dtw_cc

        settings = _c_settings(band)
        if max_dist:
            settings = {**settings, "max_dist": max_dist}
        return dtw_cc.distance_ndim(series, template, **settings)
    except (ImportError, AttributeError, TypeError):
        from dtaidistance import dtw_ndim

        return dtw_ndim.distance_fast(series, template, window=band, max_dist=max_dist or None)


@functools.lru_cache(maxsize=256)
def _c_settings(band: int | None) -> dict[str, Any]:
    """The keyword arguments :func:`dtaidistance.dtw_ndim.distance_fast` (``window=band``, every other argument its
    default) hands to its C function: :class:`dtaidistance.dtw.DTWSettings` ``.c_kwargs()`` of them."""
    from dtaidistance import innerdistance
    from dtaidistance.dtw import DTWSettings

    return DTWSettings(window=band, max_dist=None, max_step=None, max_length_diff=None, penalty=None, psi=None,
                       use_pruning=False, inner_dist=innerdistance.default, use_ndim=True).c_kwargs()


def warp_all(series: np.ndarray, columns: np.ndarray, starts: np.ndarray, out: np.ndarray) -> np.ndarray:
    """:func:`dtaidistance.dtw_ndim.distance_fast` of ``series`` (n, D) against every template at once (no band, no
    early abandoning): the same arithmetic in the same order, so the same bits.

    ``columns`` (D, M): the templates' frames side by side, coordinate by coordinate; template ``t`` is columns
    ``starts[t]:starts[t + 1]``; ``out`` (T,) receives the distances. Each frame pair's squared distance is summed
    over the coordinates in order from 0.0, as dtaidistance's C loop does; here a whole row of a template is summed
    at once (independent sums, which the compiler runs side by side without reordering any one of them). Then the
    same recurrence (the cell's cost plus the least of its three predecessors) and the square root of the last
    cell. Plain Python as written (the reference); :func:`_kernel` compiles it with numba (no ``fastmath``: no
    reordered sums, no fused multiply-adds).
    """
    n, dims = series.shape
    width = 0
    for t in range(len(starts) - 1):
        width = max(width, starts[t + 1] - starts[t])
    cost = np.empty(width)
    before = np.empty(width + 1)
    now = np.empty(width + 1)
    for t in range(len(starts) - 1):
        a = starts[t]
        m = starts[t + 1] - a
        before[0] = 0.0
        for j in range(1, m + 1):
            before[j] = np.inf
        for i in range(n):
            for j in range(m):
                cost[j] = 0.0
            k = 0
            while k + 4 <= dims:  # four coordinates a pass, added in their order (fewer loads and stores of cost)
                x0, x1, x2, x3 = series[i, k], series[i, k + 1], series[i, k + 2], series[i, k + 3]
                c0, c1 = columns[k, a : a + m], columns[k + 1, a : a + m]
                c2, c3 = columns[k + 2, a : a + m], columns[k + 3, a : a + m]
                for j in range(m):
                    d0, d1, d2, d3 = x0 - c0[j], x1 - c1[j], x2 - c2[j], x3 - c3[j]
                    cost[j] = (((cost[j] + d0 * d0) + d1 * d1) + d2 * d2) + d3 * d3
                k += 4
            while k < dims:
                x = series[i, k]
                column = columns[k, a : a + m]
                for j in range(m):
                    d = x - column[j]
                    cost[j] += d * d
                k += 1
            now[0] = np.inf
            for j in range(m):
                least = before[j]
                if before[j + 1] < least:
                    least = before[j + 1]
                if now[j] < least:
                    least = now[j]
                now[j + 1] = cost[j] + least
            before, now = now, before
        out[t] = np.sqrt(before[m])
    return out


@functools.lru_cache(maxsize=1)
def _kernel():
    """:func:`warp_all` compiled by numba (cached on disk), or ``None`` without numba (dtaidistance is used then,
    with the same numbers). Imported and compiled when a dtw observer is composed, never by importing this module."""
    kernels = compiled(warp_all)
    if kernels is None:
        return None
    (kernel,) = kernels
    one = np.zeros((1, 1))
    kernel(one, one, np.array([0, 1], dtype=np.int64), np.empty(1))  # compiled (or loaded) now, not at a match
    return kernel


class DTW(Matcher):
    """Nearest example by multivariate dynamic time warping (dtaidistance); decides at the segment's end."""

    name = "dtw"
    parameters = (
        Parameter("stride", int, 2, "Use every n-th frame of segments and templates (DTW is quadratic in length).",
                  minimum=1),
        Parameter("window", float, 0.0, "Sakoe-Chiba band as a share of the longer series (0: no band).",
                  minimum=0.0, maximum=1.0),
        Parameter("features", str, "positions", "What is warped: 'positions', every part's root-relative position (m); "
                  "'motion', the parts' positions and velocities over body size; 'velocity', their velocities alone "
                  "(issue 34's baselines on real people).", choices=FEATURES),
        Parameter("parts", list, [], "The parts 'motion' and 'velocity' compare (empty: every position part; a "
                  "finger's joint angle is not one).", items=str),
        Parameter("decision", str, "distance", "When the nearest template is 'unknown' (plugins.matchers.decision): "
                  "'distance', beyond [matcher.distance] max_distance; 'calibrated', beyond a threshold calibrated on "
                  "the templates themselves ([matcher.calibrated]).", choices=("distance", "calibrated")),
        Parameter("distance", doc="The limit of decision = 'distance'.", parameters=(
            Parameter("max_distance", float, 0.0, "Root-mean-square per-frame distance (m) above which a segment is "
                      "unknown (0: always the nearest).", minimum=0.0, length=True),
        )),
        Parameter("calibrated", doc="The calibration of decision = 'calibrated'.", parameters=(
            Parameter("known_rejected", float, 0.05, "The share of a known movement's performances that may be "
                      "called unknown, as far as the repertoire's takes of one movement show how they vary.",
                      minimum=0.0, maximum=1.0),
        )),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        root = owner.body.root_index
        self.features = self._chosen_features(owner.body)
        examples = owner.motor.examples(fps=30.0)  # the clips of a clip repertoire, else one performance of each
        self.labels = [label for label, _ in examples]
        self.templates = []
        for _, motion in examples:
            positions = motion.filled().positions  # hidden parts held (docs/conventions.md); never seen: 0
            self.templates.append(self._series(positions - positions[:, root : root + 1], motion.fps))
        seen: set[str] = set()  # each movement's first example is warped in full; its further ones (extras) are
        self._firsts, self._extras = [], []  # abandoned once sure to be farther than the movement's nearest so far
        for i, label in enumerate(self.labels):
            (self._extras if label in seen else self._firsts).append(i)
            seen.add(label)
        self._compile()
        self.decision = self._chosen_decision()

    def _compile(self) -> None:
        """Load and compile what :meth:`match` calls, when the observer is composed rather than at the first match."""
        import dtaidistance.dtw_ndim  # noqa: F401

        _kernel()

    def _chosen_decision(self) -> Decision:
        """The decision ``decision`` names, calibrated on the templates where it is ``calibrated``."""
        if self.params["decision"] == "calibrated":
            return self._calibrated()
        return Distance(self.params["distance"]["max_distance"], self.features.measure)

    def _calibrated(self) -> Calibrated:
        """The ``calibrated`` decision at ``[calibrated] known_rejected``, calibrated on the templates."""
        decision = Calibrated(self.params["calibrated"]["known_rejected"])
        decision.calibrate(self._calibration())
        return decision

    def _chosen_features(self, body: Any) -> Positions:
        """The strategy ``features`` names (:data:`FEATURES`) for ``body``, its ``parts`` and decision checked."""
        if self.params["features"] == "positions":
            return Positions(self.params["stride"])
        parts, sized = position_parts(body, self.params["parts"])
        if self.params["decision"] == "distance" and self.params["distance"]["max_distance"] > 0:
            raise ConfigError(f"features = '{self.params['features']}' measures in body sizes, and max_distance is "
                              "metres", key=("distance", "max_distance"),
                              expected="max_distance = 0 (always the nearest), decision = 'calibrated', or "
                                       "features = 'positions'")
        return BodyMotion(self.params["stride"], parts, body.root_index, sized,
                          positions=self.params["features"] == "motion")

    def _calibration(self) -> Calibration:
        """Each template as a segment: against its movement's other templates (leave one take out) and against the
        other movements' (leave one movement out), each over its distance to standing still
        (:meth:`Calibration.of_rows`)."""
        rows = np.full((len(self.templates), len(self.templates)), np.inf)
        for i, series in enumerate(self.templates):
            still = self._still(series)
            if still > 0:
                rows[i] = self._distances(series) / still
        return Calibration.of_rows(rows, self.labels)

    def _distances(self, series: np.ndarray) -> np.ndarray:
        """The root-mean-square distance per frame of ``series`` to every template after warping."""
        prep = self._prepared()
        window, n = self.params["window"], len(series)
        templates = prep.templates
        if prep.dropped is not None and not series[:, prep.dropped].any():
            # the coordinates that are 0 in every template and in the segment (the root's, root-relative) add an
            # exact +0.0 to each frame pair's sum of squares, taken in dtaidistance's order: left out, the same bits
            series, templates = np.ascontiguousarray(series[:, prep.kept]), prep.reduced
        lengths = n + prep.sizes
        summed = np.empty(len(templates))
        kernel = None if window else _kernel()
        if kernel is not None:
            # every example warped in full, in one call: each movement's nearest is the same example at the same
            # distance as with early abandoning (an abandoned example is surely farther), so the same Match
            columns, starts = prep.columns(templates is prep.reduced)
            kernel(series, columns, starts, summed)
        else:
            self._warp_one_by_one(series, templates, prep, lengths, summed)
        return np.sqrt(summed * summed / lengths)  # frame_distance of each template, element by element

    @functools.cached_property
    def features(self) -> Positions:
        """What is warped (:data:`FEATURES`): set by :meth:`attach`; every part's positions until then."""
        return Positions(self.params["stride"])

    def _series(self, rel: np.ndarray, fps: float = 30.0) -> np.ndarray:
        return self.features.series(rel, fps)

    def _prepared(self) -> _Prepared:
        """What :meth:`match` needs of the templates, computed once per list of templates (set by :meth:`attach`)."""
        prepared = getattr(self, "_prep", None)
        if prepared is None or prepared.templates is not self.templates or prepared.labels is not self.labels:
            prepared = self._prep = self._prepare()
        return prepared

    def _prepare(self) -> _Prepared:
        """The templates prepared for :meth:`match` (:meth:`_prepared` keeps them until the templates change)."""
        return _Prepared(self.templates, self.labels, self._firsts, self._extras)

    def _still(self, series: np.ndarray) -> float:
        """A series' distance to standing still, in the unit of :meth:`_distances` (what a relative decision
        divides by)."""
        return _still(series)

    def _warp_one_by_one(self, series: np.ndarray, templates: list[np.ndarray], prep: _Prepared,
                         lengths: np.ndarray, summed: np.ndarray) -> None:
        """dtaidistance's distance of ``series`` to each template into ``summed``; a movement's further examples
        abandoned (infinity) once surely farther than its nearest so far."""
        window, n = self.params["window"], len(series)
        bands = [_band(window, n, len(t)) for t in templates] if window else prep.no_band
        for i in prep.firsts:
            summed[i] = _dtw(series, templates[i], bands[i])
        nearest_so_far = {}
        for i in prep.firsts:
            nearest_so_far[prep.labels[i]] = np.sqrt(summed[i] * summed[i] / lengths[i])
        for i in prep.extras:
            # only each movement's nearest example counts (the best, the runner-up over the other movements and
            # every candidate are per-movement minima): an example farther than its movement's nearest so far is
            # abandoned (infinity). The bound is that distance back in dtaidistance's units, a billionth wider, so
            # an abandoned example is surely farther, and one that is not has its exact distance.
            label = prep.labels[i]
            bound = nearest_so_far[label] * np.sqrt(lengths[i]) * (1.0 + 1e-9)
            summed[i] = _dtw(series, templates[i], bands[i], bound if np.isfinite(bound) else None)
            nearest_so_far[label] = min(nearest_so_far[label], np.sqrt(summed[i] * summed[i] / lengths[i]))

    def match(self, motion: Motion) -> Match:
        if not motion.visible.any() or not self.templates:
            return Match.unknown("nothing visible", details={"reason": "nothing visible"})
        prep = self._prepared()
        # every part seen in every frame: nothing to fill (fill_hidden would copy the same coordinates)
        positions = np.asarray(motion.positions, dtype=float) if motion.visible.all() else motion.filled().positions
        series = self._series(positions, motion.fps)
        distances = self._distances(series)
        best = int(np.argmin(distances))
        per_frame = float(distances[best])
        label = prep.labels[best]
        verdict = self.decision.decide(label, per_frame, self._still(series) if self.decision.relative else 1.0)
        measure = self.decision.measure
        if verdict.movement is None:
            return Match.unknown("too far from every example", nearest=label, score=verdict.score,
                                 threshold=verdict.threshold, measure=measure, details={"distance": per_frame})
        # each movement's nearest example (Fig. 13's ranked candidates), ranked by distance, ties by name
        nearest = np.minimum.reduceat(distances[prep.order], prep.starts)
        others = nearest.copy()
        others[prep.slot[label]] = np.inf  # the nearest of every other movement (none: infinity)
        runner_up = float(others.min())
        confidence = float(1.0 - per_frame / runner_up) if np.isfinite(runner_up) and runner_up > 0 else 1.0
        ranked = sorted(zip(nearest.tolist(), prep.names.tolist()))
        threshold = verdict.threshold if np.isfinite(verdict.threshold) else None
        return Match(label, max(0.0, confidence), None, details={"distance": per_frame, "runner_up": runner_up},
                     candidates=tuple((lab, d) for d, lab in ranked), score=verdict.score, threshold=threshold,
                     measure=measure)


def _still(series: np.ndarray) -> float:
    """A series' distance to standing still: the root-mean-square distance of its frames from their mean (m)."""
    return float(np.sqrt(((series - series.mean(axis=0)) ** 2).sum(axis=1).mean())) if len(series) else 0.0


class Grouped:
    """Templates grouped by movement, for :meth:`DTW.match`'s ranking: the movements sorted by name (``names``), the
    templates in that order (``order``) and where each movement's begin (``starts``), for
    :func:`numpy.minimum.reduceat`; ``slot`` the place of each movement among ``names``."""

    def __init__(self, templates: list, labels: list[str]):
        self.templates, self.labels = templates, labels
        names = np.array(labels, dtype=object)
        self.order = np.argsort(names, kind="stable")
        sorted_names = names[self.order]
        self.starts = np.flatnonzero(np.r_[True, sorted_names[1:] != sorted_names[:-1]])
        self.names = sorted_names[self.starts]
        self.slot = {name: i for i, name in enumerate(self.names.tolist())}


class _Prepared(Grouped):
    """The templates as :meth:`DTW.match` uses them, computed once: their sizes, the coordinates that are 0 in all
    of them (``dropped``; ``None`` if none) with the templates without them (``reduced``), and the examples
    grouped by movement (:class:`Grouped`)."""

    def __init__(self, templates: list[np.ndarray], labels: list[str], firsts: list[int], extras: list[int]):
        super().__init__(templates, labels)
        self.firsts, self.extras = list(firsts), list(extras)
        self.sizes = np.array([len(t) for t in templates], dtype=float)
        self.no_band = [None] * len(templates)
        zero = np.logical_and.reduce([~t.any(axis=0) for t in templates]) if templates else np.zeros(0, bool)
        self.dropped = np.flatnonzero(zero) if zero.any() and not zero.all() else None
        self.kept = np.flatnonzero(~zero)
        self.reduced = [np.ascontiguousarray(t[:, self.kept]) for t in templates]
        self._columns: dict[bool, tuple[np.ndarray, np.ndarray]] = {}

    def columns(self, reduced: bool) -> tuple[np.ndarray, np.ndarray]:
        """The templates (``reduced``: without the dropped coordinates) side by side for :func:`warp_all`: the (D, M)
        coordinates and the (T + 1,) starts."""
        if reduced not in self._columns:
            templates = self.reduced if reduced else self.templates
            starts = np.cumsum([0] + [len(t) for t in templates]).astype(np.int64)
            self._columns[reduced] = (np.ascontiguousarray(np.concatenate(templates).T), starts)
        return self._columns[reduced]


@hookimpl
def likeme_register_matchers():
    return [DTW]
