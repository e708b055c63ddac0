"""The forward model's shortcuts (issue 22) give the answers of the plain computation, to the bit.

- a segment in which every subsystem is followed and no track has a candidate or a commitment left returns at once
  each frame (:meth:`ForwardModel._quiet`), without placing the rows (placed at the end, the same values);
- one-command candidates are extended at once from the stacked strokes (:meth:`ForwardModel._extended_at_once`);
- the stacked strokes' point counts come from one binary search over complex keys (:func:`_row_keys`), not from
  comparing every point;
- the anchors and the points along the table of every stroke come from compiled loops (:func:`_kernels`: numba),
  or from their plain-Python references, or from numpy's steps when numba is absent: each of the three is held to
  the plain computation (``KERNELS``).

Each is compared with the plain way on random data (hypothesis) and on Fig. 3's games, every answer and every
frame's trace.
"""

from __future__ import annotations

import contextlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import plugins.matchers.forward_model as fm
from plugins.lib.guiding_stroke import GuidingStroke
from plugins.matchers.forward_model import ForwardModel, Track, _along_rows, _distances, _row_keys
from tests.test_forward_model_incremental import _arms
from tests.test_forward_model_replay import both_ways, play_fig3_games
from toolkit import Motion
from toolkit.watching import follow

KERNELS = ("compiled", "python", "numpy")
"""How :class:`_Halves` and :class:`_StrokeRows` compute: numba's compiled loops, the same loops run as plain
Python (the reference they are compiled from), or numpy's steps (numba absent)."""


@contextlib.contextmanager
def kernels(mode: str):
    """A context in which the forward model's loops run as ``mode`` says (:data:`KERNELS`)."""
    with pytest.MonkeyPatch.context() as patch:
        if mode == "python":
            patch.setattr(fm, "_kernels", lambda: (fm._place_rows, fm._along_table))
        elif mode == "numpy":
            patch.setattr(fm, "_kernels", lambda: None)
        else:
            assert fm._kernels() is not None, "numba is a dependency: the compiled loops must be there"
        yield


@given(seed=st.integers(0, 10_000), rows=st.integers(1, 30), points=st.integers(2, 40), ties=st.booleans(),
       nan=st.booleans())
@settings(max_examples=200, deadline=None)
def test_point_counts_by_binary_search_are_the_compared_ones(seed, rows, points, ties, nan):
    """:func:`_along_rows` with the keys of :func:`_row_keys` gives the same points as comparing every point:
    lengths at a stroke's start, its end, exactly on a point, between points, on steps of no length (ties), NaN."""
    rng = np.random.default_rng(seed)
    steps = rng.random((rows, points - 1))
    if ties:  # steps of no length, and lengths that repeat
        steps = np.round(steps, 1) * (rng.random(steps.shape) < 0.6)
    arcs = np.concatenate([np.zeros((rows, 1)), np.cumsum(steps, axis=1)], axis=1)
    positions = rng.normal(size=(rows, points, 3))
    x = rng.random(rows) * arcs[:, -1]
    pick = rng.integers(0, 4, rows)
    x = np.where(pick == 1, arcs[:, -1], np.where(pick == 2, arcs[np.arange(rows), rng.integers(0, points, rows)],
                                                   np.where(pick == 3, 0.0, x)))
    if nan:
        x[rng.integers(rows)] = np.nan
    keys = _row_keys(arcs)
    assert keys is not None
    np.testing.assert_array_equal(_along_rows(arcs, positions, x, keys), _along_rows(arcs, positions, x))


def test_rows_that_do_not_grow_have_no_keys():
    assert _row_keys(np.array([[0.0, 1.0, 0.5]])) is None
    assert _row_keys(np.array([[0.0, np.nan, 1.0]])) is None
    assert _row_keys(np.array([[0.0, 0.0, 1.0], [0.0, 2.0, 2.0]])) is not None


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lengths=arrays(np.float64, 2, elements=st.floats(0.0, 1.5)),
       first=arrays(np.float64, (2, 3), elements=st.floats(-1.0, 2.0)), seed=st.integers(0, 3),
       excluded=st.integers(0, 5))
