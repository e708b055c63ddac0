"""The k-best beam's fast paths (issue 22) give the numbers and answers of the paths they replaced.

Each fast path is pinned to the arithmetic it stands for: :class:`plugins.lib.pose_distance.PoseScan` to the einsum
of eq. 1 over every part, its single-precision screen to a bound of its error, the screened start nodes to
:meth:`KBest._starts` over the whole scan, the padded reach table to :func:`_gather`, :func:`_firsts` to
``np.unique``, ``body_velocity(frames=...)`` to the whole computation (written out here as it was); and whole
searches on the project's generated streams give the same matches with every fast path on and off.
"""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import plugins.matchers.path_search.kbest as ps
from plugins.lib.pose_distance import PoseScan
from plugins.lib.travel import body_velocity, frame_rotation


def einsum_scan(poses: np.ndarray, query: np.ndarray) -> np.ndarray:
    """The scan as path search wrote it before PoseScan: eq. 1 over every part, inline."""
    diff = poses - query
    return np.sqrt(np.einsum("cpi,cpi->cp", diff, diff)).mean(axis=1)


coordinate = st.floats(-3.0, 3.0, allow_nan=False, width=64)


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 40), st.integers(1, 30), st.integers(0, 2**32 - 1), st.floats(1e-3, 1e3))
def test_the_scan_gives_the_einsum_numbers(n, parts, seed, scale):
    """Every pose, and any rows of them (repeated, in any order): bit for bit the einsum's numbers."""
    rng = np.random.default_rng(seed)
    poses = rng.normal(size=(n, parts, 3)) * scale
    poses[rng.random(n) < 0.2] = poses[0]  # duplicates: ties
    query = rng.normal(size=(parts, 3)) * scale
    scan = PoseScan(poses)
    want = einsum_scan(poses, query)
    assert np.array_equal(scan(query), want)
    rows = rng.integers(0, n, size=rng.integers(0, 3 * n))
    assert np.array_equal(scan(query, rows), want[rows])


def test_the_scan_with_coordinates_not_finite_and_with_einsum_itself():
    """NaN and infinite coordinates give einsum's NaN and inf; a scan told that einsum sums otherwise calls it."""
    rng = np.random.default_rng(0)
    poses = rng.normal(size=(50, 7, 3))
    poses[3, 2, 1] = np.nan
    poses[5, 0, 0] = np.inf
    query = rng.normal(size=(7, 3))
    scan = PoseScan(poses)
    want = einsum_scan(poses, query)
    assert np.array_equal(scan(query), want, equal_nan=True)
    assert scan.approximate(query) is None  # no bound holds: the caller scans
    scan.planes = False
    assert np.array_equal(scan(query), want, equal_nan=True)
    assert np.array_equal(scan(query, np.array([5, 3, 1])), want[[5, 3, 1]], equal_nan=True)


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 60), st.integers(1, 30), st.integers(0, 2**32 - 1), st.floats(1e-4, 1e4), st.floats(0.0, 10.0))
def test_the_single_precision_screen_stays_within_its_bound(n, parts, seed, scale, away):
    """Poses at any scale, queries near and far: every exact distance within the screen's bound of its
    approximation."""
    rng = np.random.default_rng(seed)
    poses = rng.normal(size=(n, parts, 3)) * scale
    query = poses[rng.integers(n)] + rng.normal(size=(parts, 3)) * scale * away
    near, error = PoseScan(poses).approximate(query)
    assert error > 0
    assert np.all(np.abs(near - einsum_scan(poses, query)) <= error)


@settings(max_examples=300, deadline=None)
@given(arrays(np.intp, st.integers(0, 60), elements=st.integers(0, 9)))
def test_first_occurrences_are_nps(values):
    assert np.array_equal(ps._firsts(values), np.unique(values, return_index=True)[1])


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 30).flatmap(lambda n: st.tuples(
    st.just(n), st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), max_size=3 * n),
    st.integers(1, 4), st.booleans(), st.lists(st.integers(0, n - 1), max_size=12))))
def test_the_padded_table_lists_the_gathered_pairs(case):
    """Random graphs (cycles, self-loops), any ends (repeated): the same (beam, node) pairs in the same order."""
    n, edges, max_skip, forward, ends = case
    graph = nx.DiGraph()
    graph.add_nodes_from(range(n))
    graph.add_edges_from(edges)
    nodes = list(range(n))
    fan = ps._fan(graph, nodes, {i: i for i in nodes}, max_skip, forward=forward)
    ends = np.array(ends, dtype=np.intp)
    want = ps._gather(fan.full, ends)
    got = ps._candidates(fan, ends, np.zeros(len(ends)), None)
    if fan.padded is None:
        assert fan.long.any() or np.diff(fan.full[0]).max() > ps.LONG_ROW
    for g, w in zip(got, want):
        assert g.dtype == w.dtype and g.tolist() == w.tolist()


def old_body_velocity(world, local, visible, root, fps, window=0.25):
    """body_velocity as it was before ``frames``: np.interp always, np.gradient, the facing at every frame."""
    from scipy.ndimage import uniform_filter1d

    world = np.asarray(world, dtype=float)
    n = len(world)
    out = np.full((n, 3), np.nan)
    if n < 2:
        return out
    root_seen = np.asarray(visible, dtype=bool)[:, root] & np.isfinite(world[:, root]).all(axis=1)
    if root_seen.sum() < 2:
        return out
    frames = np.arange(n)
    track = np.stack([np.interp(frames, frames[root_seen], world[root_seen, root, k]) for k in range(3)], axis=1)
    velocity = np.gradient(track, axis=0) * fps
    taps = max(1, int(round(window * fps)))
    if taps > 1:
        velocity = uniform_filter1d(velocity, taps, axis=0, mode="nearest")
    angle = frame_rotation(world, local, visible, root)
    horizontal = (velocity[:, 0] + 1j * velocity[:, 2]) * np.exp(1j * angle)
    out[:, 0], out[:, 1], out[:, 2] = horizontal.real, velocity[:, 1], horizontal.imag
    out[~root_seen | ~np.isfinite(angle)] = np.nan
    return out


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 80), st.integers(2, 6), st.integers(0, 2**32 - 1), st.sampled_from([30.0, 29.97, 120.0, 1.0]),
       st.floats(0.0, 0.6))