def test_candidates_extended_at_once_are_extended_one_by_one(write, pm, lengths, first, seed, excluded):
    """:meth:`ForwardModel._extended_at_once` gives the paths, in order, that the path-by-path loop gives, whether
    a candidate has covered its command (and goes on along every edge of its end node but itself and the excluded)
    or not."""
    character, names = _arms(write, pm, strokes=5, seed=seed)
    matcher, motor = character.matcher, character.motor
    for i, name in enumerate(names[:3]):  # commands from the end nodes of the first ones, to go on along
        end = motor.edge(name).target
        rest = motor.state("wrists", end)
        motor.learn("wrists", end, [GuidingStroke(rest[0], rest[0] + 0.1 * (i + 1), 1.0),
                                    GuidingStroke(rest[1], rest[1], 1.0)])
    track = Track("wrists", 1.0, False, "hub", 0, {(name,): 0.0 for name in names}, sorted(names),
                  first=motor.rest[2:4] + first * 0.2, excluded=set(names[excluded:excluded + 1]))
    want = []
    for path in track.candidates:  # the loop of _extended, path by path
        lead = matcher._lead(path[0])
        seen = matcher._along(track, path[0], lengths)[lead]
        total = sum(matcher._edge(e).arcs[lead, -1] for e in path)
        want.extend(matcher._next(track, path) if seen > total + 0.01 / track.scale else [path])
    assert matcher._extended(track, lengths) == want
    assert matcher._extended_at_once(track, list(track.candidates), lengths) == want


def _demonstrations(write, pm, monkeypatch, fast: bool):
    """The two-wrist body with five commands from the hub and the paper's threshold, shown a sequence of
    demonstrations frame by frame (:func:`~toolkit.watching.follow`): a command as learned, one at another speed,
    movements no command explains (every candidate drops out: learned), one that begins like a command and goes
    elsewhere; every answer and the matcher's view after each, with the shortcuts or without."""
    used = _shortcuts(monkeypatch, fast)
    character, names = _arms(write, pm, strokes=5, seed=7, threshold=0.05)
    matcher, motor = character.matcher, character.motor
    rest, rng = motor.rest, np.random.default_rng(11)
    parts = character.body.parts

    def along(name: str, n: int, speed: float = 1.0) -> np.ndarray:
        edge = motor.edge(name)
        t = np.minimum(np.arange(n) / 30.0 * speed, edge.duration)
        frames = np.repeat(rest[None], n, axis=0)
        for j, part in enumerate((2, 3)):
            frames[:, part] = edge.commands[j].position(t)
        return frames

    shows = [along(names[0], 35), along(names[2], 25, 1.3), along(names[4], 40, 0.8)]
    away = np.repeat(rest[None], 30, axis=0)
    away[:, 2] += np.linspace(0.0, 1.0, 30)[:, None] * rng.normal(0, 0.4, 3)
    shows.append(away)
    turn = along(names[1], 30)
    turn[15:, 2] = turn[15, 2] + np.linspace(0.0, 1.0, 15)[:, None] * np.array([0.0, 0.3, 0.0])
    shows.append(turn)
    shows.append(along(names[3], 30) + rng.normal(0, 0.003, (30, 4, 3)))
    answers = []
    for frames in shows:
        motion = Motion(frames - rest[0], 30.0, parts, np.ones(frames.shape[:2], dtype=bool))
        early, late = follow(matcher, motion)
        view = matcher.inspect()
        answers.append((repr(early), repr(late), repr(view["trace"]), repr(view["anchors"]), view["committed"],
                        view["committed_path"], view["committed_at"], view["deviated_at"]))
    return answers, used


def test_the_shortcuts_give_the_same_answers_on_demonstrations(write, pm):
    (fast, used), (plain, _) = both_ways(lambda monkeypatch, on: _demonstrations(write, pm, monkeypatch, on))
    assert used["quiet"] > 0 and used["at_once"] > 0  # both shortcuts were taken
    assert fast == plain


def _shortcuts(monkeypatch, fast: bool) -> dict[str, int]:
    """Count the shortcuts taken (``fast``), or replace them by the plain computation."""

    used = {"quiet": 0, "at_once": 0}
    quiet, at_once = ForwardModel._quiet, ForwardModel._extended_at_once

    def counted_quiet(self, tracks):
        answer = quiet(self, tracks) and fast
        used["quiet"] += answer
        return answer

    def counted_at_once(self, track, paths, lengths):
        if not fast:  # the loop of _extended, path by path
            out = []
            for path in paths:
                lead = self._lead(path[0])
                seen = self._along(track, path[0], lengths)[lead]
                total = sum(self._edge(e).arcs[lead, -1] for e in path)
                out.extend(self._next(track, path) if seen > total + 0.01 / track.scale else [path])
            return out
        used["at_once"] += 1
        return at_once(self, track, paths, lengths)

    monkeypatch.setattr(ForwardModel, "_quiet", counted_quiet)
    monkeypatch.setattr(ForwardModel, "_extended_at_once", counted_at_once)
    if not fast:
        monkeypatch.setattr(fm, "_row_keys", lambda arcs, first=0: None)
    return used


def _play(monkeypatch, fast: bool):
    """Fig. 3's games: every answer, and each frame's view of the matcher; with the shortcuts, or without."""
    used = _shortcuts(monkeypatch, fast)

    matches, seen = play_fig3_games(lambda view: (view["frames"], repr(view["trace"]), view["committed"],
                                                  view["committed_path"], view["committed_at"], view["deviated_at"],
                                                  repr(view["anchors"])))
    return matches, seen, used


@pytest.fixture(scope="module")
def plays():
    return both_ways(_play)  # with the shortcuts, then without


def test_the_shortcuts_give_the_same_answers_and_traces_to_the_bit(plays):
    (matches, seen, _), (matches_plain, seen_plain, _) = plays
    assert matches and matches == matches_plain
    assert seen == seen_plain


@given(seed=st.integers(0, 10_000), c=st.integers(1, 6), k=st.integers(1, 5), g=st.integers(2, 40),
       still=st.booleans(), hidden=st.booleans(), on_point=st.booleans(), groups=st.integers(1, 4),
       near=st.booleans(), scale=st.sampled_from([0, -3, -6, 120, -160]))
@settings(max_examples=150, deadline=None)
@pytest.mark.parametrize("mode", KERNELS)
def test_anchors_by_groups_of_half_strokes_are_the_masked_argmin_bit_for_bit(mode, seed, c, k, g, still, hidden,
                                                                             on_point, groups, near, scale):
    """:class:`_Halves` (the moving strokes' first halves in groups, points past a half at x = +inf) places every
    part where the plain computation does: the masked argmin of :func:`_distances` over whole strokes. Strokes that
    do not move, repeated points (ties), a part seen exactly on a point or halfway between two (near ties), a part
    never seen (NaN), strokes a millimetre or a micrometre long, and coordinates whose squares overflow or underflow
    included;
    compiled, as the compiled loop's plain-Python reference, and by numpy's steps."""
    rng = np.random.default_rng(seed)
    positions = np.cumsum(rng.normal(size=(c, k, g, 3)) * (rng.random((c, k, g, 1)) < 0.8), axis=2)
    if still:
        positions[rng.integers(c), rng.integers(k)] = rng.normal(size=3)
    steps = np.linalg.norm(np.diff(positions, axis=2), axis=-1)
    arcs = np.concatenate([np.zeros((c, k, 1)), np.cumsum(steps, axis=2)], axis=2)
    first = rng.normal(size=(k, 3)) * 2
    positions *= 10.0**scale
    first *= 10.0**scale
    if on_point:
        first[0] = positions[0, 0, rng.integers(g)]
    if near:
        i = rng.integers(g - 1)
        first[-1] = 0.5 * (positions[-1, -1, i] + positions[-1, -1, i + 1])
    if hidden:
        first[rng.integers(k)] = np.nan
    later = arcs > 0.5 * arcs[..., -1:]
    far = np.where(later, np.inf, _distances(*(np.ascontiguousarray(positions[..., i]) for i in range(3)), first))
    want = np.take_along_axis(arcs, np.argmin(far, axis=-1)[..., None], axis=-1)[..., 0]
    original = fm._Halves.GROUPS
    try:
        fm._Halves.GROUPS = groups
        with kernels(mode):
            got = fm._Halves(arcs, positions).place(first)
    finally:
        fm._Halves.GROUPS = original
    assert np.array_equal(got, want)


@given(seed=st.integers(0, 10_000), commands=st.lists(st.integers(1, 4), min_size=1, max_size=12),
       changed=st.booleans(), unsorted=st.booleans())