def test_body_velocity_at_some_frames_is_the_whole_computations_rows(n, parts, seed, fps, hidden):
    """Roots seen throughout or not, frames asked in any order (repeated): the rows of the old computation."""
    rng = np.random.default_rng(seed)
    world = np.cumsum(rng.normal(size=(n, parts, 3)), axis=0)
    local = rng.normal(size=(n, parts, 3))
    visible = rng.random((n, parts)) >= hidden
    want = old_body_velocity(world, local, visible, 0, fps)
    assert np.array_equal(body_velocity(world, local, visible, 0, fps), want, equal_nan=True)
    frames = rng.integers(0, n, size=rng.integers(0, 2 * n + 1))
    assert np.array_equal(body_velocity(world, local, visible, 0, fps, frames=frames), want[frames], equal_nan=True)


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 60), st.integers(1, 12), st.integers(0, 2**32 - 1))
def test_the_start_nodes_are_the_stable_sorts(n, k, seed):
    rng = np.random.default_rng(seed)
    first = rng.choice([0.0, 0.5, 1.0, np.inf, np.nan], n) if seed % 3 == 0 else rng.integers(0, 4, n) / 4.0
    if seed % 5 == 0:
        first = np.where(rng.random(n) < 0.3, np.inf, first)  # excluded nodes
    beam = ps.KBest.__new__(ps.KBest)  # no graph is needed for the starts
    assert np.array_equal(beam._starts(first, k), np.argsort(first, kind="stable")[:k])


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """The project's generated benchmark data (two streams), its profile and its streams read."""
    from plugins.bench.data import make_data
    from plugins.bench.mocap import _streams
    from toolkit.manager import create_plugin_manager
    from toolkit.recordings.profile import load_profile

    pm = create_plugin_manager()
    folder = make_data(pm, tmp_path_factory.mktemp("gen"), seed=4, streams=2, per_stream=4)
    profile = load_profile(folder / "profile.toml")
    streams = [profile.read(path, None) for path, _ in _streams(folder / "streams")]
    return pm, profile, folder, streams


PAPER = ["matcher.comparison=poses", "matcher.search=k-best", "matcher.decision=distance"]
SETTINGS = [PAPER, [*PAPER, "matcher.beam.k=3"], [*PAPER, "matcher.beam.max_skip=3"]]


@pytest.mark.parametrize("settings", SETTINGS)
@pytest.mark.parametrize("segmenter", ["hub-threshold", "velocity-direction"])
def test_the_same_matches_with_the_fast_paths_off(generated, settings, segmenter, monkeypatch):
    """Every segment of the generated streams (the paper's search, several beams): the same Match, field for field,
    with the screen, the padded tables and PoseScan's planes off."""
    from toolkit.observe import Observer, compose_observer
    from toolkit.config.settings import parse_settings

    pm, profile, folder, streams = generated

    def run(fast: bool) -> list[str]:
        character = compose_observer(pm, profile, folder / "repertoire", segmenter=segmenter, matcher="path-search",
                                     settings=parse_settings(settings))
        matcher = character.matcher
        beam = matcher.searcher.kbest
        if not fast:
            monkeypatch.setattr(beam, "_screened", lambda query, k: None)
            beam.succ = beam.succ._replace(padded=None)
            beam.pred = beam.pred._replace(padded=None)
            beam._scan.planes = False
        found = []
        original = matcher.match

        def match(motion):
            result = original(motion)
            found.append(repr(result))
            return result

        matcher.match = match
        for motion in streams:
            Observer(character, profile.body, motion.fps).watch(motion)
        if fast:  # the fast paths were taken (the padded table with max_skip = 2; 3 reaches past LONG_ROW nodes)
            assert beam._scan.planes
            assert (beam.succ.padded is not None) == (matcher.params["beam"]["max_skip"] == 2)
        return found

    fast, slow = run(True), run(False)
    assert len(fast) >= 4
    assert fast == slow


def test_the_screened_starts_are_the_scans(generated):
    """Queries at and between the graph's own poses (ties, exact hits): the screened start nodes and costs equal
    _starts over the whole scan, for several k."""
    from toolkit.observe import compose_observer
    from toolkit.config.settings import parse_settings

    pm, profile, folder, _ = generated
    matcher = compose_observer(pm, profile, folder / "repertoire", matcher="path-search",
                               settings=parse_settings(PAPER)).matcher.searcher.kbest
    nodes = matcher.nodes_compared
    rng = np.random.default_rng(7)
    queries = [nodes[i] for i in rng.integers(0, len(nodes), 20)]
    queries += [0.5 * (nodes[i] + nodes[j]) for i, j in rng.integers(0, len(nodes), (20, 2))]
    queries += [nodes[i] + rng.normal(scale=0.05, size=nodes.shape[1:]) for i in rng.integers(0, len(nodes), 20)]
    for k in (1, 3, 8, 40):
        for query in queries:
            first = einsum_scan(nodes, query)
            want = matcher._starts(first, k)
            start, costs = matcher._screened(query, k)
            assert start.tolist() == want.tolist()
            assert np.array_equal(costs, first[want])