@settings(max_examples=100, deadline=None)
@pytest.mark.parametrize("mode", KERNELS)
def test_the_table_of_every_stroke_predicts_as_the_stacked_strokes(mode, seed, commands, changed, unsorted):
    """:class:`_StrokeRows` (every command's strokes as rows of one growing table, a set of candidates as row
    numbers) gives the points :func:`_along_rows` gives of the same strokes stacked: commands added one by one (the
    table grows past its first size), a command whose table changed (new rows), a stroke whose lengths do not grow
    (then every point is compared); compiled, as the compiled loop's plain-Python reference, and by numpy's steps.
    Lengths at a stroke's end, past it, before its start, -0 and NaN included; the values to the bit."""
    from plugins.matchers.forward_model import _EdgeTable, _StrokeRows

    rng = np.random.default_rng(seed)
    g = 12
    table = _StrokeRows(g)

    def edge(k: int) -> _EdgeTable:
        steps = np.round(rng.random((k, g - 1)), 1) * (rng.random((k, g - 1)) < 0.7)
        arcs = np.concatenate([np.zeros((k, 1)), np.cumsum(steps, axis=1)], axis=1)
        positions = rng.normal(size=(k, g, 3))
        positions[rng.random(k) < 0.3, 0] = -0.0  # strokes from -0: the sign of a zero weight shows
        return _EdgeTable([], positions, arcs, 0)

    edges = {f"e{i}": edge(k) for i, k in enumerate(commands * 8)}
    if unsorted:
        edges["e0"].arcs[0, 3] = -1.0
    for name, e in edges.items():
        table.rows(name, e)
    if changed:
        edges["e0"] = edge(len(edges["e0"].arcs))
    names = list(rng.permutation(list(edges)))[: rng.integers(1, len(edges) + 1)]
    rows = np.concatenate([table.rows(n, edges[n]) + np.arange(len(edges[n].arcs)) for n in names])
    arcs = np.concatenate([edges[n].arcs for n in names])
    positions = np.concatenate([edges[n].positions for n in names])
    x = rng.random(len(rows)) * arcs[:, -1]
    x = np.where(rng.random(len(x)) < 0.2, arcs[:, -1], x)
    pick = rng.random(len(x))
    x = np.where(pick < 0.05, -0.0, np.where(pick < 0.1, np.nan, np.where(pick < 0.15, arcs[:, -1] + 1.0,
                                                                         np.where(pick < 0.2, -1.0, x))))
    assert table.sorted == (not unsorted)
    with kernels(mode):
        got = table.along(rows, x)
    want = _along_rows(arcs, positions, x)
    assert np.array_equal(np.isnan(got), np.isnan(want))
    assert np.array_equal(np.where(np.isnan(got), 0.0, got).view(np.uint64),
                          np.where(np.isnan(want), 0.0, want).view(np.uint64))


@pytest.mark.parametrize("mode", KERNELS)
def test_points_whose_roots_tie_keep_the_earlier_one(mode):
    """Two points of a stroke whose summed squares differ by a rounding but whose roots are equal (one point's
    coordinates reversed: the sums round differently) are equally near: the earlier one is the anchor, as numpy's
    argmin of the roots says, although the later one's summed squares are smaller. Also an exact tie (two points
    at the same distance) keeps the earlier one."""
    p = np.array([0.5937480717858228, 0.8911669542823284, 0.3208483045665637])
    q = p[::-1].copy()
    squares = [(v[0] * v[0] + v[1] * v[1]) + v[2] * v[2] for v in (p, q)]
    assert squares[1] < squares[0] and np.sqrt(squares[1]) == np.sqrt(squares[0])
    exact = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    positions = np.stack([np.stack([p, q, p + 10, p + 20, p + 30]),
                          np.stack([*exact, exact[1] + 2, exact[1] + 4, exact[1] + 6])])[None]  # (1, 2, 5, 3)
    arcs = np.concatenate([np.zeros((1, 2, 1)), np.cumsum(np.linalg.norm(np.diff(positions, axis=2), axis=-1),
                                                          axis=2)], axis=2)
    with kernels(mode):
        placed = fm._Halves(arcs, positions).place(np.zeros((2, 3)))
    assert placed.tolist() == [[0.0, 0.0]]
